// Image files through OpenImageIO. EXR is written as linear float; PNG (and other 8-bit formats)
// as sRGB-encoded 8-bit. Every write goes to a temporary file in the destination folder and is
// renamed into place, so a failure never leaves half an image.
#pragma once

#include <raster/status.h>

#include <cstdint>
#include <string>
#include <vector>

namespace focal {

struct ImageData {
    uint32_t width = 0;
    uint32_t height = 0;
    uint32_t channels = 0;
    std::vector<float> pixels; // linear, interleaved, top row first
};

// Writes `image`. The format follows the extension (.exr float; .png/.jpg/.tif... 8-bit sRGB).
raster::Status writeImage(const std::string& path, const ImageData& image);

// Reads any image OpenImageIO can decode into linear float (8/16-bit files are sRGB-decoded).
raster::Result<ImageData> readImage(const std::string& path);

// An image's samples as the file stores them, with no colour conversion: what `focal hash`
// hashes (apps/pixel_hash.h). 8-bit files give their bytes, 16-bit integer files their uint16
// values, every other format IEEE float32 (half widens exactly). Alpha is left as stored (a PNG's
// colour is not premultiplied on reading).
struct ImageSamples {
    uint32_t width = 0;
    uint32_t height = 0;
    uint32_t channels = 0;
    uint32_t bytes_per_sample = 0; // 1 (uint8), 2 (uint16) or 4 (float32)
    std::vector<uint8_t> bytes;    // samples in host byte order, interleaved, top row first
};

// Reads the first subimage (MIP level 0) of any image OpenImageIO can decode.
raster::Result<ImageSamples> readImageSamples(const std::string& path);

// True when `path` names a float format written linearly (EXR, HDR).
bool isLinearFormat(const std::string& path);

} // namespace focal
