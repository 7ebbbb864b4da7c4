#include "out_of_memory.h"

#include <dof/gather.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <functional>
#include <new>
#include <string>

#if defined(__SSE2__) && !defined(FOCAL_NO_SIMD)
#include <emmintrin.h>
#endif

namespace dof {

using raster::Result;
using raster::Status;

namespace {

constexpr uint32_t kBlock = 8; // rows (vertical pass) / columns (horizontal) per reach block

double msSince(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

void runTasks(raster::TaskPool* pool, uint32_t count, raster::TaskFn fn) {
    if (pool)
        pool->parallelFor(count, fn);
    else
        for (uint32_t i = 0; i < count; ++i)
            fn(i, 0);
}

// Reach of a pass: the filter reads offsets |k| <= ceil(R) - 1 (a sample at |k| >= R has
// O(r_p) = 0 because r_p <= R, §4.2).
uint32_t fullReach(const GatherSettings& s) {
    return uint32_t(std::ceil(s.max_radius_px)) - 1u;
}

// The loop bound a set of samples whose largest radius is `max_r` needs: O(r_p) > 0 only for
// |k| < r_p, i.e. |k| <= ceil(r_p) - 1. Radii <= 1 reach no neighbour at all.
uint32_t reachOf(float max_r) {
    return max_r > 1.0f ? uint32_t(std::ceil(max_r)) - 1u : 0u;
}

// What the coc stage found in one tile; combined in tile order.
using TileCoc = GatherScratch::TileCoc;

struct Plan {
    uint32_t width = 0, height = 0, tile = 0, tiles_x = 0, tiles_y = 0;
    uint32_t reach = 0;      // ceil(R) - 1
    uint32_t row_blocks = 0; // ceil(H / 8)
    uint32_t col_blocks = 0; // ceil(W / 8)

    // Pixel rectangle [x0, x1) x [y0, y1) of a work tile.
    struct Bounds {
        uint32_t x0, y0, x1, y1;
    };
    Bounds bounds(uint32_t t) const {
        const uint32_t x0 = (t % tiles_x) * tile, y0 = (t / tiles_x) * tile;
        return {x0, y0, std::min(width, x0 + tile), std::min(height, y0 + tile)};
    }
};

// A worker's scratch for one pass: RGBA and weight accumulators for a tile-long line, and the
// padded line the horizontal pass reads (r, I, behind, RGBA).
struct LineScratch {
    float* acc;    // 4 per pixel
    float* wsum;   // total weight
    float* nsum;   // weight of samples in front
    float* leak_c; // leakage control of the centre
    float* pad;    // padded line
};
LineScratch lineScratch(float* base, uint32_t tile) {
    float* acc = base;
    float* wsum = acc + 4 * tile;
    float* nsum = wsum + tile;
    float* leak_c = nsum + tile;
    return {acc, wsum, nsum, leak_c, leak_c + tile};
}

Status checkImage(const GatherImage& image) {
    if (image.width == 0 || image.height == 0)
        return Status::error("gather: the image is empty (" + std::to_string(image.width) + "x" +
                             std::to_string(image.height) + ")");
    if (!image.rgba)
        return Status::error("gather: no colour image");
    const bool unorm = image.depth.format == raster::DepthFormat::Unorm16;
    if ((unorm && !image.depth.unorm16) || (!unorm && !image.depth.float32))
        return Status::error("gather: no depth buffer in the stated format");
    if (uint64_t(image.width) * image.height > (uint64_t(1) << 31))
        return Status::error("gather: the image is too large (more than 2^31 pixels)");
    return {};
}

float loadDepth(const StoredDepthRef& d, size_t i) {
    return d.format == raster::DepthFormat::Float32 ? d.float32[i]
                                                    : raster::decodeUnorm16(d.unorm16[i]);
}

// The coc stage for one pixel (§4.1 then the per-pixel factors of §4.2). Returns false on bad
// input. Shared by gather() and gatherReference() so both see the same bits.
struct PixelTerms {
    float coc, radius, intensity, behind, leak;
};

bool pixelTerms(const GatherImage& image, const CocAffine& ca, const GatherSettings& s, size_t i,
                PixelTerms& t, bool& bad_depth) {
    const float stored = loadDepth(image.depth, i);
    if (!(stored >= raster::kNearDepth && stored <= raster::kFarDepth)) { // also rejects NaN
        bad_depth = true;
        return false;
    }
    const float* c = image.rgba + 4 * i;
    if (!std::isfinite(c[0]) || !std::isfinite(c[1]) || !std::isfinite(c[2]) ||
        !std::isfinite(c[3])) {
        bad_depth = false;
        return false;
    }
    // C = a D + b (docs/dof/gather.md, "Depth from the depth buffer").
    t.coc = float(ca.a * double(stored) + ca.b);
    t.radius = std::min(std::fabs(t.coc), s.max_radius_px);
    // I(r) ∝ 1/r² (§4.2), with the pole at r = 0 removed: a point covers at least its pixel.
    const float r_i = std::max(t.radius, s.min_radius_px);
    t.intensity = 1.0f / (r_i * r_i);
    // z_p > z_f <=> C > 0 (C grows with d).
    t.behind = t.coc > 0.0f ? 1.0f : 0.0f;
    // L(z_p) ∝ r_c, up to 1 (§4.2); stored per centre pixel.
    t.leak = std::min(1.0f, s.leak_scale * t.radius);
    return true;
}

// The factors of one sample's weight W(P) = O(r_p) I(r_p) L(z_p) (§4.2), evaluated as (O I) L.
struct SampleFactors {
    float overlap, intensity, leakage;
    float weight() const { return (overlap * intensity) * leakage; }
};

// The factors of one sample at offset k (|k| = dist >= 1) for a centre whose leak factor is
// leak_c, with O(r_p) = clamp(r_p - d_p, 0, 1): 0 when r_p <= d_p, the fractional ramp r_p - d_p
// up to d_{p+1} = d_p + 1, then 1. The clamps are written as SSE's MAXPS/MINPS define them
// ((a > b) ? a : b, (a < b) ? a : b), so the SSE2 path below produces the same bits, signed zeros
// included.
inline SampleFactors sampleFactors(float r_p, float i_p, float behind_p, float leak_c, float dist) {
    const float t = r_p - dist;
    const float t0 = t > 0.0f ? t : 0.0f;
    const float o = t0 < 1.0f ? t0 : 1.0f;
    // L(z_p): leak_c behind the focal plane (behind_p = 1), else 1. Exact for behind_p in {0, 1}
    // (no rounding: 1*x + 0 and 0*x + 1), and branch-free.
    const float l = behind_p * leak_c + (1.0f - behind_p);
    return {o, i_p, l};
}

// One iteration of the §5 inner loop for one centre: adds the sample's weight to the sums and its
// weighted colour c_p to acc, then hands the factors, the weight and c_p to `tap` (the probe's
// recorder; a no-op for the render, which compiles away).
template <class TapFn>
inline void addSample(float r_p, float i_p, float behind_p, float leak_c, float dist,
                      const float* c_p, float& wsum, float& nsum, float* acc, TapFn&& tap) {
    const SampleFactors f = sampleFactors(r_p, i_p, behind_p, leak_c, dist);
    const float w = f.weight();
    wsum += w;
    nsum += w;
    for (uint32_t c = 0; c < 4; ++c)
        acc[c] += w * c_p[c];
    tap(f, w, c_p);
}

// The render's recorder: records nothing.
struct NoTaps {
    void operator()(const SampleFactors&, float, const float*) const {}
};

// Adds the samples at one offset k (|k| = dist) to a row of n centres: the inner loop of the §5
// pseudo-code, run for n centres at once. Per centre the terms are added in the same order, with
// the same operations, as gatherReference adds them: the SSE2 lanes are the scalar loop's
// iterations (no FMA: the build uses -ffp-contract=off, and no intrinsic here fuses). Without
// `simd` every centre takes the scalar loop.
void addSamples(const float* r_s, const float* i_s, const float* b_s, const float* c_s,
                const float* leak_c, float dist, uint32_t n, float* wsum, float* nsum, float* acc,
                bool simd) {
    uint32_t x = 0;
#if defined(__SSE2__) && !defined(FOCAL_NO_SIMD)
    const uint32_t lanes = simd ? n : 0; // centres the SSE2 loop may take
    const __m128 vdist = _mm_set1_ps(dist), zero = _mm_setzero_ps(), one = _mm_set1_ps(1.0f);
    for (; x + 4 <= lanes; x += 4) {
        const __m128 t = _mm_sub_ps(_mm_loadu_ps(r_s + x), vdist);
        const __m128 o = _mm_min_ps(_mm_max_ps(t, zero), one);
        const __m128 b = _mm_loadu_ps(b_s + x);
        const __m128 l = _mm_add_ps(_mm_mul_ps(b, _mm_loadu_ps(leak_c + x)), _mm_sub_ps(one, b));
        const __m128 w = _mm_mul_ps(_mm_mul_ps(o, _mm_loadu_ps(i_s + x)), l);
        _mm_storeu_ps(wsum + x, _mm_add_ps(_mm_loadu_ps(wsum + x), w));
        _mm_storeu_ps(nsum + x, _mm_add_ps(_mm_loadu_ps(nsum + x), w));
        const __m128 w0 = _mm_shuffle_ps(w, w, _MM_SHUFFLE(0, 0, 0, 0));
        const __m128 w1 = _mm_shuffle_ps(w, w, _MM_SHUFFLE(1, 1, 1, 1));
        const __m128 w2 = _mm_shuffle_ps(w, w, _MM_SHUFFLE(2, 2, 2, 2));
        const __m128 w3 = _mm_shuffle_ps(w, w, _MM_SHUFFLE(3, 3, 3, 3));
        float* a = acc + 4 * x;
        const float* c = c_s + 4 * x;
        _mm_storeu_ps(a, _mm_add_ps(_mm_loadu_ps(a), _mm_mul_ps(w0, _mm_loadu_ps(c))));
        _mm_storeu_ps(a + 4, _mm_add_ps(_mm_loadu_ps(a + 4), _mm_mul_ps(w1, _mm_loadu_ps(c + 4))));
        _mm_storeu_ps(a + 8, _mm_add_ps(_mm_loadu_ps(a + 8), _mm_mul_ps(w2, _mm_loadu_ps(c + 8))));
        _mm_storeu_ps(a + 12,
                      _mm_add_ps(_mm_loadu_ps(a + 12), _mm_mul_ps(w3, _mm_loadu_ps(c + 12))));
    }
#else
    (void)simd;
#endif
    for (; x < n; ++x)
        addSample(r_s[x], i_s[x], b_s[x], leak_c[x], dist, c_s + 4 * x, wsum[x], nsum[x],
                  acc + 4 * x, NoTaps{});
}

// Renormalisation (§4.2 "renormalizes the result"): when no neighbour contributed the centre is
// returned as it was (not c*I/I, which may differ in the last bit), so copying a tile the lens
// cannot change gives the same bits as filtering it. "+ 0.0f" turns -0 into +0, so the number
// of exactly-zero terms added (which differs between the bounded and the full loop) cannot show.
inline void resolvePixel(const float* acc, float wsum, float nsum, const float* centre,
                         float* out) {
    if (nsum > 0.0f) {
        for (int c = 0; c < 4; ++c)
            out[c] = acc[c] / wsum + 0.0f;
    } else {
        for (int c = 0; c < 4; ++c)
            out[c] = centre[c];
    }
}

// The per-pixel terms of the coc stage, one array each (GatherScratch's, or the reference's).
struct TermArrays {
    const float* radius;
    const float* intensity;
    const float* behind;
    const float* leak;
};

// One output pixel (x, y) of one 1-D pass, the §5 pseudo-code: the centre's term W(C) = I(r_c),
// then the samples at k = -k_max..k_max (k != 0) of `src` (w x h RGBA) down the column
// (`vertical`) or along the row, clamped to the edge with the distance kept |k|; renormalised
// into `out` (4 floats). The same sums, in the same order, as addSamples for a row of centres.
// `rec.tap(x, y, k, factors, weight, rgba)` sees every term (the centre with factors {1, I, 1}).
template <class Recorder>
void filterPixel(const TermArrays& t, const float* src, uint32_t w, uint32_t h, bool vertical,
                 uint32_t x, uint32_t y, uint32_t k_max, float* out, Recorder& rec) {
    const size_t ci = size_t(y) * w + x;
    const float* centre = src + ci * 4;
    const float ic = t.intensity[ci];
    float acc[4];
    for (int c = 0; c < 4; ++c)
        acc[c] = ic * centre[c];
    float wsum = ic, nsum = 0.0f;
    rec.tap(x, y, 0, SampleFactors{1.0f, ic, 1.0f}, ic, centre);
    for (int k = -int(k_max); k <= int(k_max); ++k) {
        if (k == 0)
            continue;
        const uint32_t sx = vertical ? x : uint32_t(std::clamp(int(x) + k, 0, int(w) - 1));
        const uint32_t sy = vertical ? uint32_t(std::clamp(int(y) + k, 0, int(h) - 1)) : y;
        const size_t si = size_t(sy) * w + sx;
        addSample(t.radius[si], t.intensity[si], t.behind[si], t.leak[ci], float(std::abs(k)),
                  src + si * 4, wsum, nsum, acc,
                  [&](const SampleFactors& f, float wt, const float* c) {
                      rec.tap(sx, sy, k, f, wt, c);
                  });
    }
    resolvePixel(acc, wsum, nsum, centre, out);
}

// The reference's recorder: records nothing.
struct NoRecorder {
    void tap(uint32_t, uint32_t, int, const SampleFactors&, float, const float*) const {}
};

Plan makePlan(const GatherImage& image, const GatherSettings& settings) {
    Plan p;
    p.width = image.width;
    p.height = image.height;
    p.tile = settings.tile_size;
    p.tiles_x = (p.width + p.tile - 1) / p.tile;
    p.tiles_y = (p.height + p.tile - 1) / p.tile;
    p.reach = fullReach(settings);
    p.row_blocks = (p.height + kBlock - 1) / kBlock;
    p.col_blocks = (p.width + kBlock - 1) / kBlock;
    return p;
}

// The loop bound K of a pass for the centres [first, last] along it (`extent` pixels long):
// with skip_tiles the reach of the largest radius within the full reach of them, read from the
// pass's reach blocks (`blocks`: one per 8 pixels along the pass); else the full reach.
uint32_t passReach(const Plan& p, const GatherSettings& s, const float* blocks, uint32_t first,
                   uint32_t last, uint32_t extent) {
    if (!s.skip_tiles)
        return p.reach;
    const uint32_t lo = first >= p.reach ? (first - p.reach) / kBlock : 0;
    const uint32_t hi = std::min(extent - 1, last + p.reach) / kBlock;
    float max_r = 0.0f;
    for (uint32_t b = lo; b <= hi; ++b)
        max_r = std::max(max_r, blocks[b]);
    return std::min(p.reach, reachOf(max_r));
}

// The vertical pass's bound for the rows [yb, yb + 8) of tile column `tile_col`.
uint32_t verticalReach(const Plan& p, const GatherSettings& s, const float* vblock,
                       uint32_t tile_col, uint32_t yb) {
    return passReach(p, s, vblock + size_t(tile_col) * p.row_blocks, yb, yb + kBlock - 1, p.height);
}

// The horizontal pass's bound for the pixels [x0, x1) of row y.
uint32_t horizontalReach(const Plan& p, const GatherSettings& s, const float* hblock, uint32_t y,
                         uint32_t x0, uint32_t x1) {
    return passReach(p, s, hblock + size_t(y) * p.col_blocks, x0, x1 - 1, p.width);
}

} // namespace

StoredDepthRef depthRefOf(const raster::DepthBuffer& depth) {
    StoredDepthRef r;
    r.format = depth.format;
    r.unorm16 = depth.unorm16.empty() ? nullptr : depth.unorm16.data();
    r.float32 = depth.float32.empty() ? nullptr : depth.float32.data();
    return r;
}

GatherImage gatherImageOf(const raster::Frame& frame) {
    GatherImage in;
    in.rgba = frame.color.data();
    in.depth = depthRefOf(frame.depth);
    in.width = frame.width;
    in.height = frame.height;
    return in;
}

CocAffine cocAffine(const ThinLens& lens, const raster::View& view) {
    // Eq. 7 gives z from z'/w'; here D = -(1/d - 1/f) / (1/n - 1/f) (camera.h), i.e. 1/d = 1/f -
    // D (1/n - 1/f). Substituted into C(d) = E f_px (1/d_f - 1/d) (Eq. 2 in pixels, lens.h) this
    // is affine in D: no division per pixel (§5: "the circle of confusion and depth value
    // computations were combined and scaled to pixels").
    const double k = double(lens.aperture_radius) * double(lens.focal_length_px);
    const double inv_n = 1.0 / double(view.znear);
    const double inv_f = view.zfar > 0.0f ? 1.0 / double(view.zfar) : 0.0;
    CocAffine ca;
    ca.a = k * (inv_n - inv_f);
    ca.b = k * (1.0 / double(lens.focus_distance) - inv_f);
    return ca;
}

namespace {

Status checkAll(const GatherImage& image, const ThinLens& lens, const raster::View& view,
                const GatherSettings& settings) {
    if (Status st = validate(settings); !st.ok())
        return st;
    if (Status st = validate(lens, view); !st.ok())
        return st;
    if (!(view.znear > 0.0f) || !std::isfinite(view.znear))
        return Status::error("gather: the view's near plane must be > 0");
    return checkImage(image);
}

Status badInput(const GatherImage& image, size_t index, bool bad_depth) {
    const std::string where = " at pixel (" + std::to_string(index % image.width) + ", " +
                              std::to_string(index / image.width) + ")";
    if (bad_depth)
        return Status::error("gather: stored depth " +
                             std::to_string(loadDepth(image.depth, index)) + where +
                             " is not in [-1, 0]");
    return Status::error("gather: colour" + where + " is not finite");
}

} // namespace

Result<GatherStats> gather(const GatherImage& image, const ThinLens& lens, const raster::View& view,
                           const GatherSettings& settings, std::vector<float>& out_rgba,
                           std::vector<float>* out_coc, raster::TaskPool* pool,
                           GatherScratch* scratch) try {
    if (Status st = checkAll(image, lens, view, settings); !st.ok())
        return st;
    GatherScratch local;
    GatherScratch& ws = scratch ? *scratch : local;

    const Plan p = makePlan(image, settings);
    const size_t pixels = size_t(p.width) * p.height;
    const uint32_t tiles = p.tiles_x * p.tiles_y;
    const uint32_t workers = pool ? pool->workerCount() : 1u;

    GatherStats stats;
    stats.tiles = tiles;
    stats.coc = cocAffine(lens, view);

    // Working memory, sized once per image size.
    ws.radius.resize(pixels);
    ws.intensity.resize(pixels);
    ws.behind.resize(pixels);
    ws.leak.resize(pixels);
    ws.vertical.resize(pixels * 4);
    out_rgba.resize(pixels * 4);
    if (out_coc)
        out_coc->resize(pixels);
    // Reach blocks: vertical pass, max radius per (tile column, 8-row block); horizontal pass,
    // per (row, 8-column block). Each block lies inside one tile, so its tile's task writes it.
    std::vector<float>& vblock = ws.vblock;
    std::vector<float>& hblock = ws.hblock;
    vblock.assign(size_t(p.tiles_x) * p.row_blocks, 0.0f);
    hblock.assign(size_t(p.height) * p.col_blocks, 0.0f);
    const size_t worker_floats = size_t(p.tile) * 7 + size_t(p.tile + 2 * p.reach) * 7;
    ws.worker.resize(worker_floats * workers);
    std::vector<TileCoc>& tile_coc = ws.tile_coc;
    std::vector<uint64_t>& tile_samples = ws.tile_samples;
    std::vector<uint8_t>& copied_v = ws.copied_v;
    std::vector<uint8_t>& copied_h = ws.copied_h;
    tile_coc.assign(tiles, TileCoc{});
    tile_samples.assign(tiles, 0);
    copied_v.assign(tiles, 0);
    copied_h.assign(tiles, 0);

    // --- coc: C = a D + b and the per-pixel weight terms (§4.1, §4.2) ---
    auto t0 = std::chrono::steady_clock::now();
    runTasks(pool, tiles, [&](uint32_t tile, uint32_t) {
        const auto [x0, y0, x1, y1] = p.bounds(tile);
        // The tile's statistics and reach blocks are kept in locals and stored once per block
        // or tile: neighbouring tiles' entries share cache lines, and a store per pixel made
        // the two workers fight over them. The max operations run in the same order.
        TileCoc tc = tile_coc[tile];
        for (uint32_t y = y0; y < y1; ++y) {
            float& vb_slot = vblock[size_t(tile % p.tiles_x) * p.row_blocks + y / kBlock];
            float vb = vb_slot;
            float* hb_row = hblock.data() + size_t(y) * p.col_blocks;
            uint32_t hb_block = x0 / kBlock;
            float hb = hb_row[hb_block];
            for (uint32_t x = x0; x < x1; ++x) {
                const size_t i = size_t(y) * p.width + x;
                PixelTerms t{};
                bool bad_depth = false;
                if (!pixelTerms(image, stats.coc, settings, i, t, bad_depth)) {
                    if (i < tc.first_bad) {
                        tc.first_bad = i;
                        tc.bad_depth = bad_depth;
                    }
                    t = PixelTerms{0.0f, 0.0f, 1.0f, 0.0f, 0.0f};
                }
                ws.radius[i] = t.radius;
                ws.intensity[i] = t.intensity;
                ws.behind[i] = t.behind;
                ws.leak[i] = t.leak;
                if (out_coc)
                    (*out_coc)[i] = t.coc;
                tc.min_c = std::min(tc.min_c, t.coc);
                tc.max_c = std::max(tc.max_c, t.coc);
                tc.clamped += std::fabs(t.coc) > settings.max_radius_px ? 1u : 0u;
                if (x / kBlock != hb_block) {
                    hb_row[hb_block] = hb;
                    hb_block = x / kBlock;
                    hb = hb_row[hb_block];
                }
                vb = std::max(vb, t.radius);
                hb = std::max(hb, t.radius);
            }
            hb_row[hb_block] = hb;
            vb_slot = vb;
        }
        tile_coc[tile] = tc;
    });
    size_t first_bad = SIZE_MAX;
    bool first_bad_depth = false;
    stats.min_coc_px = INFINITY;
    stats.max_coc_px = -INFINITY;
    for (const TileCoc& tc : tile_coc) {
        if (tc.first_bad < first_bad) {
            first_bad = tc.first_bad;
            first_bad_depth = tc.bad_depth;
        }
        stats.min_coc_px = std::min(stats.min_coc_px, tc.min_c);
        stats.max_coc_px = std::max(stats.max_coc_px, tc.max_c);
        stats.clamped_pixels += tc.clamped;
    }
    if (first_bad != SIZE_MAX)
        return badInput(image, first_bad, first_bad_depth);
    stats.ms_coc = msSince(t0);

    const float* radius = ws.radius.data();
    const float* inten = ws.intensity.data();
    const float* behind = ws.behind.data();
    const float* leak = ws.leak.data();

    // --- vertical pass (§4.2, first pass): down the columns of the pinhole colour ---
    t0 = std::chrono::steady_clock::now();
    runTasks(pool, tiles, [&](uint32_t tile, uint32_t worker) {
        const auto [x0, y0, x1, y1] = p.bounds(tile);
        const uint32_t n = x1 - x0;
        const auto [acc, wsum, nsum, leak_c, pad] =
            lineScratch(ws.worker.data() + worker * worker_floats, p.tile);
        (void)pad; // the vertical pass reads the image directly
        uint64_t samples = 0;
        bool any_filtered = false;
        for (uint32_t yb = y0; yb < y1; yb += kBlock) {
            // Loop bound for these rows: the largest radius within the full reach.
            const uint32_t k_max = verticalReach(p, settings, vblock.data(), tile % p.tiles_x, yb);
            const uint32_t ye = std::min(y1, yb + kBlock);
            if (k_max == 0) {
                // No neighbour can reach: every output is its centre (resolvePixel).
                for (uint32_t y = yb; y < ye; ++y)
                    std::copy_n(image.rgba + (size_t(y) * p.width + x0) * 4, size_t(n) * 4,
                                ws.vertical.data() + (size_t(y) * p.width + x0) * 4);
                continue;
            }
            any_filtered = true;
            for (uint32_t y = yb; y < ye; ++y) {
                const size_t row = size_t(y) * p.width + x0;
                const float* centre = image.rgba + row * 4;
                // W(C) = I(r_c) (§4.2).
                for (uint32_t x = 0; x < n; ++x) {
                    const float ic = inten[row + x];
                    for (int c = 0; c < 4; ++c)
                        acc[4 * x + c] = ic * centre[4 * x + c];
                    wsum[x] = ic;
                    nsum[x] = 0.0f;
                    leak_c[x] = leak[row + x];
                }
                for (int k = -int(k_max); k <= int(k_max); ++k) {
                    if (k == 0)
                        continue;
                    // Clamp to edge (§5): border pixels are blended with themselves; the
                    // distance stays |k|.
                    const int ys = std::clamp(int(y) + k, 0, int(p.height) - 1);
                    const size_t srow = size_t(ys) * p.width + x0;
                    const float dist = float(std::abs(k));
                    addSamples(radius + srow, inten + srow, behind + srow, image.rgba + srow * 4,
                               leak_c, dist, n, wsum, nsum, acc, settings.simd);
                }
                samples += uint64_t(n) * 2 * k_max;
                float* out = ws.vertical.data() + row * 4;
                for (uint32_t x = 0; x < n; ++x)
                    resolvePixel(acc + 4 * x, wsum[x], nsum[x], centre + 4 * x, out + 4 * x);
            }
        }
        copied_v[tile] = any_filtered ? 0 : 1;
        tile_samples[tile] += samples;
    });
    stats.ms_vertical = msSince(t0);

    // --- horizontal pass (§4.2, second pass): along the rows of the vertical output ---
    t0 = std::chrono::steady_clock::now();
    runTasks(pool, tiles, [&](uint32_t tile, uint32_t worker) {
        const auto [x0, y0, x1, y1] = p.bounds(tile);
        const uint32_t n = x1 - x0;
        const auto [acc, wsum, nsum, leak_c, pad] =
            lineScratch(ws.worker.data() + worker * worker_floats, p.tile);
        const size_t pad_len = size_t(p.tile) + 2 * p.reach;
        float* pr = pad;
        float* pi = pr + pad_len;
        float* pb = pi + pad_len;
        float* pc = pb + pad_len;
        uint64_t samples = 0;
        bool any_filtered = false;
        for (uint32_t y = y0; y < y1; ++y) {
            const size_t row = size_t(y) * p.width;
            const float* src = ws.vertical.data() + row * 4;
            const uint32_t k_max = horizontalReach(p, settings, hblock.data(), y, x0, x1);
            float* out = out_rgba.data() + (row + x0) * 4;
            if (k_max == 0) {
                std::copy_n(src + size_t(x0) * 4, size_t(n) * 4, out);
                continue;
            }
            any_filtered = true;
            // Gather the row with clamp-to-edge padding so the inner loop is contiguous.
            const uint32_t len = n + 2 * k_max;
            for (uint32_t j = 0; j < len; ++j) {
                const int xs = std::clamp(int(x0) - int(k_max) + int(j), 0, int(p.width) - 1);
                pr[j] = radius[row + size_t(xs)];
                pi[j] = inten[row + size_t(xs)];
                pb[j] = behind[row + size_t(xs)];
                for (int c = 0; c < 4; ++c)
                    pc[4 * j + c] = src[size_t(xs) * 4 + c];
            }
            const float* centre = src + size_t(x0) * 4;
            for (uint32_t x = 0; x < n; ++x) {
                const float ic = inten[row + x0 + x];
                for (int c = 0; c < 4; ++c)
                    acc[4 * x + c] = ic * centre[4 * x + c];
                wsum[x] = ic;
                nsum[x] = 0.0f;
                leak_c[x] = leak[row + x0 + x];
            }
            for (int k = -int(k_max); k <= int(k_max); ++k) {
                if (k == 0)
                    continue;
                const float dist = float(std::abs(k));
                const size_t off = size_t(int(k_max) + k);
                addSamples(pr + off, pi + off, pb + off, pc + off * 4, leak_c, dist, n, wsum, nsum,
                           acc, settings.simd);
            }
            samples += uint64_t(n) * 2 * k_max;
            for (uint32_t x = 0; x < n; ++x)
                resolvePixel(acc + 4 * x, wsum[x], nsum[x], centre + 4 * x, out + 4 * x);
        }
        copied_h[tile] = any_filtered ? 0 : 1;
        tile_samples[tile] += samples;
    });
    stats.ms_horizontal = msSince(t0);

    for (uint32_t t = 0; t < tiles; ++t) {
        stats.samples += tile_samples[t];
        stats.tiles_copied_vertical += copied_v[t];
        stats.tiles_copied_horizontal += copied_h[t];
        stats.tiles_copied += copied_v[t] & copied_h[t];
    }
    return stats;
} catch (const std::bad_alloc&) {
    return detail::outOfMemory("running gather");
}

Result<GatherStats> gatherReference(const GatherImage& image, const ThinLens& lens,
                                    const raster::View& view, const GatherSettings& settings,
                                    std::vector<float>& out_rgba) try {
    if (Status st = checkAll(image, lens, view, settings); !st.ok())
        return st;
    const uint32_t w = image.width, h = image.height;
    const size_t pixels = size_t(w) * h;
    GatherStats stats;
    stats.tiles = 1;
    stats.coc = cocAffine(lens, view);
    std::vector<float> radius(pixels), intensity(pixels), behind(pixels), leak(pixels);
    stats.min_coc_px = INFINITY;
    stats.max_coc_px = -INFINITY;
    for (size_t i = 0; i < pixels; ++i) {
        bool bad_depth = false;
        PixelTerms t{};
        if (!pixelTerms(image, stats.coc, settings, i, t, bad_depth))
            return badInput(image, i, bad_depth);
        radius[i] = t.radius;
        intensity[i] = t.intensity;
        behind[i] = t.behind;
        leak[i] = t.leak;
        stats.min_coc_px = std::min(stats.min_coc_px, t.coc);
        stats.max_coc_px = std::max(stats.max_coc_px, t.coc);
        stats.clamped_pixels += std::fabs(t.coc) > settings.max_radius_px ? 1u : 0u;
    }
    const TermArrays terms{radius.data(), intensity.data(), behind.data(), leak.data()};
    const uint32_t reach = fullReach(settings);
    NoRecorder none;
    // The two 1-D passes of the §5 pseudo-code, every pixel over the full reach.
    std::vector<float> vertical(pixels * 4);
    out_rgba.resize(pixels * 4);
    for (bool vert : {true, false}) {
        const float* src = vert ? image.rgba : vertical.data();
        float* dst = vert ? vertical.data() : out_rgba.data();
        for (uint32_t y = 0; y < h; ++y)
            for (uint32_t x = 0; x < w; ++x)
                filterPixel(terms, src, w, h, vert, x, y, reach, dst + (size_t(y) * w + x) * 4,
                            none);
    }
    stats.samples = uint64_t(pixels) * 2 * 2 * reach;
    return stats;
} catch (const std::bad_alloc&) {
    return detail::outOfMemory("running the gather reference");
}

Status probeGather(const GatherImage& image, const ThinLens& lens, const raster::View& view,
                   const GatherSettings& settings, const GatherScratch& scratch, uint32_t x,
                   uint32_t y, GatherPixelProbe& out) try {
    if (Status st = checkAll(image, lens, view, settings); !st.ok())
        return st;
    if (x >= image.width || y >= image.height)
        return Status::error("gather probe: pixel (" + std::to_string(x) + ", " +
                             std::to_string(y) + ") is outside the " + std::to_string(image.width) +
                             "x" + std::to_string(image.height) + " image");
    const Plan p = makePlan(image, settings);
    const size_t pixels = size_t(p.width) * p.height;
    const size_t i = size_t(y) * p.width + x;
    PixelTerms t{};
    bool bad_depth = false;
    const bool kept = scratch.radius.size() == pixels && scratch.intensity.size() == pixels &&
                      scratch.behind.size() == pixels && scratch.leak.size() == pixels &&
                      scratch.vertical.size() == pixels * 4 &&
                      scratch.vblock.size() == size_t(p.tiles_x) * p.row_blocks &&
                      scratch.hblock.size() == size_t(p.height) * p.col_blocks;
    // The pixel's own terms must be the kept ones: a cheap check that the scratch holds this
    // frame (§4.1: C = a D + b).
    if (!kept || !pixelTerms(image, cocAffine(lens, view), settings, i, t, bad_depth) ||
        t.radius != scratch.radius[i] || t.intensity != scratch.intensity[i])
        return Status::error("gather probe: the scratch does not hold this frame (run gather() "
                             "with it on the same image and settings first)");

    out = GatherPixelProbe{};
    out.x = x;
    out.y = y;
    out.coc_px = t.coc;
    out.radius_px = t.radius;
    const uint32_t x0 = (x / p.tile) * p.tile;
    out.vertical_reach =
        verticalReach(p, settings, scratch.vblock.data(), x / p.tile, (y / kBlock) * kBlock);
    out.horizontal_reach =
        horizontalReach(p, settings, scratch.hblock.data(), y, x0, std::min(p.width, x0 + p.tile));
    out.copied_vertical = out.vertical_reach == 0;
    out.copied_horizontal = out.horizontal_reach == 0;

    // Records each tap of a pass into `taps`.
    struct TapRecorder {
        std::vector<GatherTap>& taps;
        void tap(uint32_t sx, uint32_t sy, int k, const SampleFactors& f, float w, const float* c) {
            GatherTap g;
            g.x = int32_t(sx);
            g.y = int32_t(sy);
            g.offset = k;
            g.weight = w;
            g.overlap = f.overlap;
            g.intensity = f.intensity;
            g.leakage = f.leakage;
            std::copy_n(c, 4, g.rgba);
            taps.push_back(g);
        }
    };
    const TermArrays terms{scratch.radius.data(), scratch.intensity.data(), scratch.behind.data(),
                           scratch.leak.data()};
    // Pass 1 on the pinhole image, pass 2 on the kept output of pass 1 (§4.2).
    TapRecorder vrec{out.vertical};
    filterPixel(terms, image.rgba, p.width, p.height, true, x, y, out.vertical_reach,
                out.vertical_rgba, vrec);
    TapRecorder hrec{out.horizontal};
    filterPixel(terms, scratch.vertical.data(), p.width, p.height, false, x, y,
                out.horizontal_reach, out.rgba, hrec);
    return {};
} catch (const std::bad_alloc&) {
    return detail::outOfMemory("probing gather");
}

} // namespace dof
