// One depth-of-field frame in one call (issue 20 part 1). Consumes a scene, a view, a thin lens,
// raster options and a MethodSettings (pinhole, accum, gather, multiview or multilayer); produces
// linear RGBA (and optionally the method's depth) in an image the caller owns, plus a report of
// stage times and counts. A FrameRenderer owns the raster::Renderer over the caller's TaskPool,
// every method's buffers (targets, scratch, the method objects) and one pinhole frame shared by
// autofocus and every method; all of them are kept from frame to frame and resized in place.
//
// Determinism: the bytes written are those of the method functions called directly (accum.h,
// gather.h, multiview.h, multilayer.h) with the same derived settings, for any thread count, and
// do not depend on what this object rendered before.
#pragma once

#include <dof/accum.h>
#include <dof/frame_observer.h>
#include <dof/gather.h>
#include <dof/lens.h>
#include <dof/lens_resolution.h>
#include <dof/lens_samples.h>
#include <dof/multilayer.h>
#include <dof/multiview.h>
#include <raster/camera.h>
#include <raster/frame.h>
#include <raster/layered_target.h>
#include <raster/renderer.h>
#include <raster/scene.h>
#include <raster/status.h>
#include <raster/task_pool.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

namespace dof {

// The pinhole image through the lens centre (the view's lens_offset and pixel_shift are ignored).
struct PinholeMethod {};

// The accumulation reference (accum.h): one render per lens sample.
struct AccumMethod {
    AccumSettings settings;
    const LensSampleSet* samples = nullptr; // required; the caller's, read during the call
    ProgressFn progress;                    // optional
};

// Zhou et al. 2007 (gather.h) on the shared pinhole frame. `settings.tile_size` and
// `settings.simd` are taken from the RenderOptions (the frame's tile size and SIMD switch).
struct GatherMethod {
    GatherSettings settings;
    std::vector<float>* coc_out = nullptr; // optional: the signed CoC map, width*height pixels
};

// Lee et al. 2009 (multiview.h). Filled in from the lens samples: `settings.seed` (their seed)
// and, with JitterMode::Halton, `settings.sequence_2n` (a Halton set of 2N samples on the same
// aperture, §4.5). The per-ray shading (§5) reads the frame's scene with the options' SIMD switch.
struct MultiviewMethod {
    MultiviewSettings settings;
    const LensSampleSet* samples = nullptr; // required
};

// Selgrad et al. 2015 (multilayer.h). `settings.memory_budget` is taken from the RenderOptions;
// with lens samples, `settings.aperture` is their aperture and `settings.aperture_second_moment`
// their apertureSecondMoment; without, both are used as given.
struct MultilayerMethod {
    MultilayerSettings settings;
    const LensSampleSet* samples = nullptr; // optional
};

using MethodSettings =
    std::variant<PinholeMethod, AccumMethod, GatherMethod, MultiviewMethod, MultilayerMethod>;

// The method's name as the command line spells it: "pinhole", "accum", "gather", ...
const char* methodName(const MethodSettings& method);

// Per-axis second moment of the aperture in lens units² from the lens samples, when there are
// at least 64 of them to describe its shape; the uniform disk's 1/4 otherwise.
double apertureSecondMoment(const LensSampleSet& samples);

// The caller's image: view.width x view.height pixels, rows top first. Only the first
// width*4 floats of each colour row (width floats of each depth row) are written.
struct FrameImage {
    float* rgba = nullptr; // linear RGBA (alpha 1 except where a method says otherwise)
    size_t stride = 0;     // floats from one colour row to the next, >= width*4
    // Optional: per pixel the distance along the view axis of what the method saw (pinhole,
    // accum, gather: the pinhole depth; multiview: the pinhole depth, +inf where empty;
    // multilayer: the closest collected fragment, +inf for the background).
    float* depth = nullptr;
    size_t depth_stride = 0; // floats from one depth row to the next, >= width
};

// What one frame did. Times are not deterministic; counts are.
struct FrameReport {
    // The method's stages in order: pinhole (none); accum: pinhole, views, accumulate; gather:
    // render, coc, vertical, horizontal; multiview: pinhole, decomposition, nbuffer, mipmaps,
    // tracing; multilayer: collect, filter, accumulate.
    std::vector<std::pair<std::string, double>> stage_ms;
    // Renderer::render calls of this frame (the pinhole, accum's views): counts and times summed,
    // and the last call's alone. Layered and fragment-list renders are not in them.
    raster::FrameStats render_sum;
    raster::FrameStats last_render;
    uint32_t renders = 0;
    // The pinhole frame made by pinhole() before this call was used instead of a new render.
    bool pinhole_reused = false;
    // Multilayer: the fragment-list render (§4).
    raster::FrameStats collect;
    // The method's own statistics (monostate for pinhole; unspecified after a failure).
    std::variant<std::monostate, AccumStats, GatherStats, MultiviewStats, MultilayerStats>
        method_stats;
};

namespace detail {
struct FrameObservation; // frame_stages.cpp: what observing a frame keeps
struct FrameObservationDeleter {
    void operator()(FrameObservation* p) const;
};
} // namespace detail

class FrameRenderer {
public:
    // Renders with the caller's pool (which must outlive this object); threads == 0 runs inline.
    // Allocates the renderer and its (empty) state; every frame buffer waits for the first
    // frame. A constructor has no Status to return, so a failure there is std::bad_alloc, as
    // from any standard container.
    explicit FrameRenderer(raster::TaskPool& pool);
    ~FrameRenderer();
    FrameRenderer(const FrameRenderer&) = delete;
    FrameRenderer& operator=(const FrameRenderer&) = delete;

    // Renders one frame of `scene` through `view` and `lens` with `method` into `image`, and,
    // when `report` is given, fills it. The lens owns the focus distance: the view's copy does not
    // change the image (resolveLens returns a view whose copy agrees). Fails with a Status naming
    // the problem on a null image, a stride below the row size, an invalid view, lens or settings,
    // a missing sample set or a failed render (memory budget, textures); the image may then be
    // partly written. Running out of memory anywhere in the frame is a Status too ("out of
    // memory while ..."), never an exception: this object then releases the method's kept
    // buffers and the pinhole frame, and the next call renders as a first frame does. Not
    // reentrant: one call at a time per object (the work itself runs on the pool).
    // With an `observer` (frame_observer.h), the frame's stages and the observer's pixel probes
    // are reported to it after the frame, on this thread; the frame's bytes are the same as
    // without one. Probe pixels outside the image fail the call before anything is rendered.
    [[nodiscard]] raster::Status render(const raster::Scene& scene, const raster::View& view,
                                        const ThinLens& lens, const raster::RenderOptions& options,
                                        const MethodSettings& method, const FrameImage& image,
                                        FrameReport* report = nullptr,
                                        FrameObserver* observer = nullptr);

    // Renders the pinhole frame of `view` (lens centre) now, e.g. to choose the focus distance,
    // and keeps it for the next render() call (out of memory: a Status, as in render()): when that
    // call has the same scene, the same view (its focus distance aside, which does not move a
    // pinhole's pixels) and the same options, every method uses this frame instead of rendering it
    // again. render() then drops it, so the next frame renders the scene again. Valid until the
    // next call on this object.
    [[nodiscard]] raster::Result<const raster::Frame*> pinhole(const raster::Scene& scene,
                                                               const raster::View& view,
                                                               const raster::RenderOptions& options,
                                                               raster::FrameStats* stats = nullptr);

    // The lens of a frame (lens_resolution.h), focused with this object's pinhole frame: a focus
    // pixel or autofocus renders it with pinhole() (its counts in `stats`), and the next render()
    // through the returned view reuses it.
    [[nodiscard]] raster::Result<ResolvedLens>
    resolveLens(const LensRequest& request, const raster::Scene& scene, const raster::View& view,
                const raster::RenderOptions& options, raster::FrameStats* stats = nullptr);

    // The last pinhole frame rendered (by pinhole() or a method), when it was rendered for this
    // scene, view and options and the caller has not changed the scene since; else null.
    const raster::Frame* lastPinhole(const raster::Scene& scene, const raster::View& view,
                                     const raster::RenderOptions& options) const;

    // The renderer over the pool, for renders outside a frame (dumps, stepping).
    raster::Renderer& renderer() { return *renderer_; }
    raster::TaskPool& pool() { return pool_; }
    // The last frame's method data, for looking inside (debug pictures, level images).
    const raster::LayeredTarget& multiviewLayers() const { return layers_; }
    const Multilayer& multilayer() const { return multilayer_; }
    const MultilayerImage& multilayerImage() const { return multilayer_image_; }

private:
    struct PinholeKey {
        const raster::Scene* scene = nullptr;
        raster::View view;
        raster::RenderOptions options;
    };
    bool pinholeMatches(const raster::Scene& scene, const raster::View& view,
                        const raster::RenderOptions& options) const;
    raster::Status renderFrame(const raster::Scene& scene, const raster::View& view,
                               const ThinLens& lens, const raster::RenderOptions& options,
                               const MethodSettings& method, const FrameImage& image,
                               FrameReport* report, FrameObserver* observer);
    // Observing (frame_stages.cpp): the kept state, accum's progress hook that captures views
    // and running averages, and the stages and probes after the frame.
    detail::FrameObservation& observation();
    std::vector<float>& observedCoc(); // gather's signed CoC map, for its stage
    // accum's probes of the observer's pixels, filled by renderAccum
    std::vector<AccumPixelProbe>& observedAccumProbes();
    // The method's record of pixel (x, y) of the frame just rendered (PixelProbe::method).
    raster::Status probeMethod(const raster::Scene& scene, const raster::View& view,
                               const ThinLens& lens, const raster::RenderOptions& options,
                               const MethodSettings& method, size_t index, PixelProbe& probe);
    ProgressFn observeAccum(const AccumMethod& m);
    raster::Status observeFrame(const raster::Scene& scene, const raster::View& view,
                                const ThinLens& lens, const raster::RenderOptions& options,
                                const MethodSettings& method, const FrameReport& report,
                                const FrameImage& image, FrameObserver& observer);
    void multiviewStages(const raster::View& view, const ThinLens& lens, const MultiviewMethod& m,
                         const FrameReport& report, FrameObserver& observer);
    void multilayerStages(const raster::View& pin, const FrameReport& report,
                          FrameObserver& observer);
    // After running out of memory: drops the pinhole frame and `method`'s kept buffers.
    void releaseAfterFailure(const MethodSettings& method) noexcept;
    raster::Status renderPinhole(const raster::Scene& scene, const raster::View& view,
                                 const raster::RenderOptions& options, raster::Frame& out,
                                 FrameReport& report);

    raster::TaskPool& pool_;
    std::unique_ptr<raster::Renderer> renderer_;
    raster::Frame pinhole_;                 // shared by autofocus and every method
    std::optional<PinholeKey> pinhole_key_; // what pinhole_ holds, when it holds a pinhole
    bool pinhole_kept_ = false;             // made by pinhole() for the next render()
    raster::Frame accum_;                   // accum's output (colour average, pinhole depth)
    AccumScratch accum_scratch_;            // accum's sums and view frame
    std::vector<float> rgba_;               // gather's and multiview's output
    GatherScratch gather_scratch_;
    raster::LayeredTarget layers_; // multiview's layered target (§4.2)
    MultiviewScratch multiview_scratch_;
    std::optional<LensSampleSet> sequence_2n_; // multiview's §4.5 Halton set
    Multilayer multilayer_;
    MultilayerImage multilayer_image_;
    GatherSettings gather_settings_;         // the frame's, with tile size and simd (probes)
    MultiviewSettings multiview_settings_;   // the frame's, with seed and sequence_2n (probes)
    MultilayerSettings multilayer_settings_; // the frame's, with what the frame renderer fills in
    FrameReport report_;                     // the report of a render() call given none
    std::unique_ptr<detail::FrameObservation, detail::FrameObservationDeleter> observation_;
};

} // namespace dof
