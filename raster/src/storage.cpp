#include <raster/storage.h>

namespace raster {

void DepthBuffer::resize(DepthFormat depth_format, uint32_t w, uint32_t h) {
    format = depth_format;
    width = w;
    height = h;
    const size_t n = size_t(w) * h;
    if (format == DepthFormat::Float32) {
        float32.assign(n, 1.0f);
        unorm16.clear();
    } else {
        unorm16.assign(n, uint16_t(65535));
        float32.clear();
    }
}

void ColorBuffer::resize(ColorFormat color_format, size_t pixels, glm::vec4 clear) {
    format = color_format;
    half.clear();
    float32.clear();
    if (format == ColorFormat::Float32) {
        float32.resize(pixels * 4);
        for (size_t i = 0; i < pixels; ++i)
            store(i, clear);
    } else {
        half.resize(pixels * 4);
        for (size_t i = 0; i < pixels; ++i)
            store(i, clear);
    }
}

} // namespace raster
