// Frame: the colour and depth target a pinhole render produces (the "framebuffer").
// Owned by the caller, resized by the renderer; rows are stored top row first.
#pragma once

#include <raster/storage.h>

#include <cstdint>
#include <vector>

namespace raster {

struct Frame {
    uint32_t width = 0;
    uint32_t height = 0;
    std::vector<float> color; // linear RGBA, 4 floats per pixel
    DepthBuffer depth;
};

} // namespace raster
