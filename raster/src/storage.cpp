#include <raster/storage.h>

#include <cmath>

namespace raster {

void DepthBuffer::resize(DepthFormat depth_format, uint32_t w, uint32_t h) {
    format = depth_format;
    width = w;
    height = h;
    const size_t n = size_t(w) * h;
    if (format == DepthFormat::Float32) {
        float32.assign(n, kFarDepth);
        unorm16.clear();
    } else {
        unorm16.assign(n, encodeUnorm16(kFarDepth));
        float32.clear();
    }
}

void ColorBuffer::resize(ColorFormat color_format, size_t pixels, glm::vec4 clear) {
    format = color_format;
    half.clear();
    float32.clear();
    // resize value-initialises to +0 in both formats, so a +0 clear colour (every target's, in
    // practice) needs no store per pixel.
    const bool zero = clear == glm::vec4(0.0f) && !std::signbit(clear.r) &&
                      !std::signbit(clear.g) && !std::signbit(clear.b) && !std::signbit(clear.a);
    if (format == ColorFormat::Float32)
        float32.resize(pixels * 4);
    else
        half.resize(pixels * 4);
    if (!zero)
        for (size_t i = 0; i < pixels; ++i)
            store(i, clear);
}

} // namespace raster
