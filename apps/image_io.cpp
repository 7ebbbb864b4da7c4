#include "apps/image_io.h"

#include <raster/texture.h>

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <memory>
#include <system_error>
#include <unistd.h>

namespace focal {

namespace fs = std::filesystem;
using raster::Result;
using raster::Status;

bool isLinearFormat(const std::string& path) {
    std::string ext = fs::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    return ext == ".exr" || ext == ".hdr";
}

namespace {

std::string oneLine(std::string s) {
    std::replace(s.begin(), s.end(), '\n', ' ');
    while (!s.empty() && s.back() == ' ')
        s.pop_back();
    return s;
}

Status writeDirect(const std::string& path, const std::string& format_hint_path,
                   const ImageData& image) {
    auto out = OIIO::ImageOutput::create(format_hint_path);
    if (!out)
        return Status::error("cannot write this image format (" + oneLine(OIIO::geterror()) + ")");
    const bool linear = isLinearFormat(format_hint_path);
    OIIO::ImageSpec spec(int(image.width), int(image.height), int(image.channels),
                         linear ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8);
    if (image.channels == 4)
        spec.alpha_channel = 3;
    if (!linear)
        spec.attribute("oiio:ColorSpace", "sRGB");
    if (!out->open(path, spec))
        return Status::error(oneLine(out->geterror()));
    bool ok;
    if (linear) {
        ok = out->write_image(OIIO::TypeDesc::FLOAT, image.pixels.data());
    } else {
        // sRGB-encode colour (alpha stays linear) and round to 8 bits ourselves, so the bytes
        // do not depend on the library's conversion.
        std::vector<uint8_t> bytes(image.pixels.size());
        for (size_t i = 0; i < image.pixels.size(); ++i) {
            const bool alpha = image.channels == 4 && i % 4 == 3;
            const float v = image.pixels[i];
            const float e = alpha ? v : raster::linearToSrgb(std::max(v, 0.0f));
            bytes[i] = uint8_t(std::clamp(e, 0.0f, 1.0f) * 255.0f + 0.5f);
        }
        ok = out->write_image(OIIO::TypeDesc::UINT8, bytes.data());
    }
    if (!ok)
        return Status::error(oneLine(out->geterror()));
    if (!out->close())
        return Status::error(oneLine(out->geterror()));
    return {};
}

} // namespace

Status writeImage(const std::string& path, const ImageData& image) {
    if (image.width == 0 || image.height == 0 ||
        image.pixels.size() != size_t(image.width) * image.height * image.channels)
        return Status::error(path + ": internal error: image buffer does not match its size");
    const fs::path target(path);
    const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
    std::error_code ec;
    if (!fs::is_directory(dir, ec))
        return Status::error(path + ": folder " + dir.string() + " does not exist");
    static std::atomic<uint32_t> counter{0};
    const fs::path tmp = dir / ("." + target.stem().string() + ".tmp" + std::to_string(::getpid()) +
                                "_" + std::to_string(counter++) + target.extension().string());
    Status s = writeDirect(tmp.string(), path, image);
    if (s.ok()) {
        fs::rename(tmp, target, ec);
        if (ec)
            s = Status::error(path +
                              ": cannot rename the finished image into place: " + ec.message());
    } else {
        s = Status::error(path + ": " + s.message());
    }
    if (!s.ok())
        fs::remove(tmp, ec);
    return s;
}

namespace {

// Opens `path` for reading; `config` carries reader hints (e.g. oiio:UnassociatedAlpha).
Result<std::unique_ptr<OIIO::ImageInput>> openImage(const std::string& path,
                                                    const OIIO::ImageSpec* config = nullptr) {
    std::error_code ec;
    if (!fs::exists(path, ec))
        return Status::error(path + ": file not found");
    auto in = OIIO::ImageInput::open(path, config);
    if (!in)
        return Status::error(path + ": cannot read image (" + oneLine(OIIO::geterror()) + ")");
    return in;
}

} // namespace

Result<ImageSamples> readImageSamples(const std::string& path) {
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    Result<std::unique_ptr<OIIO::ImageInput>> opened = openImage(path, &config);
    if (!opened.ok())
        return opened.status();
    OIIO::ImageInput& in = **opened;
    const OIIO::ImageSpec& spec = in.spec();
    const OIIO::TypeDesc type =
        spec.format.basetype == OIIO::TypeDesc::UINT8    ? OIIO::TypeDesc::UINT8
        : spec.format.basetype == OIIO::TypeDesc::UINT16 ? OIIO::TypeDesc::UINT16
                                                         : OIIO::TypeDesc::FLOAT;
    ImageSamples img;
    img.width = uint32_t(spec.width);
    img.height = uint32_t(spec.height);
    img.channels = uint32_t(spec.nchannels);
    img.bytes_per_sample = uint32_t(type.size());
    img.bytes.resize(size_t(img.width) * img.height * img.channels * img.bytes_per_sample);
    if (!in.read_image(0, 0, 0, spec.nchannels, type, img.bytes.data()))
        return Status::error(path + ": cannot decode image (" + oneLine(in.geterror()) + ")");
    return img;
}

raster::Result<ImageData> readImage(const std::string& path) {
    Result<std::unique_ptr<OIIO::ImageInput>> opened = openImage(path);
    if (!opened.ok())
        return opened.status();
    std::unique_ptr<OIIO::ImageInput>& in = *opened;
    const OIIO::ImageSpec& spec = in->spec();
    ImageData img;
    img.width = uint32_t(spec.width);
    img.height = uint32_t(spec.height);
    img.channels = uint32_t(spec.nchannels);
    img.pixels.resize(size_t(img.width) * img.height * img.channels);
    if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, img.pixels.data()))
        return Status::error(path + ": cannot decode image (" + oneLine(in->geterror()) + ")");
    const bool float_file = spec.format.basetype == OIIO::TypeDesc::FLOAT ||
                            spec.format.basetype == OIIO::TypeDesc::HALF;
    if (!float_file) {
        for (size_t i = 0; i < img.pixels.size(); ++i) {
            const bool alpha = int(i % img.channels) == spec.alpha_channel;
            if (!alpha)
                img.pixels[i] = raster::srgbToLinear(img.pixels[i]);
        }
    }
    return img;
}

} // namespace focal
