// Frame: the colour and depth target a pinhole render produces (the "framebuffer").
// Owned by the caller, resized by the renderer; rows are stored top row first.
#pragma once

#include <raster/memory_budget.h>
#include <raster/storage.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace raster {

struct Frame {
    uint32_t width = 0;
    uint32_t height = 0;
    std::vector<float> color; // linear RGBA, 4 floats per pixel
    DepthBuffer depth;
    // Stored D of the nearest BLEND fragment blended over each pixel (1 where none). BLEND
    // surfaces do not write `depth`, yet they are visible (and get blurred): whatever needs the
    // visible depths reads both. Sized only when the scene has BLEND materials.
    DepthBuffer transparent_depth;
};

// Bytes of the buffers a width x height Frame holds (colour, depth, and with BLEND materials the
// transparent depth): what Renderer::render checks against the memory budget.
inline uint64_t frameBytes(uint32_t width, uint32_t height, DepthFormat depth_format,
                           bool transparency) {
    const uint64_t per_pixel =
        4 * sizeof(float) + uint64_t{bytesPerDepth(depth_format)} * (transparency ? 2 : 1);
    return mulBytes(uint64_t{width} * height, per_pixel);
}

// Calls fn(stored D) for every visible surface depth of the frame: the opaque depth and the
// nearest BLEND surface of each covered pixel (D < kFarDepth), in pixel order.
template <class Fn> void forEachVisibleDepth(const Frame& frame, Fn&& fn) {
    const size_t pixels = size_t(frame.width) * frame.height;
    const bool transparent = frame.transparent_depth.bytes() > 0;
    for (size_t i = 0; i < pixels; ++i) {
        if (const float d = frame.depth.load(i); d < kFarDepth)
            fn(d);
        if (transparent)
            if (const float d = frame.transparent_depth.load(i); d < kFarDepth)
                fn(d);
    }
}

// The smallest and largest of those depths (none: `any` false). A function that never decreases
// as D grows, such as distanceFromDepth, takes its extremes over the visible depths at these two,
// so a frame-wide range needs one division at each end instead of one per pixel.
struct VisibleDepthBounds {
    float min = kFarDepth, max = kFarDepth; // kFarDepth when none
    bool any = false;
};
inline VisibleDepthBounds visibleDepthBounds(const Frame& frame) {
    // One buffer's extremes over its values below kFarDepth (NaN never is), on the stored
    // values: min and max of distinct negative floats do not depend on the order, and the
    // unorm16 decoding never decreases as the code grows (code 65535 is kFarDepth).
    float lo = INFINITY, hi = -INFINITY;
    bool any = false;
    auto scan = [&](const DepthBuffer& depth) {
        const size_t n = size_t(depth.width) * depth.height;
        if (depth.format == DepthFormat::Float32) {
            const float* p = depth.float32.data();
            for (size_t i = 0; i < n; ++i)
                if (const float d = p[i]; d < kFarDepth) {
                    lo = d < lo ? d : lo;
                    hi = d > hi ? d : hi;
                    any = true;
                }
        } else {
            const uint16_t* p = depth.unorm16.data();
            uint16_t code_lo = 0xffff, code_hi = 0;
            bool seen = false;
            for (size_t i = 0; i < n; ++i)
                if (const uint16_t c = p[i]; c < 0xffff) {
                    code_lo = std::min(code_lo, c);
                    code_hi = std::max(code_hi, c);
                    seen = true;
                }
            if (seen) {
                lo = std::min(lo, decodeUnorm16(code_lo));
                hi = std::max(hi, decodeUnorm16(code_hi));
                any = true;
            }
        }
    };
    scan(frame.depth);
    scan(frame.transparent_depth);
    VisibleDepthBounds b;
    if (any)
        b = {lo, hi, true};
    return b;
}

} // namespace raster
