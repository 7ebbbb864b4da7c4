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

// True when `path` names a float format written linearly (EXR, HDR).
bool isLinearFormat(const std::string& path);

} // namespace focal
