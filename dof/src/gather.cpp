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

// The weight of one sample at offset k (|k| = dist >= 1) for a centre whose leak factor is
// leak_c: W(P) = O(r_p) I(r_p) L(z_p) (§4.2), with O(r_p) = clamp(r_p - d_p, 0, 1): 0 when
// r_p <= d_p, the fractional ramp r_p - d_p up to d_{p+1} = d_p + 1, then 1. The clamps are
// written as SSE's MAXPS/MINPS define them ((a > b) ? a : b, (a < b) ? a : b), so the SSE2 path
// below produces the same bits, signed zeros included.
inline float sampleWeight(float r_p, float i_p, float behind_p, float leak_c, float dist) {
    const float t = r_p - dist;
    const float t0 = t > 0.0f ? t : 0.0f;
    const float o = t0 < 1.0f ? t0 : 1.0f;
    // L(z_p): leak_c behind the focal plane (behind_p = 1), else 1. Exact for behind_p in {0, 1}
    // (no rounding: 1*x + 0 and 0*x + 1), and branch-free.
    const float l = behind_p * leak_c + (1.0f - behind_p);
    return (o * i_p) * l;
}

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
    for (; x < n; ++x) {
        const float w = sampleWeight(r_s[x], i_s[x], b_s[x], leak_c[x], dist);
        wsum[x] += w;
        nsum[x] += w;
        for (uint32_t c = 0; c < 4; ++c)
            acc[4 * x + c] += w * c_s[4 * x + c];
    }
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

} // namespace

StoredDepthRef depthRefOf(const raster::DepthBuffer& depth) {
    StoredDepthRef r;
    r.format = depth.format;
    r.unorm16 = depth.unorm16.empty() ? nullptr : depth.unorm16.data();
    r.float32 = depth.float32.empty() ? nullptr : depth.float32.data();
    return r;
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

    Plan p;
    p.width = image.width;
    p.height = image.height;
    p.tile = settings.tile_size;
    p.tiles_x = (p.width + p.tile - 1) / p.tile;
    p.tiles_y = (p.height + p.tile - 1) / p.tile;
    p.reach = fullReach(settings);
    p.row_blocks = (p.height + kBlock - 1) / kBlock;
    p.col_blocks = (p.width + kBlock - 1) / kBlock;
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
        TileCoc& tc = tile_coc[tile];
        for (uint32_t y = y0; y < y1; ++y) {
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
                float& vb = vblock[size_t(tile % p.tiles_x) * p.row_blocks + y / kBlock];
                float& hb = hblock[size_t(y) * p.col_blocks + x / kBlock];
                vb = std::max(vb, t.radius);
                hb = std::max(hb, t.radius);
            }
        }
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
            uint32_t k_max = 0;
            if (settings.skip_tiles) {
                const uint32_t lo = yb >= p.reach ? (yb - p.reach) / kBlock : 0;
                const uint32_t hi = std::min(p.height - 1, yb + kBlock - 1 + p.reach) / kBlock;
                float max_r = 0.0f;
                for (uint32_t b = lo; b <= hi; ++b)
                    max_r = std::max(max_r, vblock[size_t(tile % p.tiles_x) * p.row_blocks + b]);
                k_max = std::min(p.reach, reachOf(max_r));
            } else {
                k_max = p.reach;
            }
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
            uint32_t k_max = p.reach;
            if (settings.skip_tiles) {
                const uint32_t lo = x0 >= p.reach ? (x0 - p.reach) / kBlock : 0;
                const uint32_t hi = std::min(p.width - 1, x1 - 1 + p.reach) / kBlock;
                float max_r = 0.0f;
                for (uint32_t b = lo; b <= hi; ++b)
                    max_r = std::max(max_r, hblock[size_t(y) * p.col_blocks + b]);
                k_max = std::min(p.reach, reachOf(max_r));
            }
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
    std::vector<PixelTerms> terms(pixels);
    stats.min_coc_px = INFINITY;
    stats.max_coc_px = -INFINITY;
    for (size_t i = 0; i < pixels; ++i) {
        bool bad_depth = false;
        if (!pixelTerms(image, stats.coc, settings, i, terms[i], bad_depth))
            return badInput(image, i, bad_depth);
        stats.min_coc_px = std::min(stats.min_coc_px, terms[i].coc);
        stats.max_coc_px = std::max(stats.max_coc_px, terms[i].coc);
        stats.clamped_pixels += std::fabs(terms[i].coc) > settings.max_radius_px ? 1u : 0u;
    }
    const int reach = int(fullReach(settings));
    // One 1-D pass of the §5 pseudo-code: `step` is the pixel-index stride along the pass.
    auto pass = [&](const std::vector<float>& src, std::vector<float>& dst, bool vertical) {
        for (uint32_t y = 0; y < h; ++y)
            for (uint32_t x = 0; x < w; ++x) {
                const size_t ci = size_t(y) * w + x;
                const PixelTerms& tc = terms[ci];
                float acc[4];
                for (int c = 0; c < 4; ++c)
                    acc[c] = tc.intensity * src[ci * 4 + c];
                float wsum = tc.intensity, nsum = 0.0f;
                for (int k = -reach; k <= reach; ++k) {
                    if (k == 0)
                        continue;
                    const size_t si =
                        vertical ? size_t(std::clamp(int(y) + k, 0, int(h) - 1)) * w + x
                                 : size_t(y) * w + size_t(std::clamp(int(x) + k, 0, int(w) - 1));
                    const PixelTerms& ts = terms[si];
                    const float wt = sampleWeight(ts.radius, ts.intensity, ts.behind, tc.leak,
                                                  float(std::abs(k)));
                    wsum += wt;
                    nsum += wt;
                    for (int c = 0; c < 4; ++c)
                        acc[c] += wt * src[si * 4 + c];
                    ++stats.samples;
                }
                resolvePixel(acc, wsum, nsum, &src[ci * 4], &dst[ci * 4]);
            }
    };
    std::vector<float> input(image.rgba, image.rgba + pixels * 4), vertical(pixels * 4);
    out_rgba.resize(pixels * 4);
    pass(input, vertical, true);
    pass(vertical, out_rgba, false);
    return stats;
} catch (const std::bad_alloc&) {
    return detail::outOfMemory("running the gather reference");
}

} // namespace dof
