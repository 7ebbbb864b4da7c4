// Multiview's height-field traversal (§4.3): a lens ray's segment through one layer's stored
// depths by the false position or the scan (over a path walked per ray or in advance), and the
// N-buffer culling queries that skip layers, per ray and per pixel. Consumes the Tracer and the
// layer's depths and N-buffer (MultiviewScratch); produces Hit and culling decisions; owns
// nothing. Included only by multiview_tracer.cpp, so both traceTile copies inline it.
#pragma once

#include "multiview_tracer.h"

namespace dof::multiview_detail {
namespace {

// §4.3 "Ray Traversal": the lens ray's segment [s0, s1] in one height field (`depth`, a layer's
// stored D per texel) by the method of false position followed by a binary search. The ray's
// image position at depth t is p + C(t) * w (Eq. 2-3, lens.h), w = (-v.x, v.y), kept relative to
// pixel (x, y) as Tracer::offsetOf. `rec` counts the steps (multiview_tracer.cpp's recorders).
template <class Rec>
Hit traceHeightField(const Tracer& tr, const float* depth, float seg_near, float s0, float s1,
                     uint32_t x, uint32_t y, glm::vec2 w, TileCounters& cnt, Rec& rec) {
    struct Sample {
        float h; // stored D of the texel, or kEmptyDepth
        uint32_t texel;
        bool covered;
    };
    auto fetch = [&](float t) -> Sample {
        ++cnt.fetches;
        const glm::vec2 o = tr.offsetOf(w, t);
        const std::optional<uint32_t> texel = tr.texelAt(int64_t(x) + int64_t(std::floor(o.x)),
                                                         int64_t(y) + int64_t(std::floor(o.y)));
        if (!texel)
            return {kEmptyDepth, 0, false};
        const float h = depth[*texel];
        // Texels beyond the segment's far end count as empty, so N-buffer culling (min > far) is
        // exactly lossless. Texels before the layer's near bound are the near parts of triangles
        // routed here by their farthest vertex (§4.2); the fragment-copy pass put them in their
        // own layer, so here they count as empty too.
        return {h, *texel, h <= s1 && h >= seg_near};
    };
    // Signed distance f = t - h along the ray: f < 0 while the ray is in front of the surface.
    // Heights are bound by the layer's extents (§4.3). Empty texels (§4.3, Fig. 5 right) take the
    // far bound inside the segment and at its near end (the ray passes in front), and the near
    // bound at its far end, so the linear model always brackets an intersection in the layer.
    auto fInterior = [&](float t, const Sample& s) {
        return s.covered ? t - std::clamp(s.h, s0, s1) : t - s1;
    };
    auto fFarEnd = [&](const Sample& s) {
        return s.covered ? s1 - std::clamp(s.h, s0, s1) : s1 - s0;
    };

    float ta = s0, fa, tb = s1, fb;
    std::optional<Sample> b; // the sample at tb, fetched when needed
    bool bracketed = false;
    if (tr.settings->bound_init) {
        // §4.3's shortcut: take d_u, d_l as the layer's bounds (f(s0) = s0 - s1, f(s1) = s1 - s0),
        // so the first intersection point is the segment's middle; only when the texel under it
        // is empty are the two end lookups made.
        fa = s0 - s1, fb = s1 - s0;
        const float ti = 0.5f * (s0 + s1);
        if constexpr (Rec::kOn)
            ++rec.step->false_position_steps;
        const Sample si = fetch(ti);
        if (si.covered) {
            const float fi = fInterior(ti, si);
            if (fi >= 0.0f)
                tb = ti, fb = fi, b = si;
            else
                ta = ti, fa = fi;
            bracketed = true;
        }
    }
    if (!bracketed) {
        const Sample a = fetch(s0);
        fa = fInterior(s0, a);
        if (a.covered && fa >= 0.0f) // the surface is at or before the segment's start
            return {true, s0, a.texel, s1};
        b = fetch(s1);
        fb = fFarEnd(*b);
        // Method of false position: intersect the ray with the line through (ta, fa), (tb, fb).
        for (uint32_t k = 0; k < tr.settings->iterations; ++k) {
            const float denom = fb - fa;
            if (!(denom > 0.0f))
                break;
            const float ti = ta + (tb - ta) * (-fa / denom);
            if (!(ti > ta && ti < tb))
                break;
            if constexpr (Rec::kOn)
                ++rec.step->false_position_steps;
            const Sample si = fetch(ti);
            const float fi = fInterior(ti, si);
            if (fi >= 0.0f) { // the surface is before I: the crossing lies in [ta, ti]
                tb = ti, fb = fi, b = si;
                break;
            }
            ta = ti, fa = fi; // restart with the farther sub-segment
        }
    }
    // Binary search refinement of the bracket [ta, tb].
    for (uint32_t k = 0; k < tr.settings->refine_steps; ++k) {
        const float tm = 0.5f * (ta + tb);
        if (!(tm > ta && tm < tb))
            break;
        if constexpr (Rec::kOn)
            ++rec.step->binary_steps;
        const Sample sm = fetch(tm);
        const float fm = fInterior(tm, sm);
        if (fm >= 0.0f)
            tb = tm, fb = fm, b = sm;
        else
            ta = tm, fa = fm;
    }
    if (!b)
        b = fetch(tb); // the shortcut's far end, never looked up
    if (b->covered)
        return {true, tb, b->texel, s1}; // the height field is solid to the segment's end
    return {};
}

// The scan (cellHit, scanCell, scanHeightField, scanPath) is the alternative to the false position
// that §6 names ("brute-force scanning finds accurate intersection points"): walk every texel the
// segment's image path crosses (a 2D DDA) and stop in the first one whose surface the ray reaches
// while inside its column. A texel is solid over [h, h + thickness], so with a bounded thickness a
// ray that enters a column already behind its surface passes behind it.

// The scan's test of texel `texel` of depth h, whose column the ray crosses over [t_in, t_out]:
// covered as in the false position (texels outside the layer's extent [seg_near, s1] are
// empty), the ray reaches the surface inside this column and is not past its thickness.
bool cellHit(const Tracer& tr, float h, float seg_near, float s1, float t_in, float t_out,
             uint32_t texel, Hit& hit) {
    if (h <= s1 && h >= seg_near && h <= t_out && t_in - h <= tr.thickness_d) {
        const float t = std::clamp(h, t_in, t_out);
        hit = {true, t, texel, std::max(t, std::min(h + tr.thickness_d, s1))};
        return true;
    }
    return false;
}

// cellHit on the cell at offset (dx, dy) from pixel (x, y), as OffscreenPolicy reads it.
bool scanCell(const Tracer& tr, const float* depth, float seg_near, float s1, uint32_t x,
              uint32_t y, int64_t dx, int64_t dy, float t_in, float t_out, TileCounters& cnt,
              Hit& hit) {
    const std::optional<uint32_t> texel = tr.texelAt(int64_t(x) + dx, int64_t(y) + dy);
    if (!texel)
        return false;
    ++cnt.fetches;
    return cellHit(tr, depth[*texel], seg_near, s1, t_in, t_out, *texel, hit);
}

Hit scanHeightField(const Tracer& tr, const float* depth, float seg_near, float s0, float s1,
                    uint32_t x, uint32_t y, glm::vec2 w, TileCounters& cnt) {
    Hit hit;
    walkCells(tr.offsetOf(w, s0), tr.offsetOf(w, s1), s0, s1,
              [&](int64_t dx, int64_t dy, float t_in, float t_out) {
                  return scanCell(tr, depth, seg_near, s1, x, y, dx, dy, t_in, t_out, cnt, hit);
              });
    return hit;
}

// scanHeightField over a path walked in advance that lies in the image around pixel index
// `pixel` (y * width + x): no texel is clamped or left out (scanCell's test on texels addressed
// by their offsets).
Hit scanPathInside(const Tracer& tr, const float* depth, float seg_near, float s1, uint32_t pixel,
                   const RayPath& path, TileCounters& cnt) {
    Hit hit;
    const PathCell* cells = tr.cells.data() + path.first;
    for (uint32_t i = 0; i < path.count; ++i) {
        const PathCell& c = cells[i];
        const uint32_t texel = uint32_t(int64_t(pixel) + c.offset);
        if (cellHit(tr, depth[texel], seg_near, s1, c.t_in, c.t_out, texel, hit)) {
            cnt.fetches += i + 1;
            return hit;
        }
    }
    cnt.fetches += path.count;
    return hit;
}

// scanHeightField over a path walked in advance (the same cells, so the same result).
Hit scanPath(const Tracer& tr, const float* depth, float seg_near, float s1, uint32_t x, uint32_t y,
             const RayPath& path, TileCounters& cnt) {
    if (int64_t(x) + path.box_x0 >= 0 && int64_t(y) + path.box_y0 >= 0 &&
        int64_t(x) + path.box_x1 < int64_t(tr.width) &&
        int64_t(y) + path.box_y1 < int64_t(tr.height))
        return scanPathInside(tr, depth, seg_near, s1, y * tr.width + x, path, cnt);
    Hit hit;
    const PathCell* cells = tr.cells.data() + path.first;
    for (uint32_t i = 0; i < path.count; ++i) {
        const PathCell& c = cells[i];
        if (scanCell(tr, depth, seg_near, s1, x, y, c.dx, c.dy, c.t_in, c.t_out, cnt, hit))
            break;
    }
    return hit;
}

// Whether layer l has no texel within its segment in the texel box [x0, x1] x [y0, y1]
// (clamped to the image, as OffscreenPolicy::Clamp reads it): one N-buffer query, §4.3 early
// culling (the minimum depth in the window is beyond the layer's far bound).
// `beyond`: the depth past which texels do not count (the segment's far bound by default).
bool boxCulled(const Tracer& tr, uint32_t l, int64_t x0, int64_t x1, int64_t y0, int64_t y1,
               std::optional<float> beyond = std::nullopt) {
    const int64_t w_max = int64_t(tr.width) - 1, h_max = int64_t(tr.height) - 1;
    x0 = std::clamp<int64_t>(x0, 0, w_max), x1 = std::clamp<int64_t>(x1, 0, w_max);
    y0 = std::clamp<int64_t>(y0, 0, h_max), y1 = std::clamp<int64_t>(y1, 0, h_max);
    const int64_t size = std::max(x1 - x0, y1 - y0) + 1;
    return nBufferMin(tr.scratch->nbuffers[l], x0, y0, size) > beyond.value_or(tr.segs[l].t1);
}

// One of a layer's per-pixel culling queries (§4.3), set up once per tile: boxCulled on the
// window [x + lo, x + hi] x [y + lo, y + hi] around pixel (x, y) against `beyond`. Windows
// inside the image are four N-buffer lookups (NBufferWindow, the same value as nBufferMin);
// near the border boxCulled clamps them.
struct PixelCull {
    NBufferWindow window;
    int64_t lo = 0, hi = 0;
    float beyond = 0.0f;
};

PixelCull pixelCull(const Tracer& tr, uint32_t l, float r, float beyond) {
    PixelCull c;
    c.lo = int64_t(std::floor(0.5f - r)), c.hi = int64_t(std::floor(0.5f + r));
    c.window = NBufferWindow(tr.scratch->nbuffers[l], c.hi - c.lo + 1);
    c.beyond = beyond;
    return c;
}

bool culledAt(const Tracer& tr, uint32_t l, const PixelCull& c, uint32_t x, uint32_t y) {
    const int64_t x0 = int64_t(x) + c.lo, x1 = int64_t(x) + c.hi;
    const int64_t y0 = int64_t(y) + c.lo, y1 = int64_t(y) + c.hi;
    if (x0 >= 0 && y0 >= 0 && x1 < int64_t(tr.width) && y1 < int64_t(tr.height))
        return c.window.minInside(x0, y0) > c.beyond;
    return boxCulled(tr, l, x0, x1, y0, y1, c.beyond);
}

// A tile layer's three per-pixel queries: culled() with the cone margin and with margin 0, and
// the window of the missed cones' first lookups against the owned interval's far bound.
struct LayerCulls {
    PixelCull cone, ray, first_cone;
};

LayerCulls layerCulls(const Tracer& tr, uint32_t l) {
    const LayerSeg& seg = tr.segs[l];
    return {pixelCull(tr, l, seg.reach_px + seg.cone_px, seg.t1),
            pixelCull(tr, l, seg.reach_px, seg.t1), pixelCull(tr, l, seg.first_cone_px, seg.own1)};
}

// Early culling per pixel (§4.3). `culls`: layerCulls of each tile layer (with culling on).
PixelLayers pixelLayers(const Tracer& tr, uint32_t x, uint32_t y, const uint32_t* tile_layers,
                        uint32_t tile_layer_count, const LayerCulls* culls, TileCounters& cnt) {
    const MultiviewSettings& s = *tr.settings;
    PixelLayers pl;
    for (uint32_t i = 0; i < tile_layer_count; ++i) {
        const uint32_t l = tile_layers[i];
        const float cone_px = tr.segs[l].cone_px;
        if (s.culling && culledAt(tr, l, culls[i].cone, x, y)) {
            ++cnt.culled_pixel;
            continue;
        }
        const bool hittable = !s.culling || cone_px == 0.0f || !culledAt(tr, l, culls[i].ray, x, y);
        // The missed cones' first lookup (missCone) reads within first_cone_px of the pixel
        // centre (clamped to the image, so nearer to it) and finds coverage only where the
        // layer owns a texel (depth <= own1): when none is there, no missed cone of the pixel
        // sees anything in the layer, and a layer only cones could see holds nothing for it.
        const bool cones =
            cone_px > 0.0f && (!s.culling || !culledAt(tr, l, culls[i].first_cone, x, y));
        if (!hittable && !cones) {
            ++cnt.culled_pixel;
            continue;
        }
        pl.hittable |= uint64_t(hittable) << l;
        pl.cones |= uint64_t(cones) << l;
        pl.active |= uint64_t(1) << l;
    }
    return pl;
}

} // namespace
} // namespace dof::multiview_detail
