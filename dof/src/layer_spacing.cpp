#include "out_of_memory.h"

#include <dof/layer_spacing.h>
#include <dof/settings_table.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <new>
#include <string>

namespace dof {

using raster::Status;

namespace {

// Margin so that the nearest and farthest visible depths fall strictly inside the bounds.
constexpr float kRangeMargin = 1e-4f;

void makeSpacing(const ThinLens& lens, const DepthRange& range, uint32_t layers, float delta_px,
                 LayerSpacing& s) {
    s.budget_limited = false;
    s.layers = layers;
    s.delta_px = delta_px;
    s.coc_near_px = cocRadiusPx(lens, range.near_d);
    s.coc_far_px = cocRadiusPx(lens, range.far_d);
    s.bounds.resize(layers + 1);
    s.bounds[0] = range.near_d * (1.0f - kRangeMargin);
    s.bounds[layers] = range.far_d * (1.0f + kRangeMargin);
    // Bound l sits where C(d) = C(d_near) + l * delta (Eq. 4 inverted):
    // 1/d = 1/d_f - C / (E f_px).
    const double k = double(lens.aperture_radius) * double(lens.focal_length_px);
    for (uint32_t l = 1; l < layers; ++l) {
        const double c = double(s.coc_near_px) + double(l) * double(delta_px);
        const double inv_d = 1.0 / double(lens.focus_distance) - c / k;
        float d = inv_d > 0.0 ? float(1.0 / inv_d) : s.bounds[layers];
        d = std::clamp(d, s.bounds[l - 1], s.bounds[layers]);
        s.bounds[l] = d;
    }
    // Keep the bounds strictly increasing (raster::renderLayers requires it) even when float
    // rounding collapses two neighbours.
    for (uint32_t l = 1; l <= layers; ++l)
        if (!(s.bounds[l] > s.bounds[l - 1]))
            s.bounds[l] = std::nextafter(s.bounds[l - 1], INFINITY);
}

Status checkRange(const DepthRange& range) {
    if (!range.covered)
        return Status::error("multiview: nothing is visible, no depth range to decompose");
    if (!(range.near_d > 0.0f) || !std::isfinite(range.far_d) || range.far_d < range.near_d)
        return Status::error("multiview: invalid visible depth range");
    return {};
}

} // namespace

DepthRange visibleDepthRange(const raster::Frame& pinhole, const raster::View& view) {
    DepthRange r;
    // distanceFromDepth never decreases as D grows, so when both ends of the stored depths give
    // valid distances, every depth between them does and the ends are the range.
    const raster::VisibleDepthBounds b = raster::visibleDepthBounds(pinhole);
    if (!b.any)
        return r;
    const float near_d = raster::distanceFromDepth(view, b.min);
    const float far_d = raster::distanceFromDepth(view, b.max);
    auto valid = [](float d) { return std::isfinite(d) && d > 0.0f; };
    if (valid(near_d) && valid(far_d)) {
        r.near_d = near_d;
        r.far_d = far_d;
        r.covered = true;
        return r;
    }
    // Otherwise (an infinite far end): one pass in pixel order over the valid distances; min and
    // max are order-independent, so this is deterministic.
    float lo = INFINITY, hi = 0.0f;
    raster::forEachVisibleDepth(pinhole, [&](float stored) {
        const float d = raster::distanceFromDepth(view, stored);
        if (!valid(d))
            return;
        lo = std::min(lo, d);
        hi = std::max(hi, d);
    });
    if (hi > 0.0f) {
        r.near_d = lo;
        r.far_d = hi;
        r.covered = true;
    }
    return r;
}

Status layerSpacingFromDelta(const ThinLens& lens, const DepthRange& range, float delta_px,
                             uint32_t max_layers, LayerSpacing& out) try {
    if (!std::isfinite(delta_px) || !(delta_px > 0.0f))
        return settingsError("multiview", "layer_spacing_px must be > 0");
    if (max_layers == 0)
        return settingsError("multiview", "the layer budget must be at least 1");
    if (Status st = checkRange(range); !st.ok())
        return st;
    const double span =
        double(cocRadiusPx(lens, range.far_d)) - double(cocRadiusPx(lens, range.near_d));
    const double wanted = std::ceil(span / double(delta_px));
    uint32_t m = uint32_t(std::clamp(wanted, 1.0, 1e6));
    bool limited = false;
    float delta = delta_px;
    if (m > max_layers) {
        m = max_layers;
        delta = float(span / double(m));
        limited = true;
    }
    makeSpacing(lens, range, m, delta, out);
    out.budget_limited = limited;
    return {};
} catch (const std::bad_alloc&) {
    return detail::outOfMemory("spacing the layers");
}

Status layerSpacingFromCount(const ThinLens& lens, const DepthRange& range, uint32_t layers,
                             LayerSpacing& out) try {
    if (layers == 0)
        return settingsError("multiview", "layers must be at least 1");
    if (Status st = checkRange(range); !st.ok())
        return st;
    const double span =
        double(cocRadiusPx(lens, range.far_d)) - double(cocRadiusPx(lens, range.near_d));
    makeSpacing(lens, range, layers, float(span / double(layers)), out);
    return {};
} catch (const std::bad_alloc&) {
    return detail::outOfMemory("spacing the layers");
}

raster::Result<LayerSpacing> layerSpacingFromDelta(const ThinLens& lens, const DepthRange& range,
                                                   float delta_px, uint32_t max_layers) try {
    LayerSpacing s;
    if (Status st = layerSpacingFromDelta(lens, range, delta_px, max_layers, s); !st.ok())
        return st;
    return s;
} catch (const std::bad_alloc&) {
    return detail::outOfMemory("spacing the layers");
}

raster::Result<LayerSpacing> layerSpacingFromCount(const ThinLens& lens, const DepthRange& range,
                                                   uint32_t layers) try {
    LayerSpacing s;
    if (Status st = layerSpacingFromCount(lens, range, layers, s); !st.ok())
        return st;
    return s;
} catch (const std::bad_alloc&) {
    return detail::outOfMemory("spacing the layers");
}

uint32_t layerIndex(const ThinLens& lens, const LayerSpacing& spacing, float depth) {
    if (spacing.layers <= 1 || !(spacing.delta_px > 0.0f))
        return 0;
    // Eq. 4 with K d_f (1/d_near - 1/d) = C(d) - C(d_near).
    const double l = std::floor((double(cocRadiusPx(lens, depth)) - double(spacing.coc_near_px)) /
                                double(spacing.delta_px));
    return uint32_t(std::clamp(l, 0.0, double(spacing.layers - 1)));
}

} // namespace dof
