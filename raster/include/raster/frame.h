// Frame: the colour and depth target a pinhole render produces (the "framebuffer").
// Owned by the caller, resized by the renderer; rows are stored top row first.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace raster {

// 16-bit unorm or 32-bit float storage of D in [0,1] (see camera.h), a run-time choice.
enum class DepthFormat : uint8_t { Unorm16, Float32 };

struct DepthBuffer {
    DepthFormat format = DepthFormat::Float32;
    uint32_t width = 0;
    uint32_t height = 0;
    std::vector<uint16_t> unorm16;  // used when format == Unorm16
    std::vector<float> float32;     // used when format == Float32

    void resize(DepthFormat depth_format, uint32_t w, uint32_t h);
    // D at pixel index i, as a float in [0,1].
    float load(uint32_t i) const {
        return format == DepthFormat::Float32 ? float32[i] : float(unorm16[i]) * (1.0f / 65535.0f);
    }
};

// Round-to-nearest unorm16 encoding of D in [0,1].
inline uint16_t encodeUnorm16(float d) {
    const float clamped = d < 0.0f ? 0.0f : (d > 1.0f ? 1.0f : d);
    return uint16_t(clamped * 65535.0f + 0.5f);
}

struct Frame {
    uint32_t width = 0;
    uint32_t height = 0;
    std::vector<float> color;  // linear RGBA, 4 floats per pixel; alpha = coverage
    DepthBuffer depth;
};

}  // namespace raster
