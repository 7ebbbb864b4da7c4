// Multiview's per-frame tracer state, shared by its translation units: multiview.cpp builds the
// Tracer once per frame, multiview_setup.cpp fills its segments, mipmap views and paths, and
// multiview_tracer.cpp traces the tiles with it. The Tracer owns only its per-frame vectors
// (segments, paths, mip views); what it points to (view, lens, samples, layers, scratch) is the
// caller's. The inline helpers here run per ray: they are inlined into both traceTile copies.
#pragma once

#include <dof/multiview.h>
#include <raster/surface_shading.h>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

namespace dof::multiview_detail {

// Stored depth of an empty layer texel in the scratch copy: above every real D in [-1, 0].
constexpr float kEmptyDepth = 2.0f;
// Channels of MultiviewScratch::owned_mips: D a, a, r a, g a, b a.
constexpr int kOwnedChannels = 5;
// Most mip levels built for cone tracing (a 256-pixel cone diameter).
constexpr uint32_t kMaxMipLevels = 8;
// 1 / 2^level: image positions to a level's texels.
constexpr std::array<float, kMaxMipLevels> kMipScale = {1.0f,    0.5f,     0.25f,     0.125f,
                                                        0.0625f, 0.03125f, 0.015625f, 0.0078125f};

// A path walked in advance is culled per ray only when longer than this: an N-buffer query
// costs about as much as scanning that many cells (tracing time on demo, dense and foliage at
// N = 64 with thresholds 0, 4, 8 and never: 8 and never were fastest, 0 slowest by 10-20 %).
constexpr uint32_t kRayCullMinCells = 8;

// The mip levels a trilinear lookup of a `diameter`-pixel window reads (§4.4): l0 and l1 = l0 + 1
// (clamped to the top level), blended by f.
struct MipLevel {
    uint32_t l0 = 0, l1 = 0;
    float f = 0.0f;
};

// One level of a layer mipmap (MultiviewScratch) as the lookups read it, flattened per frame.
// The level stores its rows [row0, row1) only (MultiviewScratch::mip_row0); the others are 0,
// read from `zero`, a row of zeros at least as wide.
struct MipView {
    const float* data = nullptr; // row row0
    const float* zero = nullptr;
    int64_t width = 0, height = 0;
    int64_t row0 = 0, row1 = 0;
    float last_u = 0.0f, last_v = 0.0f; // width - 1, height - 1: the last interior taps
    // Rows v and v + 1 are both stored when first_v <= v < stored_v (row0 and row1 - 1).
    float first_v = 0.0f, stored_v = 0.0f;
};
using MipChain = std::array<MipView, kMaxMipLevels>;

// Per-layer constants of the traversal, in stored depth D (the ray is a straight line in
// (x, y, D) because both the image offset C and D are affine in 1/d: Eq. 3 and camera.h).
struct LayerSeg {
    float t0 = 0.0f, t1 = 0.0f;     // segment bounds in D (overlapped interval, §4.2)
    float own0 = 0.0f, own1 = 0.0f; // the layer's own (not overlapped) interval in D
    float reach_px = 0.0f;          // farthest image offset of any ray in the segment
    // A ray missing the layer looks its cone up at stored depth t_cone
    // (MultiviewSettings::cone_misses); the lookup reads texels within cone_px of the ray's
    // position there (0: misses are not coned).
    float t_cone = 0.0f, cone_px = 0.0f;
    float coc_cone = 0.0f; // C(t_cone): the same for every ray, so computed once
    MipLevel cone_level;   // the levels of that first lookup (its diameter is lambda |C(t_cone)|)
    uint32_t cone_last_level = 0; // lastConeLevel(cone_level)
    // MultiviewScratch::owned_empty_blocks of the layer (null without missed cones)
    const uint8_t* cone_empty_blocks = nullptr;
    // Every ray's first lookup reads texels within first_cone_px of its pixel's centre: the ray
    // is within r_max |C(t_cone)| of it at t_cone, and a bilinear tap of level L within 1.5 2^L
    // of the ray (+1 for rounding).
    float first_cone_px = 0.0f;
    bool empty = true;
    bool transparent = false; // the transparent plane has content
    // With paths walked in advance, where a pixel's surface is seen by all its rays in its own
    // texel (inFocusPixel): every ray's path crosses the pixel's own texel column over at least
    // [focus_t0, focus_t1] (focus_t0 > focus_t1: some ray misses it), and the cells it crosses
    // before lie in the offset box focus_box (empty when x0 > x1).
    float focus_t0 = 1.0f, focus_t1 = -1.0f;
    struct {
        int32_t x0 = 0, x1 = -1, y0 = 0, y1 = -1;
    } focus_box;
    // With paths walked in advance: the union of every sample's path box in this segment
    // (RayPath offsets; empty when x0 > x1), so one test per pixel tells whether all of its
    // paths lie in the image, and whether any path is long enough to be culled per ray.
    struct {
        int32_t x0 = 0, x1 = -1, y0 = 0, y1 = -1;
    } paths_box;
    bool long_paths = false; // some path has more than kRayCullMinCells cells
};

// One traced ray's result inside a layer.
struct Hit {
    bool hit = false;
    float t = 0.0f;
    uint32_t texel = 0;
    // Where the centre ray leaves the solid slab of the surface it hit (its depth plus the
    // thickness; the paper's height field is solid to the segment's end): a continuation behind
    // a partially covered cone (§4.4's c2) starts there, so it does not meet the surface whose
    // coverage was just counted again (in this layer's neighbours or the next layer's overlap).
    float t_behind = 0.0f;
};

// Image positions along a lens ray are kept relative to its pixel's corner (x, y): the ray is
// at (x, y) + o(t) with o(t) = (0.5, 0.5) + C(t) w (Eq. 2-3). The texel under it is
// (x + floor(o.x), y + floor(o.y)), so rays of one lens sample cross the same cells relative to
// their pixels, whatever the pixel: their paths can be walked once per frame (RayPath).
struct PathCell {
    int32_t dx = 0, dy = 0;          // texel offset from the pixel
    int32_t offset = 0;              // dy * width + dx: the texel's index minus the pixel's
    float t_in = 0.0f, t_out = 0.0f; // stored D where the ray enters / leaves the texel's column
};

// The cells one lens ray crosses in a segment [s0, s1] (Tracer::cells[first, first + count)), in
// order, and their bounding box as offsets (the per-ray culling window).
struct RayPath {
    int32_t box_x0 = 0, box_x1 = 0, box_y0 = 0, box_y1 = 0;
    uint32_t first = 0, count = 0;
};

struct TileCounters {
    uint64_t rays = 0, discarded = 0, background = 0, layer_tests = 0, culled_pixel = 0,
             culled_tile = 0, culled_ray = 0, cone_partial = 0, cone_missed = 0, fetches = 0,
             transparent_hits = 0, layer_steps = 0, pixels_in_focus = 0;
};

// One lens ray between the layers of its pixel (traceTile traces a tile layer by layer, so each
// ray's state waits here while the other rays of the tile meet the same layer).
struct RayState {
    LensSample lens;            // jittered lens position (§4.5) and weight
    glm::vec2 w{0.0f};          // image offset per unit C (lensRayImageOffset)
    glm::vec2 wc{0.0f};         // where its cones are centred, per unit C (ConeCentre)
    glm::vec3 color{0.0f};      // what it has seen so far
    float transmit = 1.0f;      // (1 - v1) products of partially covered cones (§4.4); 0: ended
    float t_resume = -INFINITY; // where a continuation behind a partial cone starts (§4.4)
    float t_end = 0.0f;
    bool discarded = false; // its path starts outside the image (OffscreenPolicy::Discard)
};

// Everything the per-pixel loop reads; built once per frame.
struct Tracer {
    const raster::View* view = nullptr;
    const ThinLens* lens = nullptr;
    const LensSampleSet* samples = nullptr;
    const raster::LayeredTarget* layers = nullptr;
    const MultiviewSettings* settings = nullptr;
    const ShadingInputs* shading = nullptr;
    const MultiviewScratch* scratch = nullptr;
    const raster::Frame* pinhole = nullptr;
    const raster::SurfaceShader* shader = nullptr; // view-dependent shading (§5)
    std::vector<LayerSeg> segs;
    uint32_t width = 0, height = 0; // the layers': the image and its guard band
    // The output image's pixel (x, y) is the layers' (x + guard, y + guard)
    // (MultiviewSettings::guard_band_px); the tracer works in the layers' coordinates.
    uint32_t guard = 0, image_width = 0, image_height = 0;
    float coc_a = 0.0f, coc_b = 0.0f; // C(D) = coc_a + coc_b * D
    // With a shared sample set and the scan (RayPath): path k * segs.size() + l is ray k through
    // layer l's whole segment; empty otherwise.
    std::vector<RayPath> paths;
    std::vector<PathCell> cells;
    float lambda = 0.0f;
    float r_max = 1.0f; // bound of |v| over every lens position a ray may use
    // ConeCentre::Cell: per sample, its cone centre's image offset per unit C relative to the
    // ray's (the cell offset with x negated, as lensRayImageOffset); empty: cones on the rays.
    std::vector<glm::vec2> cone_offsets;
    // With the shared sample set (JitterMode::None): ray k's state before the first layer, the
    // same for every pixel (beginRays copies it); empty otherwise.
    std::vector<RayState> first_rays;
    // Per layer: its colour, owned and transparent mipmaps (MultiviewScratch), where built.
    std::vector<MipChain> mips, owned_mips, transparent_mips;
    std::vector<float> zero_row;  // MipView::zero: a row of the widest level, kOwnedChannels wide
    float thickness_d = INFINITY; // MultiviewSettings::thickness_px as a span of stored depth D
    bool in_focus = false;        // pixels in focus are resolved without tracing (inFocusPixel)
    glm::vec3 background{0.0f};

    // Every field as a new Tracer's, the vectors emptied with their capacity kept (a Tracer kept
    // in MultiviewScratch from frame to frame is reset at the start of each).
    void reset() {
        Tracer fresh;
        const auto keep = [](auto& kept, auto& into) {
            kept.clear();
            into.swap(kept);
        };
        keep(segs, fresh.segs);
        keep(paths, fresh.paths);
        keep(cells, fresh.cells);
        keep(cone_offsets, fresh.cone_offsets);
        keep(first_rays, fresh.first_rays);
        keep(mips, fresh.mips);
        keep(owned_mips, fresh.owned_mips);
        keep(transparent_mips, fresh.transparent_mips);
        fresh.zero_row.swap(zero_row); // kept as it is: zeros
        *this = std::move(fresh);
    }

    float cocOf(float t) const { return coc_a + coc_b * t; }
    // The output image's pixel index of the layers' pixel (x, y), inside the image.
    size_t imagePixel(uint32_t x, uint32_t y) const {
        return size_t(y - guard) * image_width + (x - guard);
    }
    bool inImage(float px, float py) const {
        return px >= 0.0f && py >= 0.0f && px < float(width) && py < float(height);
    }
    // The ray's offset from its pixel's corner at stored depth t (PathCell).
    glm::vec2 offsetOf(glm::vec2 w, float t) const {
        const float c = cocOf(t);
        return {0.5f + c * w.x, 0.5f + c * w.y};
    }
    // The texel at (qx, qy) as OffscreenPolicy says: clamped to the image, or none outside it.
    std::optional<uint32_t> texelAt(int64_t qx, int64_t qy) const {
        if (settings->offscreen == OffscreenPolicy::Clamp) {
            qx = std::clamp<int64_t>(qx, 0, int64_t(width) - 1);
            qy = std::clamp<int64_t>(qy, 0, int64_t(height) - 1);
        } else if (qx < 0 || qy < 0 || qx >= int64_t(width) || qy >= int64_t(height)) {
            return std::nullopt;
        }
        return uint32_t(qy) * width + uint32_t(qx);
    }
};

// walkCells visits the cells of the path from offset o0 (at s0) to o1 (at s1) in order, as
// visit(dx, dy, t_in, t_out), until visit returns true. The walk stays within the cells of the
// two end points, the per-ray culling box, so culling stays lossless.
template <class Visit>
void walkCells(glm::vec2 o0, glm::vec2 o1, float s0, float s1, Visit&& visit) {
    int64_t ix = int64_t(std::floor(o0.x)), iy = int64_t(std::floor(o0.y));
    const int64_t end_x = int64_t(std::floor(o1.x)), end_y = int64_t(std::floor(o1.y));
    const int64_t step_x = end_x > ix ? 1 : -1, step_y = end_y > iy ? 1 : -1;
    // u in [0, 1] along the path at which it crosses the next column / row boundary (advanced
    // by the per-cell step); an axis whose end cell is reached is not stepped again.
    const float dx = std::fabs(o1.x - o0.x), dy = std::fabs(o1.y - o0.y);
    const float delta_x = dx > 0.0f ? 1.0f / dx : INFINITY;
    const float delta_y = dy > 0.0f ? 1.0f / dy : INFINITY;
    float next_x =
        ix == end_x ? INFINITY : (step_x > 0 ? float(ix + 1) - o0.x : o0.x - float(ix)) * delta_x;
    float next_y =
        iy == end_y ? INFINITY : (step_y > 0 ? float(iy + 1) - o0.y : o0.y - float(iy)) * delta_y;
    float u_in = 0.0f;
    for (;;) {
        const float u_out = std::min({next_x, next_y, 1.0f});
        if (visit(ix, iy, s0 + u_in * (s1 - s0), s0 + u_out * (s1 - s0)))
            return;
        if (ix == end_x && iy == end_y)
            return;
        u_in = std::min(u_out, 1.0f);
        if (next_x <= next_y) {
            ix += step_x;
            next_x = ix == end_x ? INFINITY : next_x + delta_x;
        } else {
            iy += step_y;
            next_y = iy == end_y ? INFINITY : next_y + delta_y;
        }
    }
}

inline MipLevel mipLevelFor(const Tracer& tr, float diameter) {
    const uint32_t top = uint32_t(tr.scratch->mip_width.size()) - 1;
    // log2(1) = 0: windows up to a pixel read level 0 without the logarithm.
    const float level = diameter > 1.0f ? std::clamp(std::log2(diameter), 0.0f, float(top)) : 0.0f;
    const uint32_t l0 = uint32_t(level);
    return {l0, std::min(l0 + 1, top), level - float(l0)};
}

// The level whose taps decide a trilinear lookup on lv is empty (mipEmptyAt): l1 when the
// lookup blends two levels, else l0.
inline uint32_t lastConeLevel(MipLevel lv) {
    return lv.l1 != lv.l0 && lv.f != 0.0f ? lv.l1 : lv.l0;
}

// The cells a path from offset o0 to o1 can cross lie in the box of its end cells.
struct CellBox {
    int64_t x0, x1, y0, y1;
};
inline CellBox cellBox(glm::vec2 o0, glm::vec2 o1) {
    return {int64_t(std::floor(std::min(o0.x, o1.x))), int64_t(std::floor(std::max(o0.x, o1.x))),
            int64_t(std::floor(std::min(o0.y, o1.y))), int64_t(std::floor(std::max(o0.y, o1.y)))};
}

// The layers a pixel's rays can meet, as bit masks over layer indices.
struct PixelLayers {
    uint64_t active = 0;   // not culled for the pixel (§4.3): its rays or missed cones may meet it
    uint64_t hittable = 0; // its rays can hit it at all (else only the cones see it)
    uint64_t cones = 0;    // its rays' missed cones may see something there (missCone)
    bool resolved = false; // in focus, written without tracing (inFocusPixel)
};

// traceTile (multiview_tracer.cpp): the rays of the pixels [x0, x1) x [y0, y1), compiled for the
// baseline x86-64 and for AVX2 with the same bytes; traceTileFor picks the copy (AVX2 when
// `simd` and the CPU allow it, raster::useAvx2).
using TraceTileFn = void (*)(const Tracer& tr, uint32_t x0, uint32_t x1, uint32_t y0, uint32_t y1,
                             const uint32_t* tile_layers, uint32_t tile_layer_count, RayState* rays,
                             PixelLayers* pixel_layers, float* rgba, TileCounters& cnt);
TraceTileFn traceTileFor(bool simd);

// The layers the rays of output tile [x0, x1) x [y0, y1) (in the layers' coordinates) visit, front
// to back, into `out` (raster::kMaxLayers entries), and their count: the non-empty layers, less
// those with nothing in reach of the whole tile (one N-buffer query each, §4.3; counted in
// cnt.culled_tile).
uint32_t tileLayers(const Tracer& tr, uint32_t x0, uint32_t x1, uint32_t y0, uint32_t y1,
                    uint32_t* out, TileCounters& cnt);

// probeMultiview's tracing (pixel (x, y) of the output image): the pixel's tile layers and its
// rays traced by the baseline traceTile with a recorder into `out`.
void probePixel(const Tracer& tr, uint32_t x, uint32_t y, MultiviewPixelProbe& out);

// Whether layer l has no texel within `margin` pixels of what the rays of the pixels
// [x0, x1] x [y0, y1] cross: a ray stays within reach_px of its pixel centre in the layer, so it
// reads texel offsets within [floor(0.5 - reach), floor(0.5 + reach)] of its pixel (PathCell).
// Margin 0: no ray can hit the layer; cone_px: their missed cones see nothing either.
bool culled(const Tracer& tr, uint32_t l, uint32_t x0, uint32_t x1, uint32_t y0, uint32_t y1,
            float margin);

} // namespace dof::multiview_detail
