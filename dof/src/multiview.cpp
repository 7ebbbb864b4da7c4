#include <dof/float4.h>
#include <dof/multiview.h>
#include <raster/simd.h>
#include <raster/surface_shading.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>

namespace dof {

using raster::Status;

namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// Stored depth of an empty layer texel in the scratch copy: above every real D in [-1, 0].
constexpr float kEmptyDepth = 2.0f;
// Cone coverage at or above this ends the traversal (the cone is fully blocked, §4.4).
constexpr float kFullCoverage = 0.999f;
// Channels of MultiviewScratch::owned_mips: D a, a, r a, g a, b a.
constexpr int kOwnedChannels = 5;
// Most mip levels built for cone tracing (a 256-pixel cone diameter).
constexpr uint32_t kMaxMipLevels = 8;
// 1 / 2^level: image positions to a level's texels.
constexpr std::array<float, kMaxMipLevels> kMipScale = {1.0f,    0.5f,     0.25f,     0.125f,
                                                        0.0625f, 0.03125f, 0.015625f, 0.0078125f};
// Most cells walked in advance (PathCell; 20 bytes each).
constexpr double kMaxPathCells = double(1u << 22);
// Largest image offset a ray may reach (pixels): beyond it the lens is rejected as absurd for the
// view (offsets are then still exact in float and fit RayPath's int32 boxes).
constexpr float kMaxReachPx = float(1u << 24);
// A path walked in advance is culled per ray only when longer than this: an N-buffer query
// costs about as much as scanning that many cells (tracing time on demo, dense and foliage at
// N = 64 with thresholds 0, 4, 8 and never: 8 and never were fastest, 0 slowest by 10-20 %).
constexpr uint32_t kRayCullMinCells = 8;
constexpr float kPi = 3.14159265358979f;

// The mip levels a trilinear lookup of a `diameter`-pixel window reads (§4.4): l0 and l1 = l0 + 1
// (clamped to the top level), blended by f.
struct MipLevel {
    uint32_t l0 = 0, l1 = 0;
    float f = 0.0f;
};

// One level of a layer mipmap (MultiviewScratch) as the lookups read it, flattened per frame.
struct MipView {
    const float* data = nullptr;
    int64_t width = 0, height = 0;
    float last_u = 0.0f, last_v = 0.0f; // width - 1, height - 1: the last interior taps
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
    MipLevel cone_level; // the levels of that first lookup (its diameter is lambda |C(t_cone)|)
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
    uint32_t width = 0, height = 0;
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
    // Per layer: its colour, owned and transparent mipmaps (MultiviewScratch), where built.
    std::vector<MipChain> mips, owned_mips, transparent_mips;
    float thickness_d = INFINITY; // MultiviewSettings::thickness_px as a span of stored depth D
    bool in_focus = false;        // pixels in focus are resolved without tracing (inFocusPixel)
    glm::vec3 background{0.0f};

    float cocOf(float t) const { return coc_a + coc_b * t; }
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

float distanceFromD(const raster::View& view, float d_stored) {
    return raster::distanceFromDepth(view, d_stored);
}

// §4.3 "Ray Traversal": the lens ray's segment [s0, s1] in one height field (`depth`, a layer's
// stored D per texel) by the method of false position followed by a binary search. The ray's
// image position at depth t is p + C(t) * w (Eq. 2-3, lens.h), w = (-v.x, v.y), kept relative to
// pixel (x, y) as Tracer::offsetOf.
Hit traceHeightField(const Tracer& tr, const float* depth, float seg_near, float s0, float s1,
                     uint32_t x, uint32_t y, glm::vec2 w, TileCounters& cnt) {
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

// The alternative to the false position that §6 names ("brute-force scanning finds accurate
// intersection points"): walk every texel the segment's image path crosses (a 2D DDA) and stop
// in the first one whose surface the ray reaches while inside its column. A texel is solid over
// [h, h + thickness], so with a bounded thickness a ray that enters a column already behind its
// surface passes behind it.
//
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

// scanHeightField over a path walked in advance (the same cells, so the same result).
Hit scanPath(const Tracer& tr, const float* depth, float seg_near, float s1, uint32_t x, uint32_t y,
             const RayPath& path, TileCounters& cnt) {
    Hit hit;
    const PathCell* cells = tr.cells.data() + path.first;
    if (int64_t(x) + path.box_x0 >= 0 && int64_t(y) + path.box_y0 >= 0 &&
        int64_t(x) + path.box_x1 < int64_t(tr.width) &&
        int64_t(y) + path.box_y1 < int64_t(tr.height)) {
        // The whole path lies in the image: no texel is clamped or left out (scanCell's test
        // on texels addressed by their offsets).
        const uint32_t pixel = y * tr.width + x;
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
    for (uint32_t i = 0; i < path.count; ++i) {
        const PathCell& c = cells[i];
        if (scanCell(tr, depth, seg_near, s1, x, y, c.dx, c.dy, c.t_in, c.t_out, cnt, hit))
            break;
    }
    return hit;
}

MipLevel mipLevelFor(const Tracer& tr, float diameter) {
    const uint32_t top = uint32_t(tr.scratch->mip_width.size()) - 1;
    // log2(1) = 0: windows up to a pixel read level 0 without the logarithm.
    const float level = diameter > 1.0f ? std::clamp(std::log2(diameter), 0.0f, float(top)) : 0.0f;
    const uint32_t l0 = uint32_t(level);
    return {l0, std::min(l0 + 1, top), level - float(l0)};
}

// Trilinear lookup of the first C channels of a layer mipmap `mip` with Stride channels per
// texel (§4.4) at image position (px, py) on the levels `lv`. Channels 0-3 are weighted as one
// vector (C = 2 reads four and keeps two: a texel has Stride >= 4 channels); a fifth is scalar.
template <int C, int Stride = C>
std::array<float, C> sampleMip(const MipChain& mip, float px, float py, MipLevel lv) {
    static_assert(C <= 5 && Stride >= 4 && Stride >= C);
    struct Taps {
        Float4 v;
        float e; // channel 4 when C == 5
    };
    auto bilinear = [&](uint32_t level) {
        const MipView& m = mip[level];
        const int64_t w = m.width, h = m.height;
        const float scale = kMipScale[level];
        const float u = px * scale - 0.5f, v = py * scale - 0.5f;
        const float fu = std::floor(u), fv = std::floor(v);
        const float au = u - fu, av = v - fv;
        const float* r0;
        const float* r1;
        int64_t x0, x1;
        if (fu >= 0.0f && fv >= 0.0f && fu < m.last_u && fv < m.last_v) {
            // Inside the level: the four texels need no clamping (the usual case).
            x0 = int64_t(fu) * Stride;
            x1 = x0 + Stride;
            r0 = m.data + size_t(int64_t(fv) * w) * Stride;
            r1 = r0 + size_t(w) * Stride;
        } else {
            // Clamped to the level (the position may lie far outside it when a clamped ray
            // read a border texel).
            const int64_t iu = int64_t(std::clamp(fu, -1.0f, float(w)));
            const int64_t iv = int64_t(std::clamp(fv, -1.0f, float(h)));
            x0 = std::clamp<int64_t>(iu, 0, w - 1) * Stride;
            x1 = std::clamp<int64_t>(iu + 1, 0, w - 1) * Stride;
            r0 = m.data + size_t(std::clamp<int64_t>(iv, 0, h - 1) * w) * Stride;
            r1 = m.data + size_t(std::clamp<int64_t>(iv + 1, 0, h - 1) * w) * Stride;
        }
        const float bu = 1.0f - au, bv = 1.0f - av;
        Taps out;
        const Float4 top_row = loadFloat4(r0 + x0) * bu + loadFloat4(r0 + x1) * au;
        const Float4 bottom = loadFloat4(r1 + x0) * bu + loadFloat4(r1 + x1) * au;
        out.v = top_row * bv + bottom * av;
        out.e = 0.0f;
        if constexpr (C == 5) {
            const float top4 = r0[x0 + 4] * bu + r0[x1 + 4] * au;
            const float bottom4 = r1[x0 + 4] * bu + r1[x1 + 4] * au;
            out.e = top4 * bv + bottom4 * av;
        }
        return out;
    };
    Taps c0 = bilinear(lv.l0);
    if (lv.l1 != lv.l0 && lv.f != 0.0f) {
        const Taps c1 = bilinear(lv.l1);
        const float g = 1.0f - lv.f;
        c0.v = c0.v * g + c1.v * lv.f;
        c0.e = c0.e * g + c1.e * lv.f;
    }
    std::array<float, C> out;
    for (int c = 0; c < C; ++c)
        out[c] = c < 4 ? c0.v[c] : c0.e;
    return out;
}

// Whether sampleMip on `mip` (Stride channels per texel, a non-negative coverage in channel
// `channel`) at (px, py) on the levels lv returns exactly 0 in that channel because every
// texel it reads is empty there: when both levels' taps lie inside their levels, the taps of
// the finer level l0 lie in the 2x2 blocks the coarser level's four taps average (u0 = 2 u1 +
// 1/2), so four zero coverages at the last level read decide it. False when unsure.
template <int Stride>
bool mipEmptyAt(const MipChain& mip, int channel, float px, float py, MipLevel lv) {
    const float* taps = nullptr;
    int64_t row = 0;
    for (const uint32_t level : {lv.l0, lv.l1}) {
        const MipView& m = mip[level];
        const float scale = kMipScale[level];
        const float fu = std::floor(px * scale - 0.5f), fv = std::floor(py * scale - 0.5f);
        if (!(fu >= 0.0f && fv >= 0.0f && fu < m.last_u && fv < m.last_v))
            return false;
        row = m.width * Stride;
        taps = m.data + (int64_t(fv) * m.width + int64_t(fu)) * Stride + channel;
        if (lv.l1 == lv.l0 || lv.f == 0.0f)
            break; // sampleMip reads l0 only
    }
    return taps[0] == 0.0f && taps[Stride] == 0.0f && taps[row] == 0.0f &&
           taps[row + Stride] == 0.0f;
}

// The same for a window of `diameter` pixels.
template <int C, int Stride = C>
std::array<float, C> sampleMip(const Tracer& tr, const MipChain& mip, float px, float py,
                               float diameter) {
    return sampleMip<C, Stride>(mip, px, py, mipLevelFor(tr, diameter));
}

// A layer's premultiplied coverage mipmap (RGBA, alpha = coverage) at a cone (§4.4).
glm::vec4 sampleCone(const Tracer& tr, const MipChain& mip, float px, float py, float diameter) {
    const std::array<float, 4> m = sampleMip<4>(tr, mip, px, py, diameter);
    return {m[0], m[1], m[2], m[3]};
}

glm::vec3 envLookup(const EnvironmentMap& env, glm::vec3 dir) {
    const float u = 0.5f + std::atan2(dir.x, -dir.z) / (2.0f * kPi);
    const float v = std::acos(std::clamp(dir.y, -1.0f, 1.0f)) / kPi;
    const uint32_t x = std::min(uint32_t(std::max(u, 0.0f) * float(env.width)), env.width - 1);
    const uint32_t y = std::min(uint32_t(std::max(v, 0.0f) * float(env.height)), env.height - 1);
    const float* p = env.rgb.data() + (size_t(y) * env.width + x) * 3;
    return glm::vec3(p[0], p[1], p[2]) * env.intensity;
}

// World position of texel `texel` at stored depth t (pinhole through the lens centre).
glm::vec3 texelWorld(const Tracer& tr, uint32_t texel, float t) {
    const raster::View& view = *tr.view;
    const float d = distanceFromD(view, t);
    const uint32_t ix = texel % tr.width, iy = texel / tr.width;
    const float f_px = tr.lens->focal_length_px;
    const float sx = (float(ix) + 0.5f - 0.5f * float(tr.width)) / f_px;
    const float sy = (float(iy) + 0.5f - 0.5f * float(tr.height)) / f_px;
    return view.eye + d * (view.forward + sx * view.right - sy * view.up);
}

// With an environment map: a Schlick-Fresnel mirror reflection attenuated by roughness.
glm::vec3 envReflection(const Tracer& tr, const raster::GSample& g, glm::vec3 world,
                        glm::vec3 eye) {
    const EnvironmentMap* env = tr.settings->env_map;
    if (!env || g.unlit != 0.0f)
        return glm::vec3(0.0f);
    const glm::vec3 vdir = glm::normalize(eye - world);
    const float n_dot_v = std::max(glm::dot(g.normal, vdir), 0.0f);
    const glm::vec3 r = glm::reflect(-vdir, g.normal);
    const glm::vec3 f0 = glm::mix(glm::vec3(0.04f), g.base_color, g.metallic);
    const float m = 1.0f - n_dot_v;
    const glm::vec3 fresnel = f0 + (glm::vec3(1.0f) - f0) * (m * m * m * m * m);
    const float gloss = (1.0f - g.roughness) * (1.0f - g.roughness);
    return fresnel * gloss * envLookup(*env, r);
}

// §5: shade G-buffer sample g at `world` from lens point `eye`: the rasterizer's Phong model
// (raster::SurfaceShader) plus the environment reflection.
glm::vec3 shadeSample(const Tracer& tr, const raster::GSample& g, glm::vec3 world, glm::vec3 eye) {
    return tr.shader->shade(g, world, eye) + envReflection(tr, g, world, eye);
}

glm::vec3 shadeHit(const Tracer& tr, uint32_t l, uint32_t texel, float t, glm::vec3 eye) {
    const raster::LayeredTarget& lt = *tr.layers;
    return shadeSample(tr, lt.gbuffer[lt.index(l, texel)], texelWorld(tr, texel, t), eye);
}

// §4.4 + §5: the mean shaded colour of the covered texels among five taps of a cone of radius
// `radius` px around image position (px, py) in layer l (the centre and +-radius/2 along x and
// y), each shaded at its own stored depth; none when no tap is covered.
std::optional<glm::vec3> shadeTaps(const Tracer& tr, uint32_t l, float px, float py, float radius,
                                   glm::vec3 eye) {
    const raster::LayeredTarget& lt = *tr.layers;
    const std::vector<float>& depth = tr.scratch->depth[l];
    const float hr = 0.5f * radius;
    const std::array<glm::vec2, 5> taps = {
        {{0.0f, 0.0f}, {-hr, 0.0f}, {hr, 0.0f}, {0.0f, -hr}, {0.0f, hr}}};
    glm::vec3 sum(0.0f);
    uint32_t count = 0;
    for (const glm::vec2& o : taps) {
        const float x = std::floor(px + o.x), y = std::floor(py + o.y);
        if (x < 0.0f || y < 0.0f || x >= float(tr.width) || y >= float(tr.height))
            continue;
        const uint32_t ti = uint32_t(y) * tr.width + uint32_t(x);
        if (!(lt.color.load(lt.index(l, ti)).a > 0.0f))
            continue;
        sum += shadeHit(tr, l, ti, depth[ti], eye);
        ++count;
    }
    if (count == 0)
        return std::nullopt;
    return sum / float(count);
}

// The shaded colour of a cone hit on texel `texel` at depth t: ConeShading::Footprint uses the
// taps (the hit texel when none is covered), Centre shades the hit texel.
glm::vec3 shadeFootprint(const Tracer& tr, uint32_t l, uint32_t texel, float t, float px, float py,
                         float radius, glm::vec3 eye) {
    if (tr.settings->cone_shading == ConeShading::Footprint && radius > 0.5f)
        if (const std::optional<glm::vec3> c = shadeTaps(tr, l, px, py, radius, eye))
            return *c;
    return shadeHit(tr, l, texel, t, eye);
}

// The lens position of sample k at pixel (x, y) under the jitter mode (§4.5), and its weight.
LensSample jitteredSample(const Tracer& tr, uint32_t x, uint32_t y, uint32_t k,
                          const std::array<float, 4>& noise, uint32_t halton_offset) {
    const MultiviewSettings& s = *tr.settings;
    switch (s.jitter) {
    case JitterMode::None:
        return tr.samples->sample(k);
    case JitterMode::Rotate:
        return tr.samples->sample(x, y, k);
    case JitterMode::Halton: {
        const LensSampleSet& seq = *s.sequence_2n;
        return seq.sample((halton_offset + k) % seq.size());
    }
    case JitterMode::Noise: {
        // 16 pairwise combinations (n_i, n_j) of the texel's four components, each applied to
        // 1/16th of the samples, scaled to half the mean sample spacing (§4.5).
        LensSample ls = tr.samples->sample(k);
        const uint32_t combo = k % 16;
        const glm::vec2 off(noise[combo / 4], noise[combo % 4]);
        glm::vec2 p = ls.position + tr.lambda * off;
        const float len = glm::length(p);
        if (len > tr.r_max)
            p *= tr.r_max / len; // stay within the aperture's radius
        ls.position = p;
        return ls;
    }
    }
    return tr.samples->sample(k);
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

// Whether layer l has no texel within `margin` pixels of what the rays of the pixels
// [x0, x1] x [y0, y1] cross: a ray stays within reach_px of its pixel centre in the layer, so it
// reads texel offsets within [floor(0.5 - reach), floor(0.5 + reach)] of its pixel (PathCell).
// Margin 0: no ray can hit the layer; cone_px: their missed cones see nothing either.
bool culled(const Tracer& tr, uint32_t l, uint32_t x0, uint32_t x1, uint32_t y0, uint32_t y1,
            float margin) {
    const float r = tr.segs[l].reach_px + margin;
    const int64_t lo = int64_t(std::floor(0.5f - r)), hi = int64_t(std::floor(0.5f + r));
    return boxCulled(tr, l, int64_t(x0) + lo, int64_t(x1) + hi, int64_t(y0) + lo, int64_t(y1) + hi);
}

// A missed ray's cone (MultiviewSettings::cone_misses): coverage v1 and mean colour c1 of the
// layer texels around the ray where it passes them, at stored depth t.
struct MissCone {
    float v1 = 0.0f;
    glm::vec3 c1{0.0f};
    float t = 0.0f;
};

// The paper (§4.4) evaluates a cone only "given an impact point", so rays passing beside a small
// or thin object between the lens samples never see it. Here a ray that crossed layer l's
// segment without a hit is thickened too. The cone is placed where the ray passes the layer's
// content: first at the middle of the layer (t_cone), then at the mean depth of the covered
// texels found there (where a ray passes a small object depends on the object's depth, through
// C). Coverage and colour count only the texels the layer owns ([own0, own1], owned_mips), so a
// surface in the overlap of two layers is coned once (per-ray shading, §5, shades the covered
// texels among the footprint's taps, as for a hit). Off the image the cone is looked up at the
// image border under OffscreenPolicy::Clamp (the border texels stand in for the unseen content,
// as for a clamped hit) and not at all under Discard; the culling windows, clamped to the
// image, then still hold every texel read. None when the cone sees nothing. w: the cone centre's
// image offset per unit C (the ray's, or its cell's with ConeCentre::Cell).
std::optional<MissCone> missCone(const Tracer& tr, uint32_t l, float cx, float cy, glm::vec2 w,
                                 bool shade, glm::vec3 eye, TileCounters& cnt) {
    const LayerSeg& seg = tr.segs[l];
    // Where the ray is at stored depth t: off the image, clamped to its border (as a clamped
    // ray reads the border texels, OffscreenPolicy::Clamp) or none (Discard).
    auto at = [&](float t, float& px, float& py) {
        const float c = tr.cocOf(t);
        px = cx + c * w.x, py = cy + c * w.y;
        if (tr.inImage(px, py))
            return true;
        if (tr.settings->offscreen != OffscreenPolicy::Clamp)
            return false;
        px = std::clamp(px, 0.0f, std::nextafter(float(tr.width), 0.0f));
        py = std::clamp(py, 0.0f, std::nextafter(float(tr.height), 0.0f));
        return true;
    };
    float px = 0.0f, py = 0.0f;
    if (!at(seg.t_cone, px, py))
        return std::nullopt;
    const MipChain& owned = tr.owned_mips[l];
    // Most rays pass where the layer owns nothing near them: no coverage, no lookup.
    if (mipEmptyAt<kOwnedChannels>(owned, 1, px, py, seg.cone_level))
        return std::nullopt;
    const std::array<float, 2> d = sampleMip<2, kOwnedChannels>(owned, px, py, seg.cone_level);
    if (!(d[1] > 0.0f))
        return std::nullopt;
    MissCone cone;
    cone.t = std::clamp(d[0] / d[1], seg.t0, seg.t1);
    const float diameter = tr.lambda * std::fabs(tr.cocOf(cone.t));
    if (!at(cone.t, px, py) || !(diameter > 1.0f))
        return std::nullopt;
    const std::array<float, kOwnedChannels> m =
        sampleMip<kOwnedChannels>(tr, owned, px, py, diameter);
    if (!(m[1] > 0.0f))
        return std::nullopt;
    ++cnt.cone_missed;
    cone.v1 = std::min(m[1], 1.0f);
    cone.c1 = glm::vec3(m[2], m[3], m[4]) / m[1];
    if (shade && tr.settings->cone_shading == ConeShading::Footprint)
        cone.c1 = shadeTaps(tr, l, px, py, 0.5f * diameter, eye).value_or(cone.c1);
    return cone;
}

// The cells a path from offset o0 to o1 can cross lie in the box of its end cells.
struct CellBox {
    int64_t x0, x1, y0, y1;
};
CellBox cellBox(glm::vec2 o0, glm::vec2 o1) {
    return {int64_t(std::floor(std::min(o0.x, o1.x))), int64_t(std::floor(std::max(o0.x, o1.x))),
            int64_t(std::floor(std::min(o0.y, o1.y))), int64_t(std::floor(std::max(o0.y, o1.y)))};
}

// The path of ray direction w through [s0, s1]: its cells appended to `cells`.
RayPath walkPath(const Tracer& tr, glm::vec2 w, float s0, float s1, std::vector<PathCell>& cells) {
    RayPath p;
    const glm::vec2 o0 = tr.offsetOf(w, s0), o1 = tr.offsetOf(w, s1);
    const CellBox box = cellBox(o0, o1); // |offsets| < kMaxReachPx: int32 holds them
    p.box_x0 = int32_t(box.x0), p.box_x1 = int32_t(box.x1);
    p.box_y0 = int32_t(box.y0), p.box_y1 = int32_t(box.y1);
    p.first = uint32_t(cells.size());
    walkCells(o0, o1, s0, s1, [&](int64_t dx, int64_t dy, float t_in, float t_out) {
        cells.push_back(
            {int32_t(dx), int32_t(dy), int32_t(dy * int64_t(tr.width) + dx), t_in, t_out});
        return false;
    });
    p.count = uint32_t(cells.size()) - p.first;
    return p;
}

// One lens ray between the layers of its pixel (traceTile traces a tile layer by layer, so each
// ray's state waits here while the other rays of the tile meet the same layer).
struct RayState {
    LensSample lens;       // jittered lens position (§4.5) and weight
    glm::vec2 w{0.0f};     // image offset per unit C (lensRayImageOffset)
    glm::vec2 wc{0.0f};    // where its cones are centred, per unit C (ConeCentre)
    glm::vec3 color{0.0f}; // what it has seen so far
    float transmit = 1.0f; // (1 - v1) products of partially covered cones (§4.4); 0: ended
    float t_resume = -1.0f;
    float t_end = 0.0f;
    bool discarded = false; // its path starts outside the image (OffscreenPolicy::Discard)
};

// The layers a pixel's rays can meet, as bit masks over layer indices.
struct PixelLayers {
    uint64_t active = 0;   // not culled for the pixel (§4.3): its rays or missed cones may meet it
    uint64_t hittable = 0; // its rays can hit it at all (else only the cones see it)
    bool resolved = false; // in focus, written without tracing (inFocusPixel)
};

// The records of pixel (x, y)'s rays in sample order when it is the debug pixel, else null.
// beginRays sizes them (`size` rays) before anything is recorded; the others pass 0.
MultiviewRayRecord* debugRecords(const Tracer& tr, uint32_t x, uint32_t y, uint32_t size = 0) {
    const MultiviewSettings& s = *tr.settings;
    if (!s.debug_rays || x != s.debug_x || y != s.debug_y)
        return nullptr;
    if (size > 0)
        s.debug_rays->assign(size, MultiviewRayRecord{});
    return s.debug_rays->data();
}

// Whether pixel (x, y)'s ray with offset w lies in the image at stored depth t.
bool rayInside(const Tracer& tr, uint32_t x, uint32_t y, glm::vec2 w, float t) {
    const glm::vec2 o = tr.offsetOf(w, t);
    return o.x >= -float(x) && o.y >= -float(y) && o.x < float(tr.width - x) &&
           o.y < float(tr.height - y);
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
        if (!hittable) {
            // Only the missed cones can see this layer. Their first lookup (missCone) reads
            // within first_cone_px of the pixel centre (clamped to the image, so nearer to it)
            // and finds coverage only where the layer owns a texel (depth <= own1): when none
            // is there, the layer holds nothing for this pixel. (Not asked of hittable layers:
            // the query costs more than the lookups it saves there.)
            if (culledAt(tr, l, culls[i].first_cone, x, y)) {
                ++cnt.culled_pixel;
                continue;
            }
        }
        pl.hittable |= uint64_t(hittable) << l;
        pl.active |= uint64_t(1) << l;
    }
    return pl;
}

// A pixel in focus, resolved without tracing. Let l be its nearest active layer (nothing nearer
// can be hit or seen by a cone: per-pixel culling with the cone margin) and h the depth of its
// own texel there. When h lies where every ray crosses the own texel's column (LayerSeg::
// focus_t0/t1), and no texel the rays cross before it can stop them (each such cell is left
// at D <= focus_t0, so a texel deeper than focus_t0, or nearer than the segment, is no hit for
// cellHit), the scan (scanPath) hits the own texel at h with every ray. There is no cone (lambda
// |C(h)| <= 1), so each ray's colour is the texel's, and the mean is summed as endPixel sums
// it: the same bits as tracing the rays. Writes the pixel and returns true, or returns false
// when the rays have to be traced.
bool inFocusPixel(const Tracer& tr, uint32_t x, uint32_t y, const PixelLayers& pl, float* out,
                  TileCounters& cnt) {
    if (pl.active == 0)
        return false;
    const uint32_t l = uint32_t(std::countr_zero(pl.active));
    const LayerSeg& seg = tr.segs[l];
    const float* depth = tr.scratch->depth[l].data();
    const uint32_t texel = y * tr.width + x;
    const float h = depth[texel];
    if (!((pl.hittable >> l) & 1) || seg.transparent ||
        !(h >= seg.t0 && h >= seg.focus_t0 && h <= seg.focus_t1) ||
        (tr.settings->cone && tr.lambda * std::fabs(tr.cocOf(h)) > 1.0f))
        return false;
    const auto& box = seg.focus_box;
    if (box.x0 <= box.x1) {
        if (int64_t(x) + box.x0 < 0 || int64_t(y) + box.y0 < 0 ||
            int64_t(x) + box.x1 >= int64_t(tr.width) || int64_t(y) + box.y1 >= int64_t(tr.height))
            return false; // clamped reads near the border: traced
        for (int32_t dy = box.y0; dy <= box.y1; ++dy)
            for (int32_t dx = box.x0; dx <= box.x1; ++dx) {
                const float hb = depth[int64_t(texel) + int64_t(dy) * tr.width + dx];
                if ((dx != 0 || dy != 0) && hb >= seg.t0 && hb <= seg.focus_t0)
                    return false;
            }
    }
    const raster::LayeredTarget& lt = *tr.layers;
    const glm::vec3 c(lt.color.load(lt.index(l, texel)));
    double sum_r = 0.0, sum_g = 0.0, sum_b = 0.0, sum_w = 0.0;
    for (uint32_t k = 0; k < tr.samples->size(); ++k) {
        const double wt = double(tr.samples->sample(k).weight);
        sum_r += wt * double(c.r);
        sum_g += wt * double(c.g);
        sum_b += wt * double(c.b);
        sum_w += wt;
    }
    out[0] = float(sum_r / sum_w);
    out[1] = float(sum_g / sum_w);
    out[2] = float(sum_b / sum_w);
    out[3] = 1.0f;
    cnt.rays += tr.samples->size();
    ++cnt.pixels_in_focus;
    return true;
}

// The start of each of pixel (x, y)'s rays.
void beginRays(const Tracer& tr, uint32_t x, uint32_t y, RayState* rays, TileCounters& cnt) {
    const MultiviewSettings& s = *tr.settings;
    // Per-pixel jitter keys (§4.5): a pure function of (x, y, seed).
    std::array<float, 4> noise{};
    uint32_t halton_offset = 0;
    if (s.jitter == JitterMode::Noise)
        for (uint32_t c = 0; c < 4; ++c)
            noise[c] = hashToUnit(hashWords(x, y, s.seed, 0x6e6f6973u + c)) - 0.5f;
    if (s.jitter == JitterMode::Halton)
        halton_offset = hashWords(x, y, s.seed, 0x68616c74u) % s.sequence_2n->size();
    const uint32_t n = tr.samples->size();
    const float t_first = tr.segs.front().t0;
    const float cx = float(x) + 0.5f, cy = float(y) + 0.5f;
    MultiviewRayRecord* records = debugRecords(tr, x, y, n);
    for (uint32_t k = 0; k < n; ++k) {
        ++cnt.rays;
        RayState& ray = rays[k];
        ray = RayState{};
        ray.lens = jitteredSample(tr, x, y, k, noise, halton_offset);
        ray.w = glm::vec2(-ray.lens.position.x, ray.lens.position.y);
        ray.wc = tr.cone_offsets.empty() ? ray.w : ray.w + tr.cone_offsets[k];
        ray.t_end = tr.segs.back().t1;
        MultiviewRayRecord* rec = records ? records + k : nullptr;
        if (rec) {
            rec->lens = ray.lens.position;
            rec->weight = ray.lens.weight;
            rec->t_start = t_first;
            rec->start_px = glm::vec2(cx, cy) + tr.cocOf(t_first) * ray.w;
        }
        if (s.offscreen == OffscreenPolicy::Discard && !rayInside(tr, x, y, ray.w, t_first)) {
            ++cnt.discarded; // the path starts outside the image
            ray.discarded = true;
            ray.transmit = 0.0f;
            if (rec)
                rec->discarded = true, rec->t_end = t_first, rec->end_px = rec->start_px;
        }
    }
}

// Ray k of pixel (x, y) through layer l (§4.3-§4.4): its opaque hit or miss, the layer's
// transparent plane in front of it, and the cone of either.
void traceLayer(const Tracer& tr, uint32_t x, uint32_t y, uint32_t l, bool hittable, uint32_t k,
                RayState& ray, MultiviewRayRecord* rec, TileCounters& cnt) {
    const MultiviewSettings& s = *tr.settings;
    const raster::View& view = *tr.view;
    const raster::LayeredTarget& lt = *tr.layers;
    const bool shade = s.view_dependent || s.env_map;
    const float cx = float(x) + 0.5f, cy = float(y) + 0.5f;
    const glm::vec2 w = ray.w, wc = ray.wc;
    // Where this ray's hits are shaded from (§5): its lens point, or the lens centre.
    const glm::vec3 shade_from =
        s.view_dependent ? view.eye + tr.lens->aperture_radius * (ray.lens.position.x * view.right +
                                                                  ray.lens.position.y * view.up)
                         : view.eye;
    // §4.4: a cone of coverage v1 and colour c1 gives v1 c1 + (1 - v1) c2, c2 what the rest
    // of the ray sees; from kFullCoverage on it blocks the ray (returns true).
    auto blend = [&](float v1, glm::vec3 c1) {
        if (v1 >= kFullCoverage) {
            ray.color += ray.transmit * c1;
            ray.transmit = 0.0f;
            return true;
        }
        ray.color += ray.transmit * v1 * c1;
        ray.transmit *= 1.0f - v1;
        return false;
    };
    ++cnt.layer_steps;
    const LayerSeg& seg = tr.segs[l];
    const float s0 = std::max(seg.t0, ray.t_resume);
    if (!(s0 < seg.t1))
        return;
    // The whole segment's path walked in advance, unless the ray resumes inside it.
    const RayPath* path =
        !tr.paths.empty() && s0 == seg.t0 ? &tr.paths[size_t(k) * tr.segs.size() + l] : nullptr;
    bool can_hit = hittable;
    if (can_hit && s.culling && (!path || path->count > kRayCullMinCells)) {
        // Per-ray culling: the texels this ray's segment can read lie in the box of its end
        // points; one N-buffer query skips the height-field test when none of them is within
        // the layer (the same test as §4.3's per-pixel culling, on a smaller window, so it is
        // just as lossless). Short paths walked in advance are scanned without it.
        const CellBox box = path ? CellBox{path->box_x0, path->box_x1, path->box_y0, path->box_y1}
                                 : cellBox(tr.offsetOf(w, s0), tr.offsetOf(w, seg.t1));
        if (boxCulled(tr, l, int64_t(x) + box.x0, int64_t(x) + box.x1, int64_t(y) + box.y0,
                      int64_t(y) + box.y1)) {
            ++cnt.culled_ray;
            can_hit = false;
        }
    }
    auto trace = [&](const std::vector<float>& depth, float near, float t_a, float t_b) {
        return s.traversal == Traversal::Scan
                   ? scanHeightField(tr, depth.data(), near, t_a, t_b, x, y, w, cnt)
                   : traceHeightField(tr, depth.data(), near, t_a, t_b, x, y, w, cnt);
    };
    Hit h;
    if (can_hit) {
        ++cnt.layer_tests;
        h = path ? scanPath(tr, tr.scratch->depth[l].data(), seg.t0, seg.t1, x, y, *path, cnt)
                 : trace(tr.scratch->depth[l], seg.t0, s0, seg.t1);
    }
    // A ray that crossed the whole segment without a hit still has a cone (missCone),
    // composited in depth order with the transparent plane.
    std::optional<MissCone> miss;
    if (!h.hit && seg.cone_px > 0.0f && s0 == seg.t0)
        miss = missCone(tr, l, cx, cy, wc, shade, shade_from, cnt);
    auto addMiss = [&] {
        if (blend(miss->v1, miss->c1))
            ray.t_end = miss->t;
        if (rec) {
            rec->layer = int32_t(l);
            ++rec->missed_cones;
        }
        miss.reset();
    };
    // The layer's transparent plane in front of its opaque hit. The plane holds only depths of
    // the layer's own interval (LayerSink routes each BLEND fragment to the one layer owning
    // its depth), so only that part of the segment is searched. Its premultiplied colour is
    // added and the rest of the ray is seen through (1 - opacity); with cone tracing both come
    // from its mipmap (§4.4).
    const float ta = std::max(s0, seg.own0);
    const float tb = std::min(h.hit ? h.t : seg.t1, seg.own1);
    if (can_hit && seg.transparent && ta < tb) {
        const Hit ht = trace(tr.scratch->transparent_depth[l], seg.own0, ta, tb);
        if (ht.hit && miss && miss->t < ht.t)
            addMiss(); // the missed cone's content lies in front of the pane
        if (ht.hit && ray.transmit > 0.0f) {
            ++cnt.transparent_hits;
            const float ct = tr.cocOf(ht.t);
            const glm::vec4 m = s.cone && tr.lambda * std::fabs(ct) > 1.0f
                                    ? sampleCone(tr, tr.transparent_mips[l], cx + ct * wc.x,
                                                 cy + ct * wc.y, tr.lambda * std::fabs(ct))
                                    : lt.transparent_color.load(lt.index(l, ht.texel));
            glm::vec3 rgb(m);
            const size_t ti = lt.index(l, ht.texel);
            if (shade && lt.transparent_top_alpha[ti] > 0.0f) {
                // §5 for the plane: the composite is linear in its top pane's colour, which the
                // rasterizer shaded from the lens centre; swap in the top pane shaded from this
                // ray's origin (scaled by the cone's share of the texel's opacity).
                const raster::GSample& g = lt.transparent_gbuffer[ti];
                const glm::vec3 world = texelWorld(tr, ht.texel, ht.t);
                const glm::vec3 centre = tr.shader->shade(g, world, view.eye);
                const glm::vec3 from_ray = shadeSample(tr, g, world, shade_from);
                const float texel_a = lt.transparent_color.load(ti).a;
                const float share = texel_a > 0.0f ? std::min(m.a / texel_a, 1.0f) : 0.0f;
                rgb += share * lt.transparent_top_alpha[ti] * (from_ray - centre);
            }
            ray.color += ray.transmit * rgb;
            ray.transmit *= 1.0f - std::clamp(m.a, 0.0f, 1.0f);
            ray.t_end = ht.t;
            if (rec)
                rec->layer = int32_t(l);
        }
    }
    if (!h.hit) {
        if (miss)
            addMiss();
        return;
    }
    const float c_hit = tr.cocOf(h.t);
    glm::vec3 c1;
    float v1 = 1.0f;
    const bool cone_hit = s.cone && tr.lambda * std::fabs(c_hit) > 1.0f;
    if (cone_hit) {
        // §4.4: a cone of diameter lambda |C(d_i)| around the ray; the mipmapped alpha is its
        // coverage v1, the mipmapped RGB / v1 its mean colour c1.
        const glm::vec4 m = sampleCone(tr, tr.mips[l], cx + c_hit * wc.x, cy + c_hit * wc.y,
                                       tr.lambda * std::fabs(c_hit));
        v1 = std::clamp(m.a, 0.0f, 1.0f);
        c1 = v1 > 0.0f ? glm::vec3(m) / m.a : glm::vec3(0.0f);
    } else {
        c1 = glm::vec3(lt.color.load(lt.index(l, h.texel)));
    }
    if (shade)
        c1 = cone_hit ? shadeFootprint(tr, l, h.texel, h.t, cx + c_hit * wc.x, cy + c_hit * wc.y,
                                       0.5f * tr.lambda * std::fabs(c_hit), shade_from)
                      : shadeHit(tr, l, h.texel, h.t, shade_from);
    if (rec)
        rec->layer = int32_t(l);
    ray.t_end = h.t;
    if (blend(v1, c1))
        return; // the ray ends here (transmit 0)
    // Continue along the centre ray for c2.
    ++cnt.cone_partial;
    if (rec)
        ++rec->partial_hits;
    ray.t_resume = h.t_behind + 1e-6f + 1e-3f * (seg.t1 - seg.t0);
}

// The end of pixel (x, y)'s rays: the background behind them, the paths that left the image
// (Discard), and the weighted mean in sample order.
void endPixel(const Tracer& tr, uint32_t x, uint32_t y, const RayState* rays, float* out,
              TileCounters& cnt) {
    const MultiviewSettings& s = *tr.settings;
    const float cx = float(x) + 0.5f, cy = float(y) + 0.5f;
    const float t_last = tr.segs.back().t1;
    double sum_r = 0.0, sum_g = 0.0, sum_b = 0.0, sum_w = 0.0;
    MultiviewRayRecord* records = debugRecords(tr, x, y);
    for (uint32_t k = 0; k < tr.samples->size(); ++k) {
        const RayState& ray = rays[k];
        if (ray.discarded)
            continue;
        glm::vec3 color = ray.color;
        float t_end = ray.t_end;
        MultiviewRayRecord* rec = records ? records + k : nullptr;
        if (ray.transmit > 0.0f) {
            ++cnt.background;
            color += ray.transmit * tr.background;
            t_end = t_last;
            if (rec)
                rec->layer = -1;
        }
        if (rec) {
            rec->t_end = t_end;
            rec->end_px = glm::vec2(cx, cy) + tr.cocOf(t_end) * ray.w;
        }
        if (s.offscreen == OffscreenPolicy::Discard && !rayInside(tr, x, y, ray.w, t_end)) {
            ++cnt.discarded; // the path to the hit leaves the image
            if (rec)
                rec->discarded = true;
            continue;
        }
        const double wt = double(ray.lens.weight);
        sum_r += wt * double(color.r);
        sum_g += wt * double(color.g);
        sum_b += wt * double(color.b);
        sum_w += wt;
    }
    if (sum_w > 0.0) {
        out[0] = float(sum_r / sum_w);
        out[1] = float(sum_g / sum_w);
        out[2] = float(sum_b / sum_w);
    } else { // every ray left the image: the pinhole colour
        const size_t i = (size_t(y) * tr.width + x) * 4;
        out[0] = tr.pinhole->color[i];
        out[1] = tr.pinhole->color[i + 1];
        out[2] = tr.pinhole->color[i + 2];
    }
    out[3] = 1.0f;
}

// The rays of the pixels [x0, x1) x [y0, y1), layer by layer: every ray of the tile meets layer
// l before any meets layer l + 1, so one layer's texels, mipmaps and N-buffer around the tile
// stay in the cache while they are read (pixel by pixel, all layers of a tile do not fit in it).
// Each ray still visits its layers front to back with the same arithmetic, so the bytes are
// those of tracing each pixel's rays to their ends in turn. `rays` holds (x1-x0)(y1-y0)N states.
void traceTile(const Tracer& tr, uint32_t x0, uint32_t x1, uint32_t y0, uint32_t y1,
               const uint32_t* tile_layers, uint32_t tile_layer_count, RayState* rays,
               PixelLayers* pixel_layers, float* rgba, TileCounters& cnt) {
    const uint32_t n = tr.samples->size();
    const uint32_t tw = x1 - x0;
    std::array<LayerCulls, raster::kMaxLayers> culls;
    if (tr.settings->culling)
        for (uint32_t i = 0; i < tile_layer_count; ++i)
            culls[i] = layerCulls(tr, tile_layers[i]);
    for (uint32_t y = y0; y < y1; ++y)
        for (uint32_t x = x0; x < x1; ++x) {
            const size_t p = size_t(y - y0) * tw + (x - x0);
            PixelLayers& pl = pixel_layers[p];
            pl = pixelLayers(tr, x, y, tile_layers, tile_layer_count, culls.data(), cnt);
            if (tr.in_focus && !debugRecords(tr, x, y) &&
                inFocusPixel(tr, x, y, pl, rgba + (size_t(y) * tr.width + x) * 4, cnt)) {
                pl.active = 0;
                pl.resolved = true;
                continue;
            }
            beginRays(tr, x, y, rays + p * n, cnt);
        }
    for (uint32_t i = 0; i < tile_layer_count; ++i) {
        const uint32_t l = tile_layers[i];
        for (uint32_t y = y0; y < y1; ++y)
            for (uint32_t x = x0; x < x1; ++x) {
                const size_t p = size_t(y - y0) * tw + (x - x0);
                if (!((pixel_layers[p].active >> l) & 1))
                    continue;
                const bool hittable = (pixel_layers[p].hittable >> l) & 1;
                RayState* pr = rays + p * n;
                MultiviewRayRecord* recs = debugRecords(tr, x, y);
                uint32_t live = 0;
                for (uint32_t k = 0; k < n; ++k)
                    if (pr[k].transmit > 0.0f) {
                        traceLayer(tr, x, y, l, hittable, k, pr[k], recs ? recs + k : nullptr, cnt);
                        live += pr[k].transmit > 0.0f ? 1 : 0;
                    }
                if (live == 0)
                    pixel_layers[p].active = 0; // every ray has ended: no layer behind is met
            }
    }
    for (uint32_t y = y0; y < y1; ++y)
        for (uint32_t x = x0; x < x1; ++x) {
            const size_t p = size_t(y - y0) * tw + (x - x0);
            if (!pixel_layers[p].resolved)
                endPixel(tr, x, y, rays + p * n, rgba + (size_t(y) * tr.width + x) * 4, cnt);
        }
}

// traceTile compiled twice, for the baseline x86-64 and for AVX2 (the raster kernels' written-
// once, compiled-twice form, here by function attributes): `flatten` inlines everything it calls
// (the tracer's functions and the standard library's inline code) into each copy, so each is
// compiled whole for its target, and no code built for AVX2 is shared with the baseline copy.
// Without FMA the AVX2 copy computes the same IEEE operations in the same order (the build
// forbids contraction and reassociation), so the bytes are the same; what differs is the
// instructions chosen (a floor is one `vroundss` instead of a dozen SSE2 instructions, selects
// are blends). The baseline copy is the reference: ShadingInputs::simd = false (`--no-simd`).
#if defined(__x86_64__) && !defined(FOCAL_NO_SIMD)
#define FOCAL_MULTIVIEW_AVX2 1
#endif
using TraceTileFn = decltype(&traceTile);

__attribute__((flatten)) void
traceTileBaseline(const Tracer& tr, uint32_t x0, uint32_t x1, uint32_t y0, uint32_t y1,
                  const uint32_t* tile_layers, uint32_t tile_layer_count, RayState* rays,
                  PixelLayers* pixel_layers, float* rgba, TileCounters& cnt) {
    traceTile(tr, x0, x1, y0, y1, tile_layers, tile_layer_count, rays, pixel_layers, rgba, cnt);
}

#ifdef FOCAL_MULTIVIEW_AVX2
__attribute__((flatten, target("avx2,no-fma"))) void
traceTileAvx2(const Tracer& tr, uint32_t x0, uint32_t x1, uint32_t y0, uint32_t y1,
              const uint32_t* tile_layers, uint32_t tile_layer_count, RayState* rays,
              PixelLayers* pixel_layers, float* rgba, TileCounters& cnt) {
    traceTile(tr, x0, x1, y0, y1, tile_layers, tile_layer_count, rays, pixel_layers, rgba, cnt);
}
#endif

TraceTileFn traceTileFor(bool simd) {
#ifdef FOCAL_MULTIVIEW_AVX2
    if (raster::useAvx2(simd))
        return traceTileAvx2;
#endif
    (void)simd;
    return traceTileBaseline;
}

} // namespace

Status validate(const MultiviewSettings& s, uint32_t sample_count) {
    if (sample_count == 0)
        return Status::error("--samples must be at least 1");
    if (s.layers == 0 && (!std::isfinite(s.layer_spacing_px) || !(s.layer_spacing_px > 0.0f)))
        return Status::error("--layer-spacing must be a positive number of pixels");
    if (s.layers > raster::kMaxLayers)
        return Status::error("--layers must be at most " + std::to_string(raster::kMaxLayers));
    if (!std::isfinite(s.overlap) || s.overlap < 0.0f || s.overlap > 1.0f)
        return Status::error("--overlap must be in [0, 1]");
    if (std::isnan(s.thickness_px) || !(s.thickness_px > 0.0f))
        return Status::error("--thickness must be a positive number of pixels or inf");
    if (s.iterations > 64)
        return Status::error("--iterations must be at most 64");
    if (s.refine_steps > 32)
        return Status::error("--refine-steps must be at most 32");
    if (s.tile_size == 0 || s.tile_size > 1024)
        return Status::error("multiview: tile size must be in [1, 1024]");
    if (s.jitter == JitterMode::Halton) {
        if (!s.sequence_2n || s.sequence_2n->size() == 0)
            return Status::error("--jitter halton needs a 2N-sample sequence");
        if (s.sequence_2n->size() < sample_count)
            return Status::error("--jitter halton: the sequence must hold at least --samples");
    }
    if (s.env_map) {
        const EnvironmentMap& e = *s.env_map;
        if (e.width == 0 || e.height == 0 || e.rgb.size() != size_t(e.width) * e.height * 3)
            return Status::error("--env-map: the image is empty or its size does not match");
        if (!std::isfinite(e.intensity) || e.intensity < 0.0f)
            return Status::error("--env-intensity must be a non-negative number");
    }
    return {};
}

raster::Result<raster::LayeredTargetDesc> multiviewLayerDesc(const ThinLens& lens,
                                                             const DepthRange& range,
                                                             const MultiviewSettings& settings,
                                                             LayerSpacing* spacing_out) {
    raster::Result<LayerSpacing> sp =
        settings.layers > 0
            ? layerSpacingFromCount(lens, range, settings.layers)
            : layerSpacingFromDelta(lens, range, settings.layer_spacing_px, raster::kMaxLayers);
    if (!sp.ok())
        return sp.status();
    raster::LayeredTargetDesc desc;
    desc.bounds = sp->bounds;
    desc.overlap = settings.overlap;
    desc.routing = settings.routing;
    desc.color_format = settings.color_format;
    desc.depth_format = settings.depth_format;
    desc.gbuffer = settings.view_dependent || settings.env_map != nullptr;
    if (spacing_out)
        *spacing_out = std::move(*sp);
    return desc;
}

raster::Result<MultiviewStats>
synthesizeMultiview(const raster::View& view, const ThinLens& lens, const LensSampleSet& samples,
                    const raster::Frame& pinhole, const raster::LayeredTarget& layers,
                    const LayerSpacing& spacing, const MultiviewSettings& settings,
                    const ShadingInputs& shading, glm::vec3 background, raster::TaskPool& pool,
                    MultiviewScratch& scratch, std::vector<float>& rgba) {
    if (Status st = validate(settings, samples.size()); !st.ok())
        return st;
    if (Status st = validate(lens, view); !st.ok())
        return st;
    const uint32_t width = view.width, height = view.height;
    if (pinhole.width != width || pinhole.height != height || layers.width != width ||
        layers.height != height)
        return Status::error("multiview: the pinhole frame and layers must match the view size");
    if (layers.layer_count == 0 || layers.layer_count > raster::kMaxLayers)
        return Status::error("multiview: the layered target has no layers");
    const bool shade = settings.view_dependent || settings.env_map;
    const size_t layer_texels = layers.pixelCount() * layers.layer_count;
    if (shade &&
        (layers.gbuffer.size() != layer_texels || !shading.scene ||
         (layers.hasTransparency() && (layers.transparent_gbuffer.size() != layer_texels ||
                                       layers.transparent_top_alpha.size() != layer_texels))))
        return Status::error("--view-dependent needs layers rendered with a G-buffer");

    MultiviewStats stats;
    const uint32_t m = layers.layer_count;
    stats.layers = m;
    stats.delta_px = spacing.delta_px;
    stats.budget_limited = spacing.budget_limited;
    stats.layered_bytes = layers.bytes();

    Tracer tr;
    tr.view = &view;
    tr.lens = &lens;
    tr.samples = &samples;
    tr.layers = &layers;
    tr.settings = &settings;
    tr.shading = &shading;
    tr.scratch = &scratch;
    tr.pinhole = &pinhole;
    tr.width = width;
    tr.height = height;
    tr.background = background;
    std::optional<raster::SurfaceShader> shader;
    if (shade) {
        shader.emplace(*shading.scene, view, shading.simd);
        tr.shader = &*shader;
    }
    // C as an affine function of stored depth D: 1/d = 1/f - D (1/n - 1/f) (camera.h), so
    // C = E f_px (1/d_f - 1/f) + E f_px (1/n - 1/f) D (Eq. 3).
    {
        const double ef = double(lens.aperture_radius) * double(lens.focal_length_px);
        const double inv_n = 1.0 / double(view.znear);
        const double inv_f = view.zfar > 0.0f ? 1.0 / double(view.zfar) : 0.0;
        tr.coc_a = float(ef * (1.0 / double(lens.focus_distance) - inv_f));
        tr.coc_b = float(ef * (inv_n - inv_f));
    }
    if (std::isfinite(settings.thickness_px) && tr.coc_b != 0.0f)
        tr.thickness_d = settings.thickness_px / std::fabs(tr.coc_b);
    tr.lambda = meanNeighbourDistance(samples);
    stats.lambda = tr.lambda;
    float r_max = 0.0f;
    for (const LensSample& ls : samples.samples())
        r_max = std::max(r_max, glm::length(ls.position));
    if (settings.cone && settings.cone_centre == ConeCentre::Cell &&
        settings.jitter == JitterMode::None) {
        const std::vector<glm::vec2> cells = lensCellOffsets(samples);
        for (uint32_t k = 0; k < cells.size(); ++k) {
            tr.cone_offsets.push_back(lensRayImageOffset(1.0f, cells[k]));
            // The culling windows (and N-buffer levels) bound every cone centre as every ray.
            r_max = std::max(r_max, glm::length(samples.sample(k).position + cells[k]));
        }
    }
    stats.cones_on_cells = !tr.cone_offsets.empty();
    if (settings.jitter == JitterMode::Halton)
        for (const LensSample& ls : settings.sequence_2n->samples())
            r_max = std::max(r_max, glm::length(ls.position));
    if (settings.jitter == JitterMode::Rotate)
        r_max = std::max(r_max, std::sqrt(2.0f)); // any aperture lies in [-1,1]^2
    tr.r_max = std::max(r_max, 1e-6f);

    // Per-layer float depths (empty -> kEmptyDepth), content extents, N-buffers and coverage
    // mipmaps; one task per layer, each writing only its own slots.
    auto t0 = Clock::now();
    const size_t pixels = size_t(width) * height;
    const bool transparency = layers.hasTransparency();
    scratch.depth.resize(m);
    scratch.transparent_depth.resize(transparency ? m : 0);
    // Buffers kept from the caller's previous frame are resized in place, not reallocated: every
    // slot read below is rewritten, and a layer that builds nothing is cleared.
    scratch.nbuffers.resize(m);
    std::vector<float> content_min(m, INFINITY), content_max(m, -INFINITY);
    std::vector<uint8_t> transparent_content(m, 0);
    pool.parallelFor(m, [&](uint32_t l, uint32_t) {
        float lo = INFINITY, hi = -INFINITY;
        // Returns whether any texel is covered.
        auto copy = [&](const raster::ColorBuffer& color, const raster::DepthBuffer& depth,
                        std::vector<float>& d) {
            d.resize(pixels);
            bool any = false;
            for (size_t i = 0; i < pixels; ++i) {
                const size_t li = layers.index(l, i);
                const bool covered = color.load(li).a > 0.0f;
                const float v = covered ? depth.load(li) : kEmptyDepth;
                d[i] = v;
                if (covered) {
                    lo = std::min(lo, v);
                    hi = std::max(hi, v);
                    any = true;
                }
            }
            return any;
        };
        copy(layers.color, layers.depth, scratch.depth[l]);
        if (transparency)
            transparent_content[l] = copy(layers.transparent_color, layers.transparent_depth,
                                          scratch.transparent_depth[l]);
        content_min[l] = lo;
        content_max[l] = hi;
    });
    // Segments: the overlapped interval of each layer in D (§4.2); the first and last layers
    // also reach their content (depths outside the bounds are routed there).
    tr.segs.resize(m);
    float reach_max = 0.0f;
    for (uint32_t l = 0; l < m; ++l) {
        LayerSeg& seg = tr.segs[l];
        const raster::LayerInterval iv = raster::overlappedInterval(layers.desc, l);
        const float near_d = l == 0 ? layers.desc.bounds[0] : iv.near_d;
        const float far_d = l + 1 == m ? layers.desc.bounds[m] : iv.far_d;
        seg.t0 = raster::depthFromDistance(view, near_d);
        seg.t1 = raster::depthFromDistance(view, far_d);
        if (content_max[l] >= content_min[l]) {
            seg.empty = false;
            if (l == 0)
                seg.t0 = std::min(seg.t0, content_min[l]);
            if (l + 1 == m)
                seg.t1 = std::max(seg.t1, content_max[l]);
        }
        seg.t0 = std::clamp(seg.t0, raster::kNearDepth, raster::kFarDepth);
        seg.t1 = std::clamp(seg.t1, seg.t0, raster::kFarDepth);
        seg.own0 = l == 0 ? seg.t0 : raster::depthFromDistance(view, layers.desc.bounds[l]);
        seg.own1 = l + 1 == m ? seg.t1 : raster::depthFromDistance(view, layers.desc.bounds[l + 1]);
        seg.transparent = transparent_content[l] != 0;
        // Every ray of a pixel stays within r_max * max |C| of it over the segment (C is
        // monotonic in D, so the extreme is at an end).
        const float coc_max = std::max(std::fabs(tr.cocOf(seg.t0)), std::fabs(tr.cocOf(seg.t1)));
        seg.reach_px = tr.r_max * coc_max;
        if (!(seg.reach_px < kMaxReachPx && coc_max < kMaxReachPx))
            return Status::error("multiview: the lens blurs by more than 2^24 pixels over the "
                                 "visible depths (aperture radius " +
                                 std::to_string(lens.aperture_radius) + ")");
        const float widest = tr.lambda * coc_max;
        if (settings.cone && settings.cone_misses && widest > 1.0f) {
            // A missed cone is first looked up in the middle of the layer's own interval,
            // then somewhere in the segment (missCone). A trilinear lookup at diameter Dc reads
            // level floor(log2 Dc) + 1 at most (and none above the top), 1.5 of its texels
            // either side.
            seg.t_cone = 0.5f * (seg.own0 + seg.own1);
            const int top = int(kMaxMipLevels) - 1;
            seg.cone_px = 1.5f * std::ldexp(1.0f, std::min(std::ilogb(widest) + 1, top)) + 1.0f;
        }
        if (!seg.empty)
            reach_max = std::max(reach_max, seg.reach_px);
        else
            ++stats.layers_empty;
    }
    stats.ms_decomposition = msSince(t0); // the copy belongs to the decomposition's cost

    t0 = Clock::now();
    if (!settings.culling)
        scratch.nbuffers.assign(m, NBuffer{});
    if (settings.culling) {
        pool.parallelFor(m, [&](uint32_t l, uint32_t) {
            if (tr.segs[l].empty) {
                scratch.nbuffers[l] = NBuffer{};
                return;
            }
            // Window side 2 * reach + 2 texels for a pixel; the tile query uses more (it falls
            // back to a conservative tiling when the levels run out).
            const float side = 2.0f * (tr.segs[l].reach_px + tr.segs[l].cone_px) + 2.0f +
                               float(settings.tile_size);
            uint32_t level = 0;
            while (level < 16 && float(2u << level) <= side)
                ++level;
            if (!transparency) {
                buildNBuffer(scratch.depth[l].data(), width, height, level, scratch.nbuffers[l]);
                return;
            }
            // One N-buffer for both planes: the nearer of the two depths, so culling stays
            // lossless for each.
            std::vector<float> nearest(pixels);
            for (size_t i = 0; i < pixels; ++i)
                nearest[i] = std::min(scratch.depth[l][i], scratch.transparent_depth[l][i]);
            buildNBuffer(nearest.data(), width, height, level, scratch.nbuffers[l]);
        });
        for (uint32_t l = 0; l < m; ++l)
            stats.nbuffer_levels = std::max(stats.nbuffer_levels, scratch.nbuffers[l].levelCount());
    }
    stats.ms_nbuffer = msSince(t0);

    t0 = Clock::now();
    // Per layer, the levels built below (cleared for the layers that build none).
    auto keepLayers = [&](std::vector<std::vector<std::vector<float>>>& mips, bool used) {
        mips.resize(used ? m : 0);
        for (uint32_t l = 0; l < mips.size(); ++l)
            if (!settings.cone || tr.segs[l].empty)
                mips[l].clear();
    };
    keepLayers(scratch.mips, true);
    keepLayers(scratch.transparent_mips, transparency);
    keepLayers(scratch.owned_mips, settings.cone && settings.cone_misses);
    scratch.mip_width.clear();
    scratch.mip_height.clear();
    if (settings.cone) {
        // §4.4: mipmaps of the layer colour with coverage alpha (premultiplied: empty texels
        // are (0,0,0,0)), up to the level the widest cone needs.
        // reach_max = r_max * the largest |C| of any non-empty segment.
        const float widest = tr.lambda * reach_max / tr.r_max;
        uint32_t levels = 1;
        while (levels < kMaxMipLevels && float(1u << (levels - 1)) < widest)
            ++levels;
        scratch.mip_width.push_back(width);
        scratch.mip_height.push_back(height);
        for (uint32_t lv = 1; lv < levels; ++lv) {
            scratch.mip_width.push_back(std::max(1u, (scratch.mip_width.back() + 1) / 2));
            scratch.mip_height.push_back(std::max(1u, (scratch.mip_height.back() + 1) / 2));
        }
        stats.mip_levels = levels;
        // Level 0 from `level0` (C channels per texel), then 2x2 box reductions.
        auto build = [&]<uint32_t C>(std::vector<std::vector<float>>& mip, auto&& level0) {
            mip.resize(levels);
            mip[0].resize(pixels * C);
            for (size_t i = 0; i < pixels; ++i) {
                const auto c = level0(i);
                for (uint32_t k = 0; k < C; ++k)
                    mip[0][i * C + k] = c[k];
            }
            for (uint32_t lv = 1; lv < levels; ++lv) {
                const uint32_t pw = scratch.mip_width[lv - 1], ph = scratch.mip_height[lv - 1];
                const uint32_t cw = scratch.mip_width[lv], ch = scratch.mip_height[lv];
                const std::vector<float>& src = mip[lv - 1];
                std::vector<float>& dst = mip[lv];
                dst.resize(size_t(cw) * ch * C);
                for (uint32_t y = 0; y < ch; ++y) {
                    const float* r0 = src.data() + size_t(std::min(2 * y, ph - 1)) * pw * C;
                    const float* r1 = src.data() + size_t(std::min(2 * y + 1, ph - 1)) * pw * C;
                    float* o = dst.data() + size_t(y) * cw * C;
                    auto texel = [&](uint32_t x, uint32_t x0, uint32_t x1) {
                        for (uint32_t c = 0; c < C; ++c)
                            o[x * C + c] = 0.25f * (r0[x0 * C + c] + r0[x1 * C + c] +
                                                    r1[x0 * C + c] + r1[x1 * C + c]);
                    };
                    // Only an odd level's last column clamps its right neighbour.
                    for (uint32_t x = 0; x < pw / 2; ++x)
                        texel(x, 2 * x, 2 * x + 1);
                    for (uint32_t x = pw / 2; x < cw; ++x)
                        texel(x, std::min(2 * x, pw - 1), std::min(2 * x + 1, pw - 1));
                }
            }
        };
        pool.parallelFor(m, [&](uint32_t l, uint32_t) {
            if (tr.segs[l].empty)
                return;
            build.template operator()<4>(scratch.mips[l], [&](size_t i) {
                // coverage alpha: 1 where covered
                const glm::vec4 c = layers.color.load(layers.index(l, i));
                const float a = c.a > 0.0f ? 1.0f : 0.0f;
                return glm::vec4(glm::vec3(c) * a, a);
            });
            if (settings.cone_misses) { // the texels the layer owns (missCone)
                const float lo = tr.segs[l].own0, hi = tr.segs[l].own1;
                const bool last = l + 1 == m;
                build.template operator()<kOwnedChannels>(scratch.owned_mips[l], [&](size_t i) {
                    const float d = scratch.depth[l][i];
                    const bool owned = d >= lo && (d < hi || (last && d <= hi));
                    const glm::vec4 c = layers.color.load(layers.index(l, i));
                    return owned ? std::array<float, kOwnedChannels>{d, 1.0f, c.r, c.g, c.b}
                                 : std::array<float, kOwnedChannels>{};
                });
            }
            if (transparency) // already premultiplied, alpha = opacity
                build.template operator()<4>(scratch.transparent_mips[l], [&](size_t i) {
                    return layers.transparent_color.load(layers.index(l, i));
                });
        });
    }
    auto views = [&](const std::vector<std::vector<std::vector<float>>>& layer_mips) {
        std::vector<MipChain> chains(layer_mips.size());
        for (size_t l = 0; l < layer_mips.size(); ++l)
            for (size_t lv = 0; lv < layer_mips[l].size(); ++lv) {
                const int64_t w = scratch.mip_width[lv], h = scratch.mip_height[lv];
                chains[l][lv] = {layer_mips[l][lv].data(), w, h, float(w - 1), float(h - 1)};
            }
        return chains;
    };
    tr.mips = views(scratch.mips);
    tr.owned_mips = views(scratch.owned_mips);
    tr.transparent_mips = views(scratch.transparent_mips);
    for (LayerSeg& seg : tr.segs)
        if (seg.cone_px > 0.0f) {
            seg.cone_level = mipLevelFor(tr, tr.lambda * std::fabs(tr.cocOf(seg.t_cone)));
            seg.first_cone_px = tr.r_max * std::fabs(tr.cocOf(seg.t_cone)) +
                                1.5f * std::ldexp(1.0f, int(seg.cone_level.l1)) + 1.0f;
        }
    stats.ms_mipmaps = msSince(t0);
    for (uint32_t l = 0; l < m; ++l) {
        for (const std::vector<float>& lv : scratch.nbuffers[l].levels)
            stats.scratch_bytes += lv.size() * sizeof(float);
        for (const std::vector<float>& lv : scratch.mips[l])
            stats.scratch_bytes += lv.size() * sizeof(float);
        if (!scratch.owned_mips.empty())
            for (const std::vector<float>& lv : scratch.owned_mips[l])
                stats.scratch_bytes += lv.size() * sizeof(float);
        stats.scratch_bytes += scratch.depth[l].size() * sizeof(float);
        if (transparency) {
            for (const std::vector<float>& lv : scratch.transparent_mips[l])
                stats.scratch_bytes += lv.size() * sizeof(float);
            stats.scratch_bytes += scratch.transparent_depth[l].size() * sizeof(float);
        }
    }

    // §4.3: trace every pixel's lens rays, one task per output tile.
    t0 = Clock::now();
    if (settings.precompute_paths && settings.jitter == JitterMode::None &&
        settings.traversal == Traversal::Scan) {
        // A path crosses about |dx| + |dy| + 1 cells (estimated as 2 per pixel of offset, plus
        // 2); walk them in advance unless the lens makes that very many (the per-pixel walk is
        // then the cheaper one).
        double cells_bound = 0.0;
        for (const LayerSeg& seg : tr.segs)
            cells_bound += 2.0 * double(tr.r_max) *
                               std::fabs(double(tr.cocOf(seg.t1)) - double(tr.cocOf(seg.t0))) +
                           2.0;
        if (cells_bound * samples.size() <= double(kMaxPathCells)) {
            tr.paths.reserve(size_t(samples.size()) * m);
            for (uint32_t k = 0; k < samples.size(); ++k) {
                const glm::vec2 p = samples.sample(k).position;
                for (uint32_t l = 0; l < m; ++l)
                    tr.paths.push_back(tr.segs[l].empty // never traced
                                           ? RayPath{}
                                           : walkPath(tr, glm::vec2(-p.x, p.y), tr.segs[l].t0,
                                                      tr.segs[l].t1, tr.cells));
            }
            stats.path_cells = tr.cells.size();
            for (uint32_t l = 0; l < m; ++l) {
                LayerSeg& seg = tr.segs[l];
                if (seg.empty)
                    continue;
                seg.focus_t1 = seg.t1;
                for (uint32_t k = 0; k < samples.size(); ++k) {
                    const RayPath& path = tr.paths[size_t(k) * m + l];
                    const PathCell* cells = tr.cells.data() + path.first;
                    uint32_t i = 0;
                    while (i < path.count && (cells[i].dx != 0 || cells[i].dy != 0)) {
                        auto& box = seg.focus_box;
                        const bool first = box.x0 > box.x1;
                        box.x0 = first ? cells[i].dx : std::min(box.x0, cells[i].dx);
                        box.x1 = first ? cells[i].dx : std::max(box.x1, cells[i].dx);
                        box.y0 = first ? cells[i].dy : std::min(box.y0, cells[i].dy);
                        box.y1 = first ? cells[i].dy : std::max(box.y1, cells[i].dy);
                        ++i;
                    }
                    if (i == path.count) { // this ray never crosses its own texel here
                        seg.focus_t0 = 1.0f, seg.focus_t1 = -1.0f;
                        break;
                    }
                    seg.focus_t0 = k == 0 ? cells[i].t_in : std::max(seg.focus_t0, cells[i].t_in);
                    seg.focus_t1 = std::min(seg.focus_t1, cells[i].t_out);
                }
            }
            // inFocusPixel repeats what traceLayer and endPixel do for a ray that hits its own
            // texel: lens-centre shading and no ray dropped at the image border.
            tr.in_focus = !shade && settings.offscreen == OffscreenPolicy::Clamp;
        }
    }
    rgba.assign(pixels * 4, 0.0f);
    const uint32_t ts = settings.tile_size;
    const uint32_t tiles_x = (width + ts - 1) / ts, tiles_y = (height + ts - 1) / ts;
    std::vector<TileCounters> counters(size_t(tiles_x) * tiles_y);
    // Per worker: the states of one tile's rays and pixels.
    std::vector<RayState> ray_states(size_t(pool.workerCount()) * ts * ts * samples.size());
    std::vector<PixelLayers> pixel_layers(size_t(pool.workerCount()) * ts * ts);
    const TraceTileFn trace_tile = traceTileFor(shading.simd);
    pool.parallelFor(tiles_x * tiles_y, [&](uint32_t tile, uint32_t worker) {
        // Counted on the stack, stored once: neighbouring tiles' counters share cache lines,
        // and the two workers usually trace neighbouring tiles.
        TileCounters cnt;
        const uint32_t x0 = (tile % tiles_x) * ts, y0 = (tile / tiles_x) * ts;
        const uint32_t x1 = std::min(x0 + ts, width), y1 = std::min(y0 + ts, height);
        // Skip empty layers, and layers with nothing in reach of the whole tile (one query).
        std::array<uint32_t, raster::kMaxLayers> tile_layers{};
        uint32_t count = 0;
        for (uint32_t l = 0; l < m; ++l) {
            if (tr.segs[l].empty)
                continue;
            if (settings.culling && culled(tr, l, x0, x1 - 1, y0, y1 - 1, tr.segs[l].cone_px)) {
                ++cnt.culled_tile;
                continue;
            }
            tile_layers[count++] = l;
        }
        trace_tile(tr, x0, x1, y0, y1, tile_layers.data(), count,
                   ray_states.data() + size_t(worker) * ts * ts * samples.size(),
                   pixel_layers.data() + size_t(worker) * ts * ts, rgba.data(), cnt);
        counters[tile] = cnt;
    });
    for (const TileCounters& c : counters) {
        stats.rays += c.rays;
        stats.rays_discarded += c.discarded;
        stats.rays_background += c.background;
        stats.layer_tests += c.layer_tests;
        stats.layer_culled_pixel += c.culled_pixel;
        stats.layer_culled_tile += c.culled_tile;
        stats.layer_culled_ray += c.culled_ray;
        stats.cone_partial += c.cone_partial;
        stats.cone_missed += c.cone_missed;
        stats.texel_fetches += c.fetches;
        stats.layer_steps += c.layer_steps;
        stats.transparent_hits += c.transparent_hits;
        stats.pixels_in_focus += c.pixels_in_focus;
    }
    stats.ms_tracing = msSince(t0);
    return stats;
}

raster::Result<MultiviewStats>
renderMultiview(const raster::View& view, const ThinLens& lens, const LensSampleSet& samples,
                const MultiviewSettings& settings, const ShadingInputs& shading,
                glm::vec3 background, const PinholeFn& render_pinhole,
                const LayersFn& render_layers, raster::TaskPool& pool, std::vector<float>& rgba,
                raster::Frame* pinhole_out, raster::LayeredTarget* layers_out,
                MultiviewScratch* scratch_io) {
    if (Status st = validate(settings, samples.size()); !st.ok())
        return st;
    if (Status st = validate(lens, view); !st.ok())
        return st;
    raster::Frame local_pinhole;
    raster::Frame& pinhole = pinhole_out ? *pinhole_out : local_pinhole;
    // §4.1: the pinhole through the lens centre gives the visible depth range.
    auto t0 = Clock::now();
    if (Status st = render_pinhole(view, pinhole); !st.ok())
        return st;
    const double ms_pinhole = msSince(t0);
    const DepthRange range = visibleDepthRange(pinhole, view);
    // Nothing to blur: the pinhole render is the result (the same rule as accum's, so both
    // methods return the pinhole image for the same lenses). Rays offset by less than half a
    // pixel would read every pixel's own texel anyway.
    std::string skip_reason;
    if (!range.covered) {
        skip_reason = "nothing visible: the image is the background";
    } else if (settings.skip_unblurred && !settings.env_map) {
        const CocRange coc = visibleCocRange(lens, pinhole, view);
        if (lens.aperture_radius == 0.0f) {
            skip_reason = "aperture radius is 0 (pinhole)";
        } else if (coc.max_abs_px < 0.5f) {
            char buf[96];
            std::snprintf(buf, sizeof buf, "every visible depth has |C(d)| < 0.5 px (max %.3f px)",
                          double(coc.max_abs_px));
            skip_reason = buf;
        }
    }
    if (!skip_reason.empty()) {
        rgba = pinhole.color;
        if (layers_out)
            *layers_out = raster::LayeredTarget{}; // no decomposition was made
        MultiviewStats stats;
        stats.skipped = true;
        stats.skip_reason = std::move(skip_reason);
        stats.ms_pinhole = ms_pinhole;
        if (range.covered)
            stats.d_near = range.near_d, stats.d_far = range.far_d;
        return stats;
    }
    LayerSpacing spacing;
    raster::Result<raster::LayeredTargetDesc> desc =
        multiviewLayerDesc(lens, range, settings, &spacing);
    if (!desc.ok())
        return desc.status();
    raster::LayeredTarget local_layers;
    raster::LayeredTarget& layers = layers_out ? *layers_out : local_layers;
    t0 = Clock::now();
    if (Status st = render_layers(view, *desc, layers); !st.ok())
        return st;
    const double ms_layers = msSince(t0);
    MultiviewScratch local_scratch;
    MultiviewScratch& scratch = scratch_io ? *scratch_io : local_scratch;
    raster::Result<MultiviewStats> r =
        synthesizeMultiview(view, lens, samples, pinhole, layers, spacing, settings, shading,
                            background, pool, scratch, rgba);
    if (!r.ok())
        return r;
    r->ms_pinhole = ms_pinhole;
    r->ms_decomposition += ms_layers;
    r->d_near = range.near_d;
    r->d_far = range.far_d;
    return r;
}

uint64_t multiviewMinimumBytes(const MultiviewSettings& settings, uint32_t width, uint32_t height,
                               uint32_t sample_count, uint32_t workers) {
    using raster::addBytes, raster::mulBytes;
    const uint64_t pixels = uint64_t{width} * height;
    const uint32_t layers = std::max(settings.layers, 1u);
    raster::LayeredTargetDesc desc;
    desc.color_format = settings.color_format;
    desc.depth_format = settings.depth_format;
    desc.gbuffer = settings.view_dependent || settings.env_map != nullptr;
    uint64_t bytes = raster::frameBytes(width, height, raster::DepthFormat::Float32, false);
    bytes = addBytes(bytes, mulBytes(pixels, 4 * sizeof(float))); // rgba
    bytes = addBytes(bytes, raster::layeredTargetBytes(width, height, layers, desc, false));
    bytes = addBytes(bytes, mulBytes(mulBytes(pixels, layers), sizeof(float))); // scratch.depth
    const uint64_t tile_texels = uint64_t{settings.tile_size} * settings.tile_size;
    const uint64_t per_texel =
        addBytes(mulBytes(sample_count, sizeof(RayState)), sizeof(PixelLayers));
    return addBytes(bytes, mulBytes(mulBytes(workers, tile_texels), per_texel));
}

} // namespace dof
