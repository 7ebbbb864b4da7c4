// Storage formats of render targets: depth in 16-bit unorm or 32-bit float, colour (RGBA) in
// 16-bit half (Imath) or 32-bit float. The choice is made at run time; loads return float.
// Buffers are plain arrays owned by the target that holds them.
#pragma once

#include <Imath/half.h>
#include <glm/vec4.hpp>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <utility>
#include <vector>

namespace raster {

// 16-bit unorm or 32-bit float storage of D in [-1, 0] (see camera.h).
enum class DepthFormat : uint8_t { Unorm16, Float32 };

// Stored depth at the near plane and at the far plane (also the clear value: nothing drawn).
constexpr float kNearDepth = -1.0f;
constexpr float kFarDepth = 0.0f;
// RGBA colour storage.
enum class ColorFormat : uint8_t { Half, Float32 };

// Bytes one stored value takes: a depth, or an RGBA colour.
constexpr uint32_t bytesPerDepth(DepthFormat f) {
    return f == DepthFormat::Unorm16 ? 2 : 4;
}
constexpr uint32_t bytesPerColor(ColorFormat f) {
    return f == ColorFormat::Half ? 8 : 16;
}

// Round-to-nearest unorm16 encoding of D in [-1, 0] as code (D + 1) * 65535: the far plane is
// 65535. A fixed-point code gains nothing from reversing (its steps are uniform either way).
inline uint16_t encodeUnorm16(float d) {
    const float u = d + 1.0f;
    const float clamped = u < 0.0f ? 0.0f : (u > 1.0f ? 1.0f : u);
    return uint16_t(clamped * 65535.0f + 0.5f);
}
// Exact at the far plane: code 65535 decodes to 0 (kFarDepth).
inline float decodeUnorm16(uint16_t code) {
    return float(int32_t(code) - 65535) * (1.0f / 65535.0f);
}

struct DepthBuffer {
    DepthFormat format = DepthFormat::Float32;
    uint32_t width = 0;
    uint32_t height = 0;
    std::vector<uint16_t> unorm16; // used when format == Unorm16
    std::vector<float> float32;    // used when format == Float32

    // Resizes and clears to the far value kFarDepth.
    void resize(DepthFormat depth_format, uint32_t w, uint32_t h);
    // Resizes without clearing (kept values stay, new ones are 0 in either format), for a
    // renderer whose tiles each clear their own pixels with fill: the clear then runs on every
    // thread, while the tile's pixels are about to be written anyway.
    void resizeUncleared(DepthFormat depth_format, uint32_t w, uint32_t h);
    // Sets the `count` values from index `first` to d.
    void fill(size_t first, size_t count, float d);
    // D at pixel index i, as a float in [-1, 0].
    float load(size_t i) const {
        return format == DepthFormat::Float32 ? float32[i] : decodeUnorm16(unorm16[i]);
    }
    // The value D would have once stored (the depth test compares stored values).
    float quantize(float d) const {
        return format == DepthFormat::Float32 ? d : decodeUnorm16(encodeUnorm16(d));
    }
    void store(size_t i, float d) {
        if (format == DepthFormat::Float32)
            float32[i] = d;
        else
            unorm16[i] = encodeUnorm16(d);
    }
    size_t bytes() const { return unorm16.size() * 2 + float32.size() * 4; }
};

// A std::allocator under which a vector's resize leaves new elements uninitialised, for a buffer
// whose users clear what they use (ColorBuffer::resizeUncleared and fill). Imath::half's
// value-initialisation is a store loop per element (5 instructions each), on one thread.
template <class T> struct UninitializedAllocator : std::allocator<T> {
    template <class U> struct rebind { using other = UninitializedAllocator<U>; };
    UninitializedAllocator() = default;
    template <class U> UninitializedAllocator(const UninitializedAllocator<U>&) noexcept {}
    template <class U> void construct(U* p) noexcept { ::new (static_cast<void*>(p)) U; }
    template <class U, class... Args> void construct(U* p, Args&&... args) {
        ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
    }
};

struct ColorBuffer {
    ColorFormat format = ColorFormat::Float32;
    // 4 per pixel, used when format == Half
    std::vector<Imath::half, UninitializedAllocator<Imath::half>> half;
    std::vector<float> float32; // 4 per pixel, used when format == Float32

    // Resizes to `pixels` RGBA values, all set to `clear`.
    void resize(ColorFormat color_format, size_t pixels, glm::vec4 clear);
    // Resizes without clearing, as DepthBuffer::resizeUncleared (but new half values are not
    // set at all), and sets the `count` colours from pixel `first` to c.
    void resizeUncleared(ColorFormat color_format, size_t pixels);
    void fill(size_t first, size_t count, glm::vec4 c);
    glm::vec4 load(size_t i) const {
        if (format == ColorFormat::Float32)
            return {float32[4 * i], float32[4 * i + 1], float32[4 * i + 2], float32[4 * i + 3]};
        return {float(half[4 * i]), float(half[4 * i + 1]), float(half[4 * i + 2]),
                float(half[4 * i + 3])};
    }
    void store(size_t i, glm::vec4 c) {
        if (format == ColorFormat::Float32) {
            float32[4 * i] = c.r, float32[4 * i + 1] = c.g, float32[4 * i + 2] = c.b;
            float32[4 * i + 3] = c.a;
        } else {
            half[4 * i] = Imath::half(c.r), half[4 * i + 1] = Imath::half(c.g);
            half[4 * i + 2] = Imath::half(c.b), half[4 * i + 3] = Imath::half(c.a);
        }
    }
    size_t bytes() const { return half.size() * 2 + float32.size() * 4; }
};

} // namespace raster
