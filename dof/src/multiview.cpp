// Multiview's frame driver (dof/multiview.h): validation, the pinhole and layered renders, the
// Tracer's lens constants, the setup stages (multiview_setup.h), the tiles traced in parallel
// (multiview_tracer.h), the stats and the memory estimate. Consumes the caller's view, lens,
// samples, settings and render callbacks; produces the caller's RGBA image and MultiviewStats;
// scratch is the caller's MultiviewScratch or a local one.
#include "multiview_setup.h"
#include "multiview_tracer.h"
#include "out_of_memory.h"

#include <dof/multiview.h>
#include <raster/surface_shading.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <new>
#include <optional>
#include <string>

namespace dof {

using raster::Status;
using namespace multiview_detail;

namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// The kept frame state of `scratch`, made by its first frame.
FrameState& frameState(MultiviewScratch& scratch) {
    if (!scratch.frame)
        scratch.frame = std::make_unique<FrameState>();
    return *scratch.frame;
}

// The layer spacing (§4.1) and the layered target's description (§4.2) into kept buffers.
Status layerDesc(const ThinLens& lens, const DepthRange& range, const MultiviewSettings& settings,
                 LayerSpacing& spacing, raster::LayeredTargetDesc& desc) {
    const Status st = settings.layers > 0
                          ? layerSpacingFromCount(lens, range, settings.layers, spacing)
                          : layerSpacingFromDelta(lens, range, settings.layer_spacing_px,
                                                  raster::kMaxLayers, spacing);
    if (!st.ok())
        return st;
    desc.bounds = spacing.bounds; // same size: copied in place
    desc.overlap = settings.overlap;
    desc.routing = settings.routing;
    desc.color_format = settings.color_format;
    desc.depth_format = settings.depth_format;
    desc.gbuffer = settings.view_dependent || settings.env_map != nullptr;
    return {};
}

// Points the tracer at the frame's inputs (what it reads but does not own).
void bindTracer(Tracer& tr, const raster::View& view, const ThinLens& lens,
                const LensSampleSet& samples, const raster::Frame& pinhole,
                const raster::LayeredTarget& layers, const MultiviewSettings& settings,
                const ShadingInputs& shading, const MultiviewScratch& scratch) {
    tr.view = &view;
    tr.lens = &lens;
    tr.samples = &samples;
    tr.layers = &layers;
    tr.settings = &settings;
    tr.shading = &shading;
    tr.scratch = &scratch;
    tr.pinhole = &pinhole;
}

Status outsideImage(uint32_t x, uint32_t y, uint32_t width, uint32_t height) {
    return Status::error("multiview probe: pixel (" + std::to_string(x) + ", " + std::to_string(y) +
                         ") lies outside the " + std::to_string(width) + "x" +
                         std::to_string(height) + " image");
}

} // namespace

MultiviewScratch::MultiviewScratch() = default;
MultiviewScratch::~MultiviewScratch() = default;
MultiviewScratch::MultiviewScratch(MultiviewScratch&&) noexcept = default;
MultiviewScratch& MultiviewScratch::operator=(MultiviewScratch&&) noexcept = default;

raster::Result<raster::LayeredTargetDesc> multiviewLayerDesc(const ThinLens& lens,
                                                             const DepthRange& range,
                                                             const MultiviewSettings& settings,
                                                             LayerSpacing* spacing_out) try {
    LayerSpacing spacing;
    raster::LayeredTargetDesc desc;
    if (Status st = layerDesc(lens, range, settings, spacing, desc); !st.ok())
        return st;
    if (spacing_out)
        *spacing_out = std::move(spacing);
    return desc;
} catch (const std::bad_alloc&) {
    return detail::outOfMemory("describing the multiview layers");
}

raster::Result<MultiviewStats>
synthesizeMultiview(const raster::View& view, const ThinLens& lens, const LensSampleSet& samples,
                    const raster::Frame& pinhole, const raster::LayeredTarget& layers,
                    const LayerSpacing& spacing, const MultiviewSettings& settings,
                    const ShadingInputs& shading, glm::vec3 background, raster::TaskPool& pool,
                    MultiviewScratch& scratch, std::vector<float>& rgba) try {
    if (Status st = validate(settings, samples.size()); !st.ok())
        return st;
    if (Status st = validate(lens, view); !st.ok())
        return st;
    const uint32_t width = view.width, height = view.height;
    if (pinhole.width != width || pinhole.height != height)
        return Status::error("multiview: the pinhole frame must match the view size");
    // The layers cover the image and a guard band of the same width on every side (guardedView).
    if (layers.width < width || layers.height < height ||
        layers.width - width != layers.height - height || (layers.width - width) % 2 != 0)
        return Status::error("multiview: the layers must match the view size, or exceed it by a "
                             "guard band as wide on every side");
    const uint32_t guard = (layers.width - width) / 2;
    if (layers.layer_count == 0 || layers.layer_count > raster::kMaxLayers)
        return Status::error("multiview: the layered target has no layers");
    const bool shade = settings.view_dependent || settings.env_map;
    const size_t layer_texels = layers.pixelCount() * layers.layer_count;
    if (shade &&
        (layers.gbuffer.size() != layer_texels || !shading.scene ||
         (layers.hasTransparency() && (layers.transparent_gbuffer.size() != layer_texels ||
                                       layers.transparent_top_alpha.size() != layer_texels))))
        return settingsError("multiview", "view_dependent needs layers rendered with a G-buffer");

    MultiviewStats stats;
    const uint32_t m = layers.layer_count;
    stats.layers = m;
    stats.delta_px = spacing.delta_px;
    stats.guard_band_px = guard;
    stats.budget_limited = spacing.budget_limited;
    stats.layered_bytes = layers.bytes();

    if (settings.debug_rays && (settings.debug_x >= width || settings.debug_y >= height))
        return outsideImage(settings.debug_x, settings.debug_y, width, height);
    FrameState& fs = frameState(scratch);
    fs.kept = FrameState::Kept::None;
    Tracer& tr = fs.tracer;
    tr.reset();
    bindTracer(tr, view, lens, samples, pinhole, layers, settings, shading, scratch);
    tr.width = layers.width;
    tr.height = layers.height;
    tr.guard = guard;
    tr.image_width = width;
    tr.image_height = height;
    tr.background = background;
    if (shade) {
        // Kept with the frame state: preparing it again reuses its memory.
        fs.shader.prepare(*shading.scene, view, shading.simd);
        tr.shader = &fs.shader;
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
    // lambda and the cells: measured again only when the sample set changes.
    const bool cone_cells = settings.cone && settings.cone_centre == ConeCentre::Cell &&
                            settings.jitter == JitterMode::None;
    updateLensCells(samples, cone_cells, fs.lens_cells);
    tr.lambda = fs.lens_cells.lambda;
    stats.lambda = tr.lambda;
    float r_max = 0.0f;
    for (const LensSample& ls : samples.samples())
        r_max = std::max(r_max, glm::length(ls.position));
    if (cone_cells) {
        const std::vector<glm::vec2>& cells = fs.lens_cells.offsets;
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
    // mipmaps; one task per layer, each writing only its own slots (multiview_setup.h).
    auto t0 = Clock::now();
    const size_t pixels = size_t(width) * height;
    const bool transparency = layers.hasTransparency();
    copyLayerDepths(layers, pool, scratch, fs.content);
    float reach_max = 0.0f;
    if (Status st = buildSegments(tr, fs.content, stats, reach_max); !st.ok())
        return st;
    stats.ms_decomposition = msSince(t0); // the copy belongs to the decomposition's cost

    t0 = Clock::now();
    buildNBuffers(tr, pool, scratch, fs.nearest, stats);
    stats.ms_nbuffer = msSince(t0);

    t0 = Clock::now();
    buildMipmaps(tr, fs.content, reach_max, pool, scratch, stats);
    buildFirstRays(tr);
    stats.ms_mipmaps = msSince(t0);
    for (uint32_t l = 0; l < m; ++l) {
        for (const std::vector<float>& lv : scratch.nbuffers[l].levels)
            stats.scratch_bytes += lv.size() * sizeof(float);
        for (const std::vector<float>& lv : scratch.mips[l])
            stats.scratch_bytes += lv.size() * sizeof(float);
        if (!scratch.owned_mips.empty()) {
            for (const std::vector<float>& lv : scratch.owned_mips[l])
                stats.scratch_bytes += lv.size() * sizeof(float);
            stats.scratch_bytes += scratch.owned_empty_blocks[l].size();
        }
        stats.scratch_bytes += scratch.depth[l].size() * sizeof(float);
        if (transparency) {
            for (const std::vector<float>& lv : scratch.transparent_mips[l])
                stats.scratch_bytes += lv.size() * sizeof(float);
            stats.scratch_bytes += scratch.transparent_depth[l].size() * sizeof(float);
        }
    }

    // §4.3: trace every pixel's lens rays, one task per output tile (the guard band's pixels
    // are read, not traced).
    t0 = Clock::now();
    if (settings.precompute_paths && settings.jitter == JitterMode::None &&
        settings.traversal == Traversal::Scan && walkPaths(tr, stats)) {
        // inFocusPixel repeats what traceLayer and endPixel do for a ray that hits its own
        // texel: lens-centre shading and no ray dropped at the image border.
        tr.in_focus = !shade && settings.offscreen == OffscreenPolicy::Clamp;
    }
    // Not cleared (a serial pass over the image): traceTile writes every pixel of every tile.
    rgba.resize(pixels * 4);
    const uint32_t ts = settings.tile_size;
    const uint32_t tiles_x = (width + ts - 1) / ts, tiles_y = (height + ts - 1) / ts;
    std::vector<TileCounters>& counters = fs.counters;
    counters.assign(size_t(tiles_x) * tiles_y, TileCounters{});
    // Per worker: the states of one tile's rays and pixels (as new ones: the same size and
    // settings reuse the kept buffers).
    std::vector<RayState>& ray_states = fs.ray_states;
    ray_states.assign(size_t(pool.workerCount()) * ts * ts * samples.size(), RayState{});
    std::vector<PixelLayers>& pixel_layers = fs.pixel_layers;
    pixel_layers.assign(size_t(pool.workerCount()) * ts * ts, PixelLayers{});
    const TraceTileFn trace_tile = traceTileFor(shading.simd);
    pool.parallelFor(tiles_x * tiles_y, [&](uint32_t tile, uint32_t worker) {
        // Counted on the stack, stored once: neighbouring tiles' counters share cache lines,
        // and the two workers usually trace neighbouring tiles.
        TileCounters cnt;
        const uint32_t x0 = guard + (tile % tiles_x) * ts, y0 = guard + (tile / tiles_x) * ts;
        const uint32_t x1 = std::min(x0 + ts, guard + width);
        const uint32_t y1 = std::min(y0 + ts, guard + height);
        std::array<uint32_t, raster::kMaxLayers> tile_layers{};
        const uint32_t count = tileLayers(tr, x0, x1, y0, y1, tile_layers.data(), cnt);
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
    fs.kept = FrameState::Kept::Traced;
    fs.sample_count = samples.size();
    if (settings.debug_rays) {
        MultiviewPixelProbe probe;
        probePixel(tr, settings.debug_x, settings.debug_y, probe);
        *settings.debug_rays = std::move(probe.rays);
    }
    return stats;
} catch (const std::bad_alloc&) {
    return detail::outOfMemory("synthesizing multiview");
}

raster::Result<MultiviewStats>
renderMultiview(const raster::View& view, const ThinLens& lens, const LensSampleSet& samples,
                const MultiviewSettings& settings, const ShadingInputs& shading,
                glm::vec3 background, const PinholeFn& render_pinhole,
                const LayersFn& render_layers, raster::TaskPool& pool, std::vector<float>& rgba,
                raster::Frame* pinhole_out, raster::LayeredTarget* layers_out,
                MultiviewScratch* scratch_io) try {
    if (Status st = validate(settings, samples.size()); !st.ok())
        return st;
    if (Status st = validate(lens, view); !st.ok())
        return st;
    raster::Frame local_pinhole;
    raster::Frame& pinhole = pinhole_out ? *pinhole_out : local_pinhole;
    // §4.1: the pinhole through the lens centre gives the visible depth range. Its colour is
    // needed only by a skipped frame (rendered again below) and by a pixel whose every ray is
    // discarded or whose weights sum to 0 (endPixel), which cannot happen when rays are clamped
    // to the image and every sample weighs more than 0.
    const bool positive = std::all_of(samples.samples().begin(), samples.samples().end(),
                                      [](const LensSample& s) { return s.weight > 0.0f; });
    const bool depth_only = settings.offscreen == OffscreenPolicy::Clamp && positive;
    auto t0 = Clock::now();
    if (Status st = render_pinhole(view, pinhole, depth_only); !st.ok())
        return st;
    double ms_pinhole = msSince(t0);
    const DepthRange range = visibleDepthRange(pinhole, view);
    // Nothing to blur: the pinhole render is the result (the same rule as accum's, so both
    // methods return the pinhole image for the same lenses). Rays offset by less than half a
    // pixel would read every pixel's own texel anyway.
    const bool skip_test = settings.skip_unblurred && !settings.env_map;
    CocRange coc;
    if (range.covered && (skip_test || settings.guard_band_px > 0.0f))
        coc = visibleCocRange(lens, pinhole, view);
    std::string skip_reason;
    if (!range.covered) {
        skip_reason = "nothing visible: the image is the background";
    } else if (skip_test) {
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
        if (depth_only) {
            t0 = Clock::now();
            if (Status st = render_pinhole(view, pinhole, false); !st.ok())
                return st;
            ms_pinhole += msSince(t0);
        }
        rgba = pinhole.color;
        if (scratch_io)
            frameState(*scratch_io).kept = FrameState::Kept::Skipped;
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
    MultiviewScratch local_scratch;
    MultiviewScratch& scratch = scratch_io ? *scratch_io : local_scratch;
    FrameState& fs = frameState(scratch);
    if (Status st = layerDesc(lens, range, settings, fs.spacing, fs.desc); !st.ok())
        return st;
    raster::LayeredTarget local_layers;
    raster::LayeredTarget& layers = layers_out ? *layers_out : local_layers;
    // §4.3's viewport that encompasses the lens rays: a ray from the lens rim moves |C(d)| px.
    // A band the rasterizer cannot take (a side past its limit, a field of view near 180°) is
    // narrowed until it can.
    uint32_t guard = uint32_t(std::min(settings.guard_band_px, std::ceil(coc.max_abs_px)));
    while (guard > 0 && !raster::validate(guardedView(view, guard)).ok())
        guard /= 2;
    t0 = Clock::now();
    if (Status st = render_layers(guardedView(view, guard), fs.desc, layers); !st.ok())
        return st;
    const double ms_layers = msSince(t0);
    raster::Result<MultiviewStats> r =
        synthesizeMultiview(view, lens, samples, pinhole, layers, fs.spacing, settings, shading,
                            background, pool, scratch, rgba);
    if (!r.ok())
        return r;
    r->ms_pinhole = ms_pinhole;
    r->ms_decomposition += ms_layers;
    r->d_near = range.near_d;
    r->d_far = range.far_d;
    return r;
} catch (const std::bad_alloc&) {
    return detail::outOfMemory("rendering multiview");
}

raster::View guardedView(const raster::View& view, uint32_t guard) {
    raster::View v = view;
    v.width = view.width + 2 * guard;
    v.height = view.height + 2 * guard;
    // f_px = (H/2) / tan(yfov/2) kept: tan(yfov'/2) = tan(yfov/2) H' / H (in double, so that
    // f_px is kept to the float's last bits or so).
    v.yfov = float(2.0 * std::atan(std::tan(0.5 * double(view.yfov)) * double(v.height) /
                                   double(view.height)));
    return v;
}

Status probeMultiview(const raster::View& view, const ThinLens& lens, const LensSampleSet& samples,
                      const raster::Frame& pinhole, const raster::LayeredTarget& layers,
                      const MultiviewSettings& settings, const ShadingInputs& shading,
                      const MultiviewScratch& scratch, uint32_t x, uint32_t y,
                      MultiviewPixelProbe& out) try {
    const FrameState* fs = scratch.frame.get();
    if (!fs || fs->kept == FrameState::Kept::None)
        return Status::error("multiview probe: the scratch holds no frame (probe after a "
                             "renderMultiview or synthesizeMultiview call that used it)");
    if (x >= view.width || y >= view.height)
        return outsideImage(x, y, view.width, view.height);
    if (pinhole.width != view.width || pinhole.height != view.height)
        return Status::error("multiview probe: the pinhole frame must match the view size");
    if (fs->kept == FrameState::Kept::Skipped) {
        // renderMultiview returned the pinhole image.
        out = MultiviewPixelProbe{};
        out.x = x, out.y = y;
        out.skipped = true;
        std::copy_n(pinhole.color.data() + (size_t(y) * view.width + x) * 4, 4, out.rgba);
        return {};
    }
    const Tracer& kept = fs->tracer;
    if (view.width != kept.image_width || view.height != kept.image_height ||
        layers.width != kept.width || layers.height != kept.height ||
        layers.layer_count != kept.segs.size() || samples.size() != fs->sample_count)
        return Status::error("multiview probe: the view, layers or samples are not the frame's");
    if (Status st = validate(settings, samples.size()); !st.ok())
        return st;
    // The kept tracer read the frame's inputs, which the caller passes again here.
    Tracer tr = kept;
    bindTracer(tr, view, lens, samples, pinhole, layers, settings, shading, scratch);
    probePixel(tr, x, y, out);
    return {};
} catch (const std::bad_alloc&) {
    return detail::outOfMemory("probing a multiview pixel");
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
