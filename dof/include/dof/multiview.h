// `multiview`: depth of field by multiview synthesis from a layered image-based scene
// (Lee, Eisemann & Seidel 2009). Consumes a pinhole frame and a raster::LayeredTarget rendered
// through the lens centre (§4.1-4.2; or render callbacks that produce them), the thin lens and a
// lens sample set; traces N lens rays per pixel through the layers' height fields (§4.3, Eq. 2-3)
// with N-buffer culling (§4.3), approximate cone tracing (§4.4; also for rays that miss a
// layer, MultiviewSettings::cone_misses; cones centred on their samples' Voronoi cells,
// MultiviewSettings::cone_centre), optional jittered lens sampling (§4.5; the shared set
// is the default) and optional view-dependent shading per ray (§5). Produces linear RGBA owned
// by the caller; scratch (N-buffers, mipmaps) lives in the MultiviewScratch the caller may keep
// between frames.
//
// Determinism: the image is split into tiles; each output pixel is computed by one task, its
// rays traced in sample order and summed in a fixed order; counters are summed per tile, then in
// tile order. Jitter is a pure function of (pixel, sample index, seed). Output bytes do not
// depend on the thread count.
#pragma once

#include <dof/layer_spacing.h>
#include <dof/lens.h>
#include <dof/lens_samples.h>
#include <dof/n_buffer.h>
#include <dof/settings_table.h>
#include <raster/camera.h>
#include <raster/frame.h>
#include <raster/layered_target.h>
#include <raster/renderer.h>
#include <raster/scene.h>
#include <raster/status.h>
#include <raster/task_pool.h>

#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace dof {

// Per-pixel variation of the lens samples (§4.5). Every choice is a pure function of the pixel,
// the sample index and MultiviewSettings::seed.
enum class JitterMode : uint8_t {
    None,   // every pixel uses the shared set (like accum): aliasing along edges, which the cones
            // (§4.4) smooth; the default: closer to accum than Noise on every built-in scene,
            // in PSNR and SSIM (docs/benchmarks.md)
    Noise,  // the paper's trade-off: a per-pixel 4-component noise texel; its 16 pairwise
            // combinations (n_i, n_j) offset 1/16th of the samples each, scaled by lambda/2
    Halton, // the paper's best quality: a 2N-sample sequence, each pixel takes N consecutive
            // samples from an offset in [0, 2N-1] (needs MultiviewSettings::sequence_2n)
    Rotate, // a per-pixel Cranley-Patterson rotation of the pattern (LensSampleSet::sample(x,y,i))
};

// How a lens ray's segment is intersected with a layer's height field (§4.3).
enum class Traversal : uint8_t {
    FalsePosition, // the paper: false-position steps, then a binary search (approximate)
    Scan,          // every texel the segment crosses (§6's "brute-force scanning": exact)
};

// What happens to a lens ray whose path leaves the image (§4.3 "Handling Off-Screen Pixels").
enum class OffscreenPolicy : uint8_t {
    Discard, // the paper: the ray is dropped and the remaining rays' weights renormalised
    Clamp,   // the ray reads the nearest border texel instead; the default: better than or equal
             // to Discard against accum on every built-in scene, in PSNR and SSIM
             // (docs/benchmarks.md)
};

// Where a ray's cone (§4.4) is centred. A cone stands for the part of the aperture closest to
// its lens sample, its Voronoi cell. Sample centres it on the ray (the paper): the cones of the
// outer samples then reach past the aperture's rim by half a sample spacing, and every defocused
// highlight's disc gets a soft, too wide rim. Cell centres it on the cell's centroid
// (lensCellOffsets), which lies inward of an outer sample. Used with JitterMode::None: the
// other modes move the samples per pixel, so their cones stay on the ray.
enum class ConeCentre : uint8_t {
    Sample,
    Cell,
};

// How a cone hit (§4.4) is shaded when hits are re-shaded per ray (§5). The paper mipmaps the
// G-buffer; shading a filtered G-buffer texel is not the filtered shading, so we instead shade
// level-0 texels of the cone's footprint and average them.
enum class ConeShading : uint8_t {
    Centre,    // shade the centre ray's hit texel only (cheap; the footprint's colour is ignored)
    Footprint, // shade the covered texels among 5 taps of the footprint (centre and +-r/2 in x
               // and y, r the cone radius) and average them: the mean of what the cone sees
};

// An equirectangular environment map in linear RGB for reflections (§5, Fig. 9): row 0 is the
// +y pole; u = 0.5 + atan2(dir.x, -dir.z) / 2pi. Plain data (loaded by the app).
struct EnvironmentMap {
    uint32_t width = 0;
    uint32_t height = 0;
    std::vector<float> rgb; // width*height*3
    float intensity = 1.0f;
};

// What a lens ray met in one layer it visited (traceLayer; layers culled for the whole pixel
// are not visited, MultiviewPixelProbe::layers).
enum class MultiviewStepResult : uint8_t {
    Skipped,    // it resumes behind a partially covered cone past this segment (§4.4): no test
    Passed,     // no hit, and no cone of the miss saw anything
    Hit,        // hit a texel and took its colour (sharp: cones off, or lambda |C(d)| <= 1)
    Cone,       // hit, coloured by its cone (§4.4): coverage v1 and mean colour c1 of the mipmap
    MissedCone, // no hit; the cone of the miss saw coverage v1 > 0 (cone_misses)
};

// One (ray, layer) step of traceLayer (§4.3-§4.4), in the order the ray met the layers.
struct MultiviewLayerStep {
    uint32_t layer = 0;
    float t_enter = 0.0f; // stored D where the ray enters the segment (its start or t_resume)
    // §4.3 per-ray culling: one N-buffer query on the box of the ray's cells found nothing of
    // the layer there, so no height-field test was run (lossless).
    bool culled = false;
    bool tested = false; // the height-field test ran (§4.3)
    // Traversal::FalsePosition (§4.3): false-position iterations (bound_init's first point
    // included) and binary-search steps after the bracketing, over the opaque and the
    // transparent plane's searches.
    uint32_t false_position_steps = 0;
    uint32_t binary_steps = 0;
    uint32_t fetches = 0; // height-field texels read
    MultiviewStepResult result = MultiviewStepResult::Passed;
    float t = 0.0f;           // Hit, Cone: stored D of the hit; MissedCone: where the cone looked
    uint32_t texel = 0;       // Hit, Cone: index of the texel hit (y * width + x)
    float coverage = 0.0f;    // Hit: 1; Cone, MissedCone: the cone's coverage v1 (§4.4)
    glm::vec3 c1{0.0f};       // Hit: the texel's colour; Cone, MissedCone: the cone's c1 (§4.4)
    bool transparent = false; // the layer's transparent plane was hit in front (BLEND surfaces)
    // The ray after the step: its colour so far and the transmittance (1 - v1) products (§4.4)
    // left for the layers behind (0: the ray has ended).
    glm::vec3 color{0.0f};
    float transmit = 0.0f;
};

// One lens ray of a pixel (probeMultiview): the straight line p + C(t) w in (x, y, D) of §4.3,
// where it starts and ends, each layer it visited and what it gave the pixel. How it ended:
// discarded; else layer >= 0: blocked there (by a hit, or by cones whose coverage, §4.4, used
// it up); else layer -1: it passed every layer and sees the background with what it had left.
struct MultiviewRayRecord {
    glm::vec2 lens{0.0f};      // jittered lens position (lens units, §4.5)
    float weight = 0.0f;       // the sample's weight
    float t_start = 0.0f;      // stored D where the ray enters the first layer
    float t_end = 0.0f;        // stored D of the hit that ended it (or of the last layer's end)
    glm::vec2 start_px{0.0f};  // image position at t_start
    glm::vec2 end_px{0.0f};    // image position at t_end
    int32_t layer = -1;        // layer of the hit that ended it; -1: background
    uint32_t partial_hits = 0; // cone hits with coverage < 1 passed through (§4.4)
    uint32_t missed_cones = 0; // layers missed whose cone saw something (cone_misses)
    bool discarded = false;    // left the image (OffscreenPolicy::Discard): not in the mean
    std::vector<MultiviewLayerStep> steps; // layer by layer, front to back
    // What the ray adds to the pixel's weighted mean (§4.3): its colour, the background seen
    // through what it had left, alpha 1; all 0 when discarded.
    float rgba[4] = {};
};

// Why a layer was or was not visited by a pixel's rays (§4.3 early culling with N-buffers).
enum class MultiviewLayerCull : uint8_t {
    Empty,     // the layer holds no fragment
    Tile,      // one N-buffer query for the pixel's output tile found nothing in reach
    Pixel,     // the pixel's query found nothing in reach of its rays or of their cones
    ConesOnly, // the rays cannot hit it, only their missed cones see it (cone_misses)
    None,      // visited by every ray that was still going
};

// Everything one output pixel's tracing did (probeMultiview).
struct MultiviewPixelProbe {
    uint32_t x = 0, y = 0;
    // The frame was not traced (MultiviewStats::skipped): the pixel is the pinhole's, no rays.
    bool skipped = false;
    // The frame resolved this pixel in focus without tracing its rays (every ray hits its own
    // texel, §4.3); the rays below are traced anyway and give the same bytes.
    bool in_focus = false;
    std::vector<MultiviewLayerCull> layers; // per layer index
    std::vector<MultiviewRayRecord> rays;   // every lens ray of the pixel, in sample order
    float rgba[4] = {};                     // the pixel's result, bit-equal to what the frame wrote
};

struct MultiviewSettings {
    float layer_spacing_px = 2.0f; // delta of §4.1 (used when layers == 0)
    uint32_t layers = 0;           // M; 0: from layer_spacing_px (capped at raster::kMaxLayers)
    float overlap = 0.1f;          // §4.2: each layer widened by this fraction (in 1/d)
    raster::LayerRouting routing = raster::LayerRouting::MaxVertexDepth;
    raster::ColorFormat color_format = raster::ColorFormat::Half;
    raster::DepthFormat depth_format = raster::DepthFormat::Float32;
    uint32_t iterations = 3;   // false-position steps per layer (§4.3: "three ... enough")
    uint32_t refine_steps = 4; // binary-search steps after the bracketing (§4.3)
    // §4.3's shortcut: start the false position from the layer's depth bounds as d_u, d_l, and
    // look the segment's end texels up only when the texel under the first point is empty.
    bool bound_init = false;
    Traversal traversal = Traversal::Scan;
    // How far behind its stored depth a covered texel is solid (used by Traversal::Scan; the
    // false position needs a closed height field to bracket its crossings), as a CoC difference in
    // pixels (converted to D with Eq. 3). INFINITY is the paper's height field: solid down to the
    // layer's far end, so a ray passing behind a thin object in the same layer stops on it.
    // 0.5 px: with the cones of missed rays, thinner was closer to accum than 1 or 2 px at
    // N = 8-64 on six of the eight built-in scenes, about equal on railing and dense
    // (docs/benchmarks.md, "Cones of missed rays and texel thickness").
    float thickness_px = 0.5f;
    bool culling = true; // §4.3 early layer culling with N-buffers (lossless)
    // With JitterMode::None and Traversal::Scan every pixel's ray k crosses the same cells
    // relative to the pixel, so each (sample, layer) path is walked once per frame instead of
    // once per pixel. The same bits either way; off is the per-pixel reference.
    bool precompute_paths = true;
    // Return the pinhole render when the lens cannot change the image (MultiviewStats::skipped);
    // false runs every stage anyway (for looking at them).
    bool skip_unblurred = true;
    bool cone = true; // §4.4 approximate cone tracing
    // With cone: a ray that crosses a layer without a hit also looks its cone up there. The
    // paper evaluates the cone only at an impact point, so rays that pass beside a small or thin
    // object never see it and the gaps between lens samples stay (false: the paper's rule).
    bool cone_misses = true;
    ConeCentre cone_centre = ConeCentre::Cell; // with cone and JitterMode::None
    JitterMode jitter = JitterMode::None;
    uint32_t seed = 0; // jitter key
    OffscreenPolicy offscreen = OffscreenPolicy::Clamp;
    // §4.3, "Handling Off-Screen Pixels": the paper's other remedy for rays that leave the
    // image, "a decomposition of the scene ... with a viewport that encompasses all lens rays".
    // The layers are rendered over the image and a band around it as wide as the largest
    // visible |C(d)| (rounded up: how far a ray from the lens rim moves), at most this many
    // pixels; the band has the image's f_px, so the focal plane is as sharp as without it. A ray
    // near the border then reads what the scene holds beside the image instead of the border
    // texels (Clamp) or nothing (Discard). 0: the layers cover the image alone (the paper's
    // choice); docs/multiview.md, "Off-screen rays".
    float guard_band_px = 64.0f;
    bool view_dependent = false; // §5: shade each hit from its own lens point (needs G-buffer)
    ConeShading cone_shading = ConeShading::Footprint; // with cone && (view_dependent || env)
    const EnvironmentMap* env_map = nullptr;           // §5 reflections (implies a G-buffer)
    // For JitterMode::Halton: 2N samples of the same pattern family and aperture as the main set.
    const LensSampleSet* sequence_2n = nullptr;
    uint32_t tile_size = 16; // output tile (the unit of parallel work and of tile culling)
    // Debugging: when debug_rays is set, the frame ends with probeMultiview of pixel
    // (debug_x, debug_y), whose rays are stored there (no effect on the image).
    uint32_t debug_x = 0, debug_y = 0;
    std::vector<MultiviewRayRecord>* debug_rays = nullptr;
};

struct MultiviewStats {
    // The pinhole render is the result: nothing is visible, or the lens cannot change the image
    // (as accum decides it: aperture 0, or every visible depth has |C(d)| < 0.5 px; this test is
    // not made with an environment map, whose reflections need the synthesis, or with
    // skip_unblurred off).
    bool skipped = false;
    std::string skip_reason;
    // Counts (deterministic).
    uint32_t layers = 0;               // M
    uint32_t layers_empty = 0;         // layers with no fragment (skipped entirely)
    float delta_px = 0.0f;             // spacing used
    uint32_t guard_band_px = 0;        // the band the layers were rendered with (guard_band_px)
    bool budget_limited = false;       // the spacing needed more than raster::kMaxLayers layers
    float d_near = 0.0f, d_far = 0.0f; // visible depth range (§4.1)
    float lambda = 0.0f;         // mean nearest-neighbour distance of the lens samples (§4.4)
    bool cones_on_cells = false; // the cones were centred on their samples' cells (ConeCentre)
    uint32_t nbuffer_levels = 0; // most levels any layer needed
    uint32_t mip_levels = 0;
    uint64_t rays = 0;               // lens rays (pixels x N), traced or in focus
    uint64_t pixels_in_focus = 0;    // pixels whose rays all see their own texel, not traced
    uint64_t rays_discarded = 0;     // left the image (OffscreenPolicy::Discard)
    uint64_t rays_background = 0;    // passed every layer without a hit
    uint64_t layer_steps = 0;        // (ray, layer) pairs visited
    uint64_t layer_tests = 0;        // ray-segment/height-field tests run
    uint64_t layer_culled_pixel = 0; // (pixel, layer) pairs skipped by the N-buffer query
    uint64_t layer_culled_tile = 0;  // (tile, layer) pairs skipped by one query for the tile
    uint64_t layer_culled_ray = 0;   // (ray, layer) pairs skipped by a query on the ray's path
    uint64_t cone_partial = 0;       // hits whose cone coverage v1 < 1 continued the traversal
    uint64_t cone_missed = 0;        // misses whose cone met coverage v1 > 0 (cone_misses)
    uint64_t texel_fetches = 0;      // height-field lookups
    uint64_t transparent_hits = 0;   // hits on a layer's transparent plane (BLEND surfaces)
    uint64_t path_cells = 0;         // cells of the paths walked once per frame (0: none)
    uint64_t layered_bytes = 0;      // memory of the layered target
    uint64_t scratch_bytes = 0;      // N-buffers + mipmaps
    // Times (not deterministic).
    double ms_pinhole = 0.0;       // pinhole render for the depth range
    double ms_decomposition = 0.0; // layered rendering (§4.2)
    double ms_nbuffer = 0.0;
    double ms_mipmaps = 0.0;
    double ms_tracing = 0.0;
};

namespace multiview_detail {
struct FrameState; // multiview_setup.h
} // namespace multiview_detail

// Reusable scratch: per-layer float depths, N-buffers and coverage mipmaps, and the rest of a
// frame's buffers. Kept from frame to frame, every buffer is resized in place, so a second frame
// of the same size, samples and settings allocates nothing (the bytes are those of a fresh one).
struct MultiviewScratch {
    MultiviewScratch();
    ~MultiviewScratch();
    MultiviewScratch(MultiviewScratch&&) noexcept;
    MultiviewScratch& operator=(MultiviewScratch&&) noexcept;

    std::vector<std::vector<float>> depth; // per layer, stored D; kEmptyDepth where empty
    std::vector<NBuffer> nbuffers;         // per layer (empty when the layer is empty or culling
                                           // is off)
    // per layer, per level: premultiplied RGBA (alpha = coverage), level sizes halve. A level
    // stores only its rows from mip_row0[layer][level] on, as many as its size holds: the rows
    // that can differ from 0 (those of the layer's drawn texels, and the rows of coarser levels
    // they reach). Every other texel is 0, and the lookups read it so.
    std::vector<std::vector<std::vector<float>>> mips;
    std::vector<uint32_t> mip_width, mip_height; // per level (level 0 = image)
    std::vector<std::vector<uint32_t>> mip_row0; // per layer, per level: mips and owned_mips
    // per layer, per level: (D a, a, r a, g a, b a) over the texels the layer owns (a = 1 where
    // its depth lies in the layer's own interval, else 0), for the cones of missed rays
    // (MultiviewSettings::cone_misses; empty otherwise)
    std::vector<std::vector<std::vector<float>>> owned_mips;
    // per layer with missed cones: 1 where the 2x2 block of owned_mips texels from (u, v) has no
    // coverage, one byte per block, row-major, at the level the layer's first missed-cone lookup
    // reads last (missCone); a lookup inside the level reads blocks u < width - 1,
    // v < height - 1, the last row and column stay 0; empty otherwise
    std::vector<std::vector<uint8_t>> owned_empty_blocks;
    // The same for the layers' transparent planes (empty when the scene has no BLEND surface):
    // stored D of the nearest BLEND fragment (kEmptyDepth where none) and premultiplied mipmaps.
    std::vector<std::vector<float>> transparent_depth;
    std::vector<std::vector<std::vector<float>>> transparent_mips;
    std::vector<std::vector<uint32_t>> transparent_mip_row0; // as mip_row0
    // The rest, private to the method: the layer spacing and description, the tracer's segments,
    // paths and mip views, the tiles' ray states and counters, and the lens cells (lambda and cone
    // centres) of the last sample set, computed again only when the set changes. Made by the
    // first frame.
    std::unique_ptr<multiview_detail::FrameState> frame;
};

// The layered target's description for a depth range (§4.1 spacing + §4.2 options).
raster::Result<raster::LayeredTargetDesc> multiviewLayerDesc(const ThinLens& lens,
                                                             const DepthRange& range,
                                                             const MultiviewSettings& settings,
                                                             LayerSpacing* spacing_out = nullptr);

// Mean distance from each sample to its nearest neighbour in lens units: the lambda of §4.4.
// Allocates a search grid (std::bad_alloc when that fails; renderMultiview turns it into a
// Status).
float meanNeighbourDistance(const LensSampleSet& samples);

// For each lens sample, the centroid of its Voronoi cell within the aperture minus the sample,
// in lens units (ConeCentre::Cell). The cell is measured on a Hammersley set (seed 0) on the
// same aperture, `fine_per_sample` points per sample and at most 65536 in all: each point goes
// to its nearest sample (ties: the lower index) and the centroid is the weighted mean of a
// sample's points (a sample without points keeps offset 0). Empty when that leaves fewer than
// 16 points a sample (more than 4096 samples by default): the cells are not measured, and the
// cones stay on the rays. Allocates the returned offsets and the measuring set: std::bad_alloc
// when that fails, never an empty result (renderMultiview turns it into a Status).
std::vector<glm::vec2> lensCellOffsets(const LensSampleSet& samples, uint32_t fine_per_sample = 64);

// The view-dependent shading context (§5): the scene whose lights shade each hit with the
// rasterizer's model (raster::SurfaceShader), plus MultiviewSettings::env_map reflections.
struct ShadingInputs {
    const raster::Scene* scene = nullptr;
    // The SIMD switch of the tracing (`--no-simd` turns it off): the tracer's AVX2 build and the
    // lighting kernel of the per-ray shading, or the baseline build and the scalar reference.
    bool simd = true;
};

// §4.3-§5 on given layers: traces every pixel's lens rays and writes linear RGBA into `rgba`
// (resized to width*height*4, alpha 1). `pinhole` (the view's size) supplies the colour of pixels
// whose rays were all discarded; `background` is what rays that miss every layer see. `layers`
// cover the view's image, or the image and a guard band of G pixels on every side (rendered
// through guardedView(view, G): G is half the difference of their widths, and of their heights).
// Fails on invalid settings (messages name the options) or mismatched sizes.
raster::Result<MultiviewStats>
synthesizeMultiview(const raster::View& view, const ThinLens& lens, const LensSampleSet& samples,
                    const raster::Frame& pinhole, const raster::LayeredTarget& layers,
                    const LayerSpacing& spacing, const MultiviewSettings& settings,
                    const ShadingInputs& shading, glm::vec3 background, raster::TaskPool& pool,
                    MultiviewScratch& scratch, std::vector<float>& rgba);

// The probe of pixel (x, y) of the last frame synthesized with `scratch` (§4.3-§4.5): its
// lens rays traced again with the tracer's own functions (the baseline build, which gives the
// AVX2 build's bytes) and a recorder, on the per-frame constants, N-buffers and mipmaps kept in
// `scratch`. The other arguments must be those of that frame, unchanged since (the
// MultiviewSettings as the frame read them, with seed and sequence_2n). Writes `out` (its
// vectors allocated here); the scratch is only read. Fails when the pixel lies outside the
// image, when `scratch` holds no frame, or when the arguments do not match it.
raster::Status probeMultiview(const raster::View& view, const ThinLens& lens,
                              const LensSampleSet& samples, const raster::Frame& pinhole,
                              const raster::LayeredTarget& layers,
                              const MultiviewSettings& settings, const ShadingInputs& shading,
                              const MultiviewScratch& scratch, uint32_t x, uint32_t y,
                              MultiviewPixelProbe& out);

// The view of the image and a band of `guard` pixels on every side (MultiviewSettings::
// guard_band_px): the same eye, axes and f_px, the image grown by 2 * guard in width and height
// around the same centre, so its pixel (x + guard, y + guard) is the view's pixel (x, y).
raster::View guardedView(const raster::View& view, uint32_t guard);

// Renders the pinhole view into the frame. With `depth_only` only the frame's depth buffers are
// read (raster::RenderOptions::depth_only may serve): renderMultiview asks for the colour too
// only when the pinhole image is, or may be, part of its output.
using PinholeFn =
    std::function<raster::Status(const raster::View&, raster::Frame&, bool depth_only)>;
using LayersFn = std::function<raster::Status(const raster::View&, const raster::LayeredTargetDesc&,
                                              raster::LayeredTarget&)>;

// The whole method: pinhole render (visible depth range, §4.1), layered render (§4.2, through
// guardedView with the settings' guard band), then synthesizeMultiview. When the lens cannot change
// the image (MultiviewStats::skipped) the output is the pinhole frame. The pinhole is rendered for
// its depth only when no pixel can take its colour (OffscreenPolicy::Clamp and every lens sample of
// positive weight), so `pinhole_out`'s colour is then not the pinhole image. `rgba` as above.
// `pinhole_out`, `layers_out` and `scratch` (optional) are the caller's: kept from one frame to the
// next, their buffers are resized in place rather than allocated again (the same bytes as fresh
// ones).
raster::Result<MultiviewStats>
renderMultiview(const raster::View& view, const ThinLens& lens, const LensSampleSet& samples,
                const MultiviewSettings& settings, const ShadingInputs& shading,
                glm::vec3 background, const PinholeFn& render_pinhole,
                const LayersFn& render_layers, raster::TaskPool& pool, std::vector<float>& rgba,
                raster::Frame* pinhole_out = nullptr, raster::LayeredTarget* layers_out = nullptr,
                MultiviewScratch* scratch = nullptr);

// The parameters of MultiviewSettings a caller chooses (settings_table.h), in the order --help
// lists them. Not in it, because the caller or dof::FrameRenderer sets them: the storage formats,
// seed, sequence_2n, env_map, tile_size and the debug fields.
std::span<const Param<MultiviewSettings>> multiviewParams();

// Validates settings alone: every parameter of the table in its range, then the checks between
// them (messages "multiview settings: NAME ...", naming the fields).
raster::Status validate(const MultiviewSettings& settings, uint32_t sample_count);

// A lower bound of the bytes renderMultiview holds for a width x height image with
// `sample_count` lens samples on `workers` workers, from the settings alone (layers = 0 counts
// one layer): the pinhole frame, the output, the layered target with its per-layer depth copy,
// and each worker's ray states for one tile. Checked against the memory budget before anything
// is rendered, so an absurd request fails in milliseconds; the layered target's real size is
// checked again by Renderer::renderLayers once the layer count is known.
uint64_t multiviewMinimumBytes(const MultiviewSettings& settings, uint32_t width, uint32_t height,
                               uint32_t sample_count, uint32_t workers);

} // namespace dof
