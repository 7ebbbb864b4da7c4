// Layer spacing of Lee, Eisemann & Seidel 2009 §4.1 (Eq. 4): depth layers uniform in the signed
// circle of confusion C(d), with spacing delta pixels from d_near. Consumes a thin lens and the
// visible depth range of a pinhole frame; produces the M+1 layer bounds a raster::LayeredTarget
// is rendered with. Plain values; the caller owns the returned vectors.
//
//   Eq. 4:  l = floor( K d_f / delta * (1/d_near - 1/d) ),   K d_f (1/d_near - 1/d) = C(d) -
//   C(d_near)
//
// so the bound between layers l-1 and l is the depth where C(d) = C(d_near) + l * delta.
#pragma once

#include <dof/lens.h>
#include <raster/camera.h>
#include <raster/frame.h>
#include <raster/status.h>

#include <cstdint>
#include <vector>

namespace dof {

// Nearest and farthest distance along the view axis over the pixels of a pinhole frame that show
// geometry (stored depth < 1); background pixels are skipped, the clip planes are not used
// (§4.1 starts the layers at the visible d_near). `covered` is false when nothing is visible.
struct DepthRange {
    float near_d = 0.0f;
    float far_d = 0.0f;
    bool covered = false;
};
DepthRange visibleDepthRange(const raster::Frame& pinhole, const raster::View& view);

struct LayerSpacing {
    float delta_px = 0.0f;     // CoC growth from one layer to the next (§4.1's delta)
    uint32_t layers = 0;       // M
    float coc_near_px = 0.0f;  // C(d_near)
    float coc_far_px = 0.0f;   // C(d_far)
    std::vector<float> bounds; // M+1 increasing distances; bounds[0] <= d_near, bounds[M] >= d_far
    bool budget_limited = false; // delta was widened because M would exceed max_layers
};

// Layers of spacing `delta_px` (> 0) covering [range.near_d, range.far_d]:
// M = max(1, ceil((C(d_far) - C(d_near)) / delta)). When M would exceed `max_layers`, M =
// max_layers and delta grows to fit (budget_limited). Fails on a non-positive or non-finite delta,
// max_layers == 0, or an empty range. Messages name --layer-spacing.
raster::Result<LayerSpacing> layerSpacingFromDelta(const ThinLens& lens, const DepthRange& range,
                                                   float delta_px, uint32_t max_layers);

// A budget of exactly `layers` (>= 1) layers: delta = (C(d_far) - C(d_near)) / M (§4.1, "we can
// define a budget of layers"). Messages name --layers.
raster::Result<LayerSpacing> layerSpacingFromCount(const ThinLens& lens, const DepthRange& range,
                                                   uint32_t layers);

// The same two, into `out`: its bounds are resized in place, so a kept LayerSpacing with M+1
// bounds is filled without allocating. On failure `out` is unspecified.
raster::Status layerSpacingFromDelta(const ThinLens& lens, const DepthRange& range, float delta_px,
                                     uint32_t max_layers, LayerSpacing& out);
raster::Status layerSpacingFromCount(const ThinLens& lens, const DepthRange& range, uint32_t layers,
                                     LayerSpacing& out);

// Eq. 4: the layer of depth d, clamped to [0, M-1].
uint32_t layerIndex(const ThinLens& lens, const LayerSpacing& spacing, float depth);

} // namespace dof
