#include "out_of_memory.h"
#include "pinhole_view.h"

#include <dof/frame_renderer.h>
#include <raster/fragment_lists.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <new>
#include <string>
#include <type_traits>

namespace dof {

using raster::Status;

namespace {

// What the render callbacks of accum and multiview read to reuse the kept pinhole frame; they
// capture `this` and a pointer to it, which std::function stores without allocating.
struct PinholeCall {
    const raster::Scene& scene;
    const raster::RenderOptions& options;
    FrameReport& report;
    bool kept;
    mutable bool depth_rendered = false; // multiview's depth-only pinhole was rendered
    mutable bool rendered = false;       // accum: a view was rendered in this call
};

double msSince(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

using detail::pinholeView;

bool isPinholeView(const raster::View& v) {
    return v.lens_offset == glm::vec2(0.0f) && v.pixel_shift == glm::vec2(0.0f) &&
           std::isfinite(v.focus_distance) && v.focus_distance > 0.0f;
}

// Two pinhole views with the same pixels: every field but the focus distance, which moves
// pixels only through lens_offset / focus_distance (raster::projectionMatrix), zero here.
bool samePinholeView(const raster::View& a, const raster::View& b) {
    return isPinholeView(a) && isPinholeView(b) && a.eye == b.eye && a.forward == b.forward &&
           a.right == b.right && a.up == b.up && a.yfov == b.yfov && a.width == b.width &&
           a.height == b.height && a.znear == b.znear && a.zfar == b.zfar;
}

bool sameOptions(const raster::RenderOptions& a, const raster::RenderOptions& b) {
    return a.tile_size == b.tile_size && a.depth_format == b.depth_format &&
           a.shading == b.shading && a.texture_filter == b.texture_filter && a.simd == b.simd &&
           a.peel_depth == nullptr && b.peel_depth == nullptr &&
           a.memory_budget.bytes == b.memory_budget.bytes;
}

void addStats(raster::FrameStats& sum, const raster::FrameStats& one) {
    sum.triangles_in += one.triangles_in;
    sum.triangles_culled += one.triangles_culled;
    sum.triangles_clipped += one.triangles_clipped;
    sum.triangles_setup += one.triangles_setup;
    sum.fragments_covered += one.fragments_covered;
    sum.fragments_passed += one.fragments_passed;
    sum.ms_geometry += one.ms_geometry;
    sum.ms_binning += one.ms_binning;
    sum.ms_raster += one.ms_raster;
    sum.ms_resolve += one.ms_resolve;
    sum.target_bytes = std::max(sum.target_bytes, one.target_bytes);
}

// Copies width x height RGBA pixels (rows of width*4 floats) into the caller's rows, a row per
// task: a copy by one thread would be serial time in every frame.
void copyRows(raster::TaskPool& pool, const float* src, uint32_t width, uint32_t height,
              const FrameImage& image) {
    const size_t row = size_t(width) * 4;
    pool.parallelFor(height, [&](uint32_t y, uint32_t) {
        std::memcpy(image.rgba + size_t(y) * image.stride, src + size_t(y) * row,
                    row * sizeof(float));
    });
}

// The distance along the view axis of each stored depth D (+inf where D >= kFarDepth when
// `empty_is_infinite`), into the caller's depth rows, a row per task.
void writeDepth(raster::TaskPool& pool, const raster::View& view, const raster::DepthBuffer& depth,
                bool empty_is_infinite, const FrameImage& image) {
    pool.parallelFor(view.height, [&](uint32_t y, uint32_t) {
        float* row = image.depth + size_t(y) * image.depth_stride;
        for (uint32_t x = 0; x < view.width; ++x) {
            const float d = depth.load(size_t(y) * view.width + x);
            row[x] = empty_is_infinite && !(d < raster::kFarDepth)
                         ? INFINITY
                         : raster::distanceFromDepth(view, d);
        }
    });
}

} // namespace

const char* methodName(const MethodSettings& method) {
    constexpr const char* kNames[] = {"pinhole", "accum", "gather", "multiview", "multilayer"};
    static_assert(std::size(kNames) == std::variant_size_v<MethodSettings>);
    return kNames[method.index()];
}

double apertureSecondMoment(const LensSampleSet& samples) {
    if (samples.size() < 64)
        return 0.25;
    double m = 0.0, w = 0.0;
    for (const LensSample& s : samples.samples()) {
        m += double(s.weight) * 0.5 *
             (double(s.position.x) * double(s.position.x) +
              double(s.position.y) * double(s.position.y));
        w += double(s.weight);
    }
    return w > 0.0 && m > 0.0 ? m / w : 0.25;
}

FrameRenderer::FrameRenderer(raster::TaskPool& pool)
    : pool_(pool), renderer_(std::make_unique<raster::Renderer>(pool)) {}

FrameRenderer::~FrameRenderer() = default;

bool FrameRenderer::pinholeMatches(const raster::Scene& scene, const raster::View& view,
                                   const raster::RenderOptions& options) const {
    return pinhole_key_ && pinhole_key_->scene == &scene &&
           samePinholeView(pinhole_key_->view, view) && sameOptions(pinhole_key_->options, options);
}

raster::Status FrameRenderer::renderPinhole(const raster::Scene& scene, const raster::View& view,
                                            const raster::RenderOptions& options,
                                            raster::Frame& out, FrameReport& report) {
    if (&out == &pinhole_)
        pinhole_key_.reset(); // overwritten: holds nothing until the render succeeds
    raster::FrameStats one;
    Status s = renderer_->render(scene, view, options, out, &one);
    addStats(report.render_sum, one);
    report.last_render = one;
    ++report.renders;
    if (s.ok() && &out == &pinhole_ && isPinholeView(view) && !options.depth_only)
        pinhole_key_ = PinholeKey{&scene, view, options};
    return s;
}

raster::Result<const raster::Frame*> FrameRenderer::pinhole(const raster::Scene& scene,
                                                            const raster::View& view,
                                                            const raster::RenderOptions& options,
                                                            raster::FrameStats* stats) try {
    pinhole_kept_ = false;
    FrameReport report;
    if (Status s = renderPinhole(scene, pinholeView(view), options, pinhole_, report); !s.ok())
        return s;
    if (stats)
        *stats = report.last_render;
    pinhole_kept_ = true;
    return &pinhole_;
} catch (const std::bad_alloc&) {
    pinhole_key_.reset();
    return detail::outOfMemory("rendering the pinhole frame");
}

raster::Result<ResolvedLens> FrameRenderer::resolveLens(const LensRequest& request,
                                                        const raster::Scene& scene,
                                                        const raster::View& view,
                                                        const raster::RenderOptions& options,
                                                        raster::FrameStats* stats) try {
    // The callback captures two pointers, which std::function stores without allocating.
    const struct {
        const raster::Scene& scene;
        const raster::RenderOptions& options;
        raster::FrameStats* stats;
    } call{scene, options, stats};
    return dof::resolveLens(request, scene, view, [this, &call](const raster::View& v) {
        return pinhole(call.scene, v, call.options, call.stats);
    });
} catch (const std::bad_alloc&) {
    pinhole_key_.reset();
    pinhole_kept_ = false;
    return detail::outOfMemory("resolving the lens");
}

const raster::Frame* FrameRenderer::lastPinhole(const raster::Scene& scene,
                                                const raster::View& view,
                                                const raster::RenderOptions& options) const {
    return pinholeMatches(scene, pinholeView(view), options) ? &pinhole_ : nullptr;
}

raster::Status FrameRenderer::render(const raster::Scene& scene, const raster::View& view,
                                     const ThinLens& lens, const raster::RenderOptions& options,
                                     const MethodSettings& method, const FrameImage& image,
                                     FrameReport* report_out, FrameObserver* observer) {
    Status s;
    try {
        s = renderFrame(scene, view, lens, options, method, image, report_out, observer);
    } catch (const std::bad_alloc&) {
        s = detail::outOfMemoryWhile([&] {
            return std::string("rendering ") + methodName(method) + " at " +
                   std::to_string(view.width) + "x" + std::to_string(view.height);
        });
    }
    // Out of memory (thrown here or turned into a Status on the way): the method's kept buffers
    // may be half resized; give them back, as the memory is wanted elsewhere, and the next frame
    // starts as a first one does.
    if (detail::isOutOfMemory(s))
        releaseAfterFailure(method);
    return s;
}

void FrameRenderer::releaseAfterFailure(const MethodSettings& method) noexcept {
    // Moves of empty buffers, which allocate nothing.
    pinhole_key_.reset();
    pinhole_kept_ = false;
    pinhole_ = raster::Frame{};
    if (std::holds_alternative<AccumMethod>(method)) {
        accum_ = raster::Frame{};
        accum_scratch_ = AccumScratch{};
    } else if (std::holds_alternative<GatherMethod>(method)) {
        rgba_ = std::vector<float>{};
        gather_scratch_ = GatherScratch{};
    } else if (std::holds_alternative<MultiviewMethod>(method)) {
        rgba_ = std::vector<float>{};
        layers_ = raster::LayeredTarget{};
        multiview_scratch_ = MultiviewScratch{};
        sequence_2n_.reset();
    } else if (std::holds_alternative<MultilayerMethod>(method)) {
        multilayer_ = Multilayer{};
        multilayer_image_ = MultilayerImage{};
    }
    report_ = FrameReport{};
}

raster::Status FrameRenderer::renderFrame(const raster::Scene& scene, const raster::View& view,
                                          const ThinLens& lens,
                                          const raster::RenderOptions& options,
                                          const MethodSettings& method, const FrameImage& image,
                                          FrameReport* report_out, FrameObserver* observer) {
    // The pinhole made by pinhole() serves this frame only.
    const bool kept = pinhole_kept_;
    pinhole_kept_ = false;
    // Without a caller's report, the kept one (its stage list and statistics keep their memory).
    FrameReport& report = report_out ? *report_out : report_;
    // Cleared field by field: a caller's report keeps its capacity from frame to frame.
    report.stage_ms.clear();
    report.render_sum = {};
    report.last_render = {};
    report.renders = 0;
    report.pinhole_reused = false;
    report.collect = {};
    if (std::holds_alternative<PinholeMethod>(method))
        report.method_stats = std::monostate{};

    // Check everything before the first render.
    const char* name = methodName(method);
    if (!image.rgba)
        return Status::error(std::string(name) + ": the image has no colour buffer "
                                                 "(FrameImage::rgba is null)");
    if (image.stride < size_t(view.width) * 4)
        return Status::error(
            std::string(name) + ": the colour row stride " + std::to_string(image.stride) +
            " is below width*4 = " + std::to_string(size_t(view.width) * 4) + " floats");
    if (image.depth && image.depth_stride < view.width)
        return Status::error(std::string(name) + ": the depth row stride " +
                             std::to_string(image.depth_stride) +
                             " is below width = " + std::to_string(view.width) + " floats");
    if (Status s = raster::validate(view); !s.ok())
        return s;
    if (Status s = raster::validate(options); !s.ok())
        return s;
    if (!std::holds_alternative<PinholeMethod>(method))
        if (Status s = validate(lens, view); !s.ok())
            return s;
    if (observer)
        for (const glm::uvec2& p : observer->probePixels())
            if (p.x >= view.width || p.y >= view.height)
                return Status::error(std::string(name) + ": probe pixel " + std::to_string(p.x) +
                                     "," + std::to_string(p.y) + " is outside the " +
                                     std::to_string(view.width) + "x" +
                                     std::to_string(view.height) + " image");
    // After the method, the observer's stages and probes (frame_stages.cpp).
    const auto observed = [&](Status s) -> Status {
        if (!s.ok() || !observer)
            return s;
        return observeFrame(scene, view, lens, options, method, report, image, *observer);
    };
    const raster::View pin = pinholeView(view);
    // Renders the pinhole into pinhole_ unless the kept one is this frame's.
    auto sharedPinhole = [&]() -> Status {
        if (kept && pinholeMatches(scene, pin, options)) {
            report.pinhole_reused = true;
            return {};
        }
        return renderPinhole(scene, pin, options, pinhole_, report);
    };

    if (std::holds_alternative<PinholeMethod>(method)) {
        if (Status s = sharedPinhole(); !s.ok())
            return s;
        copyRows(pool_, pinhole_.color.data(), view.width, view.height, image);
        if (image.depth)
            writeDepth(pool_, view, pinhole_.depth, false, image);
        return observed({});
    }

    if (const AccumMethod* m = std::get_if<AccumMethod>(&method)) {
        if (!m->samples)
            return Status::error("accum: needs lens samples (AccumMethod::samples is null)");
        // The first render is the pinhole (lens centre) into the output frame: the kept one is
        // copied there instead.
        // The callback captures two pointers, which std::function stores without allocating.
        const PinholeCall call{scene, options, report, kept};
        const RenderFn render_view = [this, &call](const raster::View& v,
                                                   raster::Frame& f) -> Status {
            if (&f == &accum_ && call.kept && pinholeMatches(call.scene, v, call.options)) {
                call.report.pinhole_reused = true;
                accum_.width = pinhole_.width;
                accum_.height = pinhole_.height;
                accum_.color = pinhole_.color;
                accum_.depth = pinhole_.depth;
                accum_.transparent_depth = pinhole_.transparent_depth;
                return {};
            }
            // The views after the first are of the same scene, unchanged within this call: the
            // renderer keeps its world-space vertices (raster::Renderer::promiseSceneUnchanged).
            if (call.rendered)
                renderer_->promiseSceneUnchanged();
            call.rendered = true;
            return renderPinhole(call.scene, v, call.options, f, call.report);
        };
        AccumSettings settings = m->settings;
        if (observer) { // each view's sample at the observer's pixels
            settings.probe_pixels = observer->probePixels();
            settings.probes = &observedAccumProbes();
        }
        raster::Result<AccumStats> r =
            renderAccum(view, lens, *m->samples, settings, render_view, accum_, &pool_,
                        observer ? observeAccum(*m) : m->progress, &accum_scratch_);
        if (!r.ok())
            return r.status();
        copyRows(pool_, accum_.color.data(), view.width, view.height, image);
        if (image.depth)
            writeDepth(pool_, view, accum_.depth, false, image);
        report.stage_ms = {
            {"pinhole", r->ms_pinhole}, {"views", r->ms_views}, {"accumulate", r->ms_accumulate}};
        report.method_stats = *r;
        return observed({});
    }

    if (const GatherMethod* m = std::get_if<GatherMethod>(&method)) {
        // Kept: a probe of the frame gathers with the same settings (frame_stages.cpp).
        GatherSettings& settings = gather_settings_;
        settings = m->settings;
        settings.tile_size = options.tile_size;
        settings.simd = options.simd;
        if (Status s = validate(settings); !s.ok())
            return s;
        // The pinhole frame through the lens centre (§5: the application renders as before).
        const auto t0 = std::chrono::steady_clock::now();
        if (Status s = sharedPinhole(); !s.ok())
            return s;
        const double ms_render = msSince(t0);
        const GatherImage in = gatherImageOf(pinhole_);
        std::vector<float>* coc_out =
            m->coc_out || !observer ? m->coc_out : &observedCoc(); // the stages show it
        raster::Result<GatherStats> r =
            gather(in, lens, pin, settings, rgba_, coc_out, &pool_, &gather_scratch_);
        if (!r.ok())
            return r.status();
        copyRows(pool_, rgba_.data(), view.width, view.height, image);
        if (image.depth)
            writeDepth(pool_, pin, pinhole_.depth, false, image);
        report.stage_ms = {{"render", ms_render},
                           {"coc", r->ms_coc},
                           {"vertical", r->ms_vertical},
                           {"horizontal", r->ms_horizontal}};
        report.method_stats = *r;
        return observed({});
    }

    if (const MultiviewMethod* m = std::get_if<MultiviewMethod>(&method)) {
        if (!m->samples)
            return Status::error("multiview: needs lens samples (MultiviewMethod::samples is "
                                 "null)");
        // Kept: a probe of the frame re-traces with the same settings (frame_stages.cpp).
        MultiviewSettings& settings = multiview_settings_;
        settings = m->settings;
        settings.seed = m->samples->seed();
        settings.sequence_2n = nullptr;
        if (settings.jitter == JitterMode::Halton) {
            // §4.5's 2N-sample sequence: a Halton sequence on the same aperture, kept while the
            // aperture, count and seed stay the same (it is a pure function of them).
            const LensSampleSet& main = *m->samples;
            if (!sequence_2n_ || sequence_2n_->size() != 2 * main.size() ||
                sequence_2n_->seed() != main.seed() ||
                !sameAperture(sequence_2n_->shape(), main.shape())) {
                sequence_2n_.reset();
                raster::Result<LensSampleSet> seq = LensSampleSet::create(
                    main.shape(), LensPattern::Halton, 2 * main.size(), main.seed());
                if (!seq.ok())
                    return seq.status();
                sequence_2n_ = std::move(*seq);
            }
            settings.sequence_2n = &*sequence_2n_;
        }
        ShadingInputs shading;
        shading.scene = &scene;
        shading.simd = options.simd;
        // The callbacks capture two pointers, which std::function stores without allocating.
        const PinholeCall call{scene, options, report, kept};
        const PinholeFn render_pinhole = [this, &call](const raster::View& v, raster::Frame& f,
                                                       bool depth_only) -> Status {
            if (&f == &pinhole_ && call.kept && pinholeMatches(call.scene, v, call.options)) {
                call.report.pinhole_reused = true;
                return {};
            }
            raster::RenderOptions o = call.options;
            o.depth_only = depth_only;
            // The colour after this frame's depth-only render of the same view (a skipped
            // frame): the same geometry and bins.
            if (!depth_only && call.depth_rendered)
                renderer_->promiseSceneUnchanged();
            const Status s = renderPinhole(call.scene, v, o, f, call.report);
            call.depth_rendered = s.ok() && depth_only;
            return s;
        };
        const LayersFn render_layers = [this, &call](const raster::View& v,
                                                     const raster::LayeredTargetDesc& d,
                                                     raster::LayeredTarget& t) {
            // The pinhole was rendered just before from the same eye (unless it was kept from
            // pinhole()): its geometry and bins serve the layers too.
            if (!call.report.pinhole_reused)
                renderer_->promiseSceneUnchanged();
            return renderer_->renderLayers(call.scene, v, call.options, d, t);
        };
        raster::Result<MultiviewStats> r = renderMultiview(
            view, lens, *m->samples, settings, shading, scene.background, render_pinhole,
            render_layers, pool_, rgba_, &pinhole_, &layers_, &multiview_scratch_);
        if (!r.ok())
            return r.status();
        copyRows(pool_, rgba_.data(), view.width, view.height, image);
        if (image.depth)
            writeDepth(pool_, view, pinhole_.depth, true, image);
        report.stage_ms = {{"pinhole", r->ms_pinhole},
                           {"decomposition", r->ms_decomposition},
                           {"nbuffer", r->ms_nbuffer},
                           {"mipmaps", r->ms_mipmaps},
                           {"tracing", r->ms_tracing}};
        report.method_stats = std::move(*r);
        return observed({});
    }

    const MultilayerMethod& m = std::get<MultilayerMethod>(method);
    // Copied into the kept settings, whose arrays (aperture grids, mask) keep their memory.
    MultilayerSettings& settings = multilayer_settings_;
    settings = m.settings;
    settings.memory_budget = options.memory_budget;
    settings.level_contributions = settings.level_contributions || observer; // Fig. 7's stage
    if (m.samples) {
        settings.aperture = m.samples->shape();
        settings.aperture_second_moment = apertureSecondMoment(*m.samples);
    }
    // The callback captures two pointers, which std::function stores without allocating.
    const struct {
        const raster::Scene& scene;
        const raster::View& view;
        const raster::RenderOptions& options;
        raster::FrameStats& stats;
    } call{scene, pin, options, report.collect};
    const CollectFn collect = [this, &call](const raster::FragmentListDesc& desc,
                                            raster::FragmentLists& lists) {
        return renderer_->renderFragmentLists(call.scene, call.view, call.options, desc, lists,
                                              &call.stats);
    };
    // The statistics go straight into the report's, whose arrays keep their memory.
    if (!std::holds_alternative<MultilayerStats>(report.method_stats))
        report.method_stats.emplace<MultilayerStats>();
    MultilayerStats& st = std::get<MultilayerStats>(report.method_stats);
    if (Status s = multilayer_.render(pin, lens, scene.background, settings, collect, pool_,
                                      multilayer_image_, &st);
        !s.ok())
        return s;
    copyRows(pool_, multilayer_image_.rgba.data(), view.width, view.height, image);
    if (image.depth)
        pool_.parallelFor(view.height, [&](uint32_t y, uint32_t) {
            std::memcpy(image.depth + size_t(y) * image.depth_stride,
                        multilayer_image_.depth.data() + size_t(y) * view.width,
                        size_t(view.width) * sizeof(float));
        });
    report.stage_ms = {
        {"collect", st.ms_collect}, {"filter", st.ms_filter}, {"accumulate", st.ms_accumulate}};
    return observed({});
}

} // namespace dof
