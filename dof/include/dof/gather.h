// `gather`: the post-process of Zhou, Chen & Pullen 2007 ("Accurate depth of field simulation in
// real time"). Consumes a pinhole colour image (linear RGBA float) and its stored, non-linear
// depth buffer (16-bit unorm or 32-bit float, camera.h convention) plus the thin lens and the
// View the frame was rendered with; produces the depth-of-field image (and optionally the signed
// CoC map). Inputs are plain read-only views, so the filter runs as well on EXRs loaded from
// disk; the caller owns the output vectors, GatherScratch holds the working memory between
// frames.
//
// Stages (docs/dof/gather.md):
//   coc         per pixel C = a*D + b from the stored depth D (§4.1, Eq. 3-7 rewritten for
//               focal's projection: C is affine in D, see cocAffine), then the weight terms.
//   vertical    the adaptive 1-D filter of §4.2 down the columns,
//   horizontal  the same filter along the rows of the vertical pass's output.
// Each output pixel is computed by exactly one task, its samples summed in a fixed order, so the
// bytes do not depend on the thread count or the tile size. Tiles the lens cannot change are
// copied (see GatherStats); the copy is exact, the same bits as filtering them. probeGather
// re-runs one pixel's passes on the kept GatherScratch and records every tap.
#pragma once

#include <dof/lens.h>
#include <dof/settings_table.h>
#include <raster/camera.h>
#include <raster/frame.h>
#include <raster/status.h>
#include <raster/storage.h>
#include <raster/task_pool.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace dof {

// A read-only view of a stored depth buffer: D in [-1, 0] (camera.h), one value per pixel, rows
// top first, in the format the frame was rendered with.
struct StoredDepthRef {
    raster::DepthFormat format = raster::DepthFormat::Float32;
    const uint16_t* unorm16 = nullptr; // format == Unorm16: D = value / 65535 - 1
    const float* float32 = nullptr;    // format == Float32
};

// The view of a raster::DepthBuffer (which must outlive it).
StoredDepthRef depthRefOf(const raster::DepthBuffer& depth);

// The pinhole frame the filter reads.
struct GatherImage {
    const float* rgba = nullptr; // linear RGBA, 4 floats per pixel, width*height pixels
    StoredDepthRef depth;
    uint32_t width = 0;
    uint32_t height = 0;
};
// The view of a raster::Frame's colour and depth (the frame must outlive it).
GatherImage gatherImageOf(const raster::Frame& frame);

// §4.1 rewritten for focal: the stored depth is D = -(1/d - 1/f) / (1/n - 1/f) (the window-space
// z'/w' of Eq. 4 mapped to [-1, 0], reversed-Z with the sign flipped), so 1/d = 1/f - D (1/n - 1/f)
// and the CoC of Eq. 2, C(d) = E f_px (1/d_f - 1/d), is affine in D:
//   C = a D + b,   a = E f_px (1/n - 1/f),   b = E f_px (1/d_f - 1/f)      (1/f = 0 if f = inf).
// Computed in double; C is then evaluated per pixel as a*D + b in double and rounded to float.
struct CocAffine {
    double a = 0.0; // pixels per unit of stored depth
    double b = 0.0; // pixels (the CoC at D = 0, i.e. on the far plane or at infinity)
};
CocAffine cocAffine(const ThinLens& lens, const raster::View& view);

struct GatherSettings {
    // R: the largest CoC radius the filter honours, pixels, in [1, 256]. Each 1-D pass reads
    // up to ceil(R) - 1 pixels either side; radii beyond R are clamped to R (the light is spread
    // over the filter's reach instead of the full circle). --gather-max-radius.
    float max_radius_px = 16.0f;
    // L(z_p) of §4.2 for samples behind the focal plane: min(1, leak_scale * r_c), r_c the centre
    // pixel's CoC radius in pixels. 1 means background samples count fully once the centre's CoC
    // reaches one pixel; 0 removes background samples entirely. >= 0. --gather-leak-scale.
    float leak_scale = 1.0f;
    // I(r) = 1 / max(r, min_radius)^2 (§4.2 "I(r_p) ∝ 1/r_p²" with the pole removed): a CoC
    // smaller than this still covers one pixel's footprint. In (0, 1]. --gather-min-radius.
    float min_radius_px = 0.5f;
    // Work unit: square tiles of this many pixels, a multiple of 8 in [8, 256]. Does not change
    // the output bits.
    uint32_t tile_size = 64;
    // Copy tiles whose largest CoC radius, including every pixel that can reach them, is below
    // half a pixel, and bound each row's loop by the largest CoC that can reach it. Off: the
    // plain per-pixel loop over the whole reach (the reference path; same bits).
    bool skip_tiles = true;
    // Add four centres' samples at once in SSE2 lanes where the build has them (x86-64 without
    // FOCAL_NO_SIMD). Off: the scalar loop alone, the reference the lanes reproduce bit for bit.
    // `focal render --no-simd`.
    bool simd = true;
};

// The parameters of GatherSettings a caller chooses (settings_table.h). Not in it: tile_size and
// simd, which dof::FrameRenderer takes from the raster options.
std::span<const Param<GatherSettings>> gatherParams();

// Rejects NaN, R outside [1, 256], leak_scale < 0, min_radius outside (0, 1], bad tile sizes.
// Messages name the fields ("gather settings: max_radius_px must be in [1, 256], got 0").
raster::Status validate(const GatherSettings& settings);

struct GatherStats {
    uint32_t tiles = 0;                   // tiles per pass
    uint32_t tiles_copied_vertical = 0;   // copied unfiltered by the vertical pass
    uint32_t tiles_copied_horizontal = 0; // copied unfiltered by the horizontal pass
    uint32_t tiles_copied = 0;            // copied by both passes: the output is the input
    uint64_t samples = 0;                 // sample weights evaluated, both passes (the work done)
    uint64_t clamped_pixels = 0;          // pixels whose |C| exceeded R
    float min_coc_px = 0.0f;              // signed CoC range over the image (background included)
    float max_coc_px = 0.0f;
    CocAffine coc;
    double ms_coc = 0.0;
    double ms_vertical = 0.0;
    double ms_horizontal = 0.0;
};

// Working memory reused between frames (resized on the first call and when the image grows).
struct GatherScratch {
    std::vector<float> radius;    // per pixel: min(|C|, R)
    std::vector<float> intensity; // per pixel: I(r) = 1 / max(r, min_radius)^2
    std::vector<float> behind;    // per pixel: 1 if C > 0 (behind the focal plane), else 0
    std::vector<float> leak;      // per pixel: L for background samples, min(1, s * |C|)
    std::vector<float> vertical;  // RGBA output of the vertical pass
    std::vector<float> worker;    // per-worker accumulators and padded rows
    std::vector<uint16_t> reach;  // per tile/row-block loop bounds
    std::vector<float> vblock;    // max radius per (tile column, 8-row block): vertical pass
    std::vector<float> hblock;    // max radius per (row, 8-column block): horizontal pass
    // The coc stage's per-tile reduction, combined in tile order afterwards.
    struct TileCoc {
        size_t first_bad = SIZE_MAX; // first pixel (row-major index) with bad input
        bool bad_depth = false;      // else: bad colour
        float min_c = INFINITY;
        float max_c = -INFINITY;
        uint64_t clamped = 0;
    };
    std::vector<TileCoc> tile_coc;
    std::vector<uint64_t> tile_samples;      // samples added per tile
    std::vector<uint8_t> copied_v, copied_h; // per tile: the pass copied instead of filtering
};

// Runs the filter. `out_rgba` is resized to width*height*4; `out_coc`, when given, receives the
// signed CoC C per pixel (pixels). `pool` may be null (inline). Fails, naming the problem, on
// an invalid lens or settings, a null/empty image, non-finite colour, or stored depth that is
// not finite or outside [-1, 0] (the first offending pixel in row order).
raster::Result<GatherStats> gather(const GatherImage& image, const ThinLens& lens,
                                   const raster::View& view, const GatherSettings& settings,
                                   std::vector<float>& out_rgba,
                                   std::vector<float>* out_coc = nullptr,
                                   raster::TaskPool* pool = nullptr,
                                   GatherScratch* scratch = nullptr);

// Scalar reference: the paper's fragment-shader loop (§5) for every pixel, one pixel at a time,
// over the full reach, no tiles, no skipping. Same contract and the same bits as gather(); slow.
raster::Result<GatherStats> gatherReference(const GatherImage& image, const ThinLens& lens,
                                            const raster::View& view,
                                            const GatherSettings& settings,
                                            std::vector<float>& out_rgba);

// --- Probing a pixel (focal steps / focal probe) ---------------------------------------------

// One sample a pass read for the probed pixel: the §5 pseudo-code's inner-loop iteration, or the
// centre's own term. weight == (overlap * intensity) * leakage, bit for bit, as the pass
// computes it (§4.2: W(P) = O(r_p) I(r_p) L(z_p)).
struct GatherTap {
    int32_t x = 0, y = 0;   // the sample's pixel (clamped to the image edge, §5)
    int32_t offset = 0;     // k: its offset along the pass; 0 is the centre, W(C) = I(r_c)
    float weight = 0.0f;    // W: its weight in the pass's sums
    float overlap = 0.0f;   // O(r_p) = clamp(r_p - |k|, 0, 1) (§4.2); 1 for the centre
    float intensity = 0.0f; // I(r_p) = 1 / max(r_p, min_radius)^2 (§4.2)
    float leakage = 0.0f;   // L(z_p): the centre's min(1, s r_c) if the sample lies behind the
                            // focal plane (C_p > 0), else 1 (§4.2); 1 for the centre
    float rgba[4] = {};     // the colour the pass read at the sample (the vertical pass: the
                            // pinhole image; the horizontal pass: the vertical pass's output)
};

// What made one output pixel of gather(): the taps of both passes, in the order the pass adds
// them (centre first, then k = -K..K without 0). Owns its vectors.
struct GatherPixelProbe {
    uint32_t x = 0, y = 0;
    float coc_px = 0.0f;    // signed CoC C of the pixel (Eq. 2, evaluated as a*D + b, §4.1)
    float radius_px = 0.0f; // r_c = min(|C|, R): the radius the filter uses
    // The loop bound K of each pass at the pixel (skip_tiles: the largest radius that can reach
    // its 8-pixel block; else ceil(R) - 1). 0: the pass copied the pixel instead of filtering
    // (the tap list then holds the centre alone, which gives the same bits as the copy).
    uint32_t vertical_reach = 0;
    uint32_t horizontal_reach = 0;
    bool copied_vertical = false;      // vertical_reach == 0
    bool copied_horizontal = false;    // horizontal_reach == 0
    std::vector<GatherTap> vertical;   // pass 1 at (x, y), down the column
    std::vector<GatherTap> horizontal; // pass 2 at (x, y), along the row of pass 1's output
    float vertical_rgba[4] = {};       // pass 1's output at (x, y)
    float rgba[4] = {};                // the final output at (x, y)
};

// After gather() wrote `out_rgba` with `scratch` (and the same image, lens, view and settings),
// re-runs pixel (x, y)'s two passes on the kept per-pixel terms and vertical output with the
// same per-tap code, recording every tap into `out` (which it overwrites; it allocates the tap
// lists). out.rgba equals out_rgba at (x, y) bit for bit, out.vertical_rgba the kept vertical
// output. The probe runs the scalar loop, which the SSE2 lanes reproduce bit for bit
// (GatherSettings::simd). Reads `image` and `scratch`, changes neither. Fails on invalid
// settings or lens, (x, y) outside the image, or a scratch that does not hold this frame.
raster::Status probeGather(const GatherImage& image, const ThinLens& lens, const raster::View& view,
                           const GatherSettings& settings, const GatherScratch& scratch, uint32_t x,
                           uint32_t y, GatherPixelProbe& out);

} // namespace dof
