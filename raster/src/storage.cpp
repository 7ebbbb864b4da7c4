#include <raster/frame.h>

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

}  // namespace raster
