#include <raster/storage.h>

#include <algorithm>
#include <cmath>
#include <cstring>

namespace raster {

namespace {
bool isPositiveZero(glm::vec4 c) {
    return c == glm::vec4(0.0f) && !std::signbit(c.r) && !std::signbit(c.g) && !std::signbit(c.b) &&
           !std::signbit(c.a);
}
} // namespace

void DepthBuffer::resize(DepthFormat depth_format, uint32_t w, uint32_t h) {
    resizeUncleared(depth_format, w, h);
    fill(0, size_t(w) * h, kFarDepth);
}

void DepthBuffer::resizeUncleared(DepthFormat depth_format, uint32_t w, uint32_t h) {
    format = depth_format;
    width = w;
    height = h;
    const size_t n = size_t(w) * h;
    if (format == DepthFormat::Float32) {
        float32.resize(n);
        unorm16.clear();
    } else {
        unorm16.resize(n);
        float32.clear();
    }
}

void DepthBuffer::fill(size_t first, size_t count, float d) {
    if (format == DepthFormat::Float32)
        std::fill_n(float32.data() + first, count, d);
    else
        std::fill_n(unorm16.data() + first, count, encodeUnorm16(d));
}

void ColorBuffer::resizeUncleared(ColorFormat color_format, size_t pixels) {
    format = color_format;
    if (format == ColorFormat::Float32) {
        float32.resize(pixels * 4);
        half.clear();
    } else {
        half.resize(pixels * 4);
        float32.clear();
    }
}

void ColorBuffer::fill(size_t first, size_t count, glm::vec4 c) {
    if (isPositiveZero(c)) { // +0 is all zero bits in both formats
        if (format == ColorFormat::Float32)
            std::memset(float32.data() + first * 4, 0, count * 4 * sizeof(float));
        else
            std::memset(static_cast<void*>(half.data() + first * 4), 0,
                        count * 4 * sizeof(Imath::half));
        return;
    }
    if (format == ColorFormat::Float32) {
        float* p = float32.data() + first * 4;
        for (size_t i = 0; i < count; ++i, p += 4)
            p[0] = c.r, p[1] = c.g, p[2] = c.b, p[3] = c.a;
    } else {
        const Imath::half h[4] = {Imath::half(c.r), Imath::half(c.g), Imath::half(c.b),
                                  Imath::half(c.a)};
        Imath::half* p = half.data() + first * 4;
        for (size_t i = 0; i < count; ++i, p += 4)
            p[0] = h[0], p[1] = h[1], p[2] = h[2], p[3] = h[3];
    }
}

void ColorBuffer::resize(ColorFormat color_format, size_t pixels, glm::vec4 clear) {
    resizeUncleared(color_format, pixels);
    fill(0, pixels, clear);
}

} // namespace raster
