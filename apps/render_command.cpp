#include "apps/render_command.h"

#include "apps/dof_method.h"
#include "apps/image_io.h"
#include "apps/render_dumps.h"
#include "apps/render_request.h"
#include "apps/render_stats.h"
#include "apps/scene_source.h"
#include "apps/settings_options.h"

#include <dof/accum.h>
#include <dof/frame_renderer.h>
#include <dof/lens_resolution.h>
#include <dof/lens_samples.h>
#include <raster/camera.h>
#include <raster/depth_precision.h>
#include <raster/renderer.h>
#include <raster/task_pool.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <unistd.h>

namespace focal {

using raster::Result;
using raster::Status;

namespace {

// Library messages name settings fields; the user reads the options that set them.
int fail(const std::string& message) {
    std::fprintf(stderr, "focal: error: %s\n", withOptionNames(message).c_str());
    return 1;
}

// Progress bar on stderr, only when stderr is a terminal.
class ProgressBar {
public:
    explicit ProgressBar(bool enabled) : enabled_(enabled) {}
    void update(uint32_t done, uint32_t total) {
        if (!enabled_ || total == 0)
            return;
        const uint32_t permille = uint32_t(uint64_t(done) * 1000 / total);
        if (permille == last_ && done != total)
            return;
        last_ = permille;
        constexpr int kBar = 40;
        const int filled = int(uint64_t(done) * kBar / total);
        std::fprintf(stderr, "\rfocal: accum [%.*s%.*s] %u/%u views", filled,
                     "########################################", kBar - filled,
                     "........................................", done, total);
        if (done == total)
            std::fputc('\n', stderr);
        std::fflush(stderr);
    }

private:
    bool enabled_;
    uint32_t last_ = ~0u;
};

// No silent wrong image: warns, with the numbers, when a depth format cannot hold the distances
// the scene spans in front of the view (docs/targets.md, "Depth precision"). `targets`: the
// storage of the layered target / fragment lists when the user chose one.
void warnDepthPrecision(const raster::Scene& scene, const raster::View& view,
                        raster::DepthFormat frame_format,
                        std::optional<raster::DepthFormat> targets, bool table_method) {
    const raster::Bounds b = raster::worldBounds(scene);
    if (b.empty)
        return;
    float near_d = INFINITY, far_d = -INFINITY;
    for (int corner = 0; corner < 8; ++corner) {
        const glm::vec3 p((corner & 1) ? b.max.x : b.min.x, (corner & 2) ? b.max.y : b.min.y,
                          (corner & 4) ? b.max.z : b.min.z);
        const float d = glm::dot(p - view.eye, view.forward);
        near_d = std::min(near_d, d);
        far_d = std::max(far_d, d);
    }
    near_d = std::max(near_d, view.znear);
    if (view.zfar > 0.0f)
        far_d = std::min(far_d, view.zfar);
    auto warn = [&](raster::DepthFormat format, const char* target) {
        if (std::optional<std::string> problem =
                raster::depthPrecisionProblem(view, format, near_d, far_d, target))
            std::fprintf(stderr, "focal: warning: %s\n", problem->c_str());
    };
    warn(frame_format, "depth");
    if (table_method && targets && *targets != frame_format)
        warn(*targets, "target depth");
}

// "--method multiview at 16384x16384 with 65536 samples": the request, in messages.
std::string requestText(const RenderArgs& args, const raster::View& view) {
    std::string text = "--method " + args.method + " at " + std::to_string(view.width) + "x" +
                       std::to_string(view.height);
    if (args.method != "pinhole")
        text += " with " + std::to_string(args.samples) + " samples";
    return text;
}

// The memory a render request needs at least, before anything is rendered: the pinhole frame
// (autofocus and the lens centre), accum's second frame and its double-precision sum, and what a
// table method declares (MethodEntry::minimum_bytes).
uint64_t requestMinimumBytes(const RenderArgs& args, const raster::View& view,
                             const raster::RenderOptions& options, const MethodEntry* table_method,
                             uint32_t workers) {
    const uint32_t w = view.width, h = view.height;
    uint64_t bytes = raster::frameBytes(w, h, options.depth_format, false);
    if (args.method == "accum")
        bytes = raster::addBytes(
            bytes, raster::addBytes(raster::frameBytes(w, h, options.depth_format, false),
                                    raster::mulBytes(uint64_t{w} * h, 4 * sizeof(double))));
    if (table_method && table_method->minimum_bytes)
        bytes = raster::addBytes(bytes, table_method->minimum_bytes(view, args.samples, workers));
    return bytes;
}

// What every run of the command shares once the scene, view and lens are known.
struct RenderJob {
    const RenderArgs& args;
    const raster::Scene& scene;
    const raster::RenderOptions& options;
    const dof::ResolvedLens& lens;
    const MethodEntry* table_method; // null for pinhole and accum
    const MethodContext& context;
    dof::FrameRenderer& frames;
};

// What the --repeat runs produced besides the image.
struct RunsResult {
    RunTimes times;
    dof::AccumStats accum;
    MethodOutput method_out;   // the table's methods: the last run's
    raster::FrameStats counts; // the last Renderer::render call's, when a run made one
};

Result<dof::MethodSettings>
methodSettings(const RenderJob& job, const dof::LensSampleSet& lens_samples, ProgressBar& bar) {
    if (job.args.method == "accum") {
        dof::AccumMethod accum;
        accum.settings = job.args.accum;
        accum.samples = &lens_samples;
        accum.progress = [&bar](uint32_t done, uint32_t total) { bar.update(done, total); };
        return dof::MethodSettings(std::move(accum));
    }
    if (job.table_method)
        return job.table_method->settings(job.context);
    return dof::MethodSettings(dof::PinholeMethod{});
}

// Renders the frame --repeat times into `image` (`color` is its buffer, for the table methods'
// finish step), timing each run.
Status renderRuns(const RenderJob& job, const dof::LensSampleSet& lens_samples,
                  const dof::FrameImage& image, const std::vector<float>& color, RunsResult& out) {
    const RenderArgs& args = job.args;
    const bool is_accum = args.method == "accum";
    const bool show_progress =
        is_accum && !args.no_progress && args.samples > 1 && ::isatty(::fileno(stderr)) == 1;
    dof::FrameReport report;
    for (uint32_t run = 0; run < args.repeat; ++run) {
        const auto start = std::chrono::steady_clock::now();
        ProgressBar bar(show_progress);
        Result<dof::MethodSettings> method = methodSettings(job, lens_samples, bar);
        if (!method.ok())
            return method.status();
        if (Status s =
                job.frames.render(job.scene, job.lens.view, job.lens.lens, job.options, *method,
                                  image, &report, run + 1 == args.repeat ? args.observer : nullptr);
            !s.ok())
            return s;
        if (job.table_method) {
            out.method_out = MethodOutput{};
            if (Status s = job.table_method->finish(job.context, *method, job.frames, report, color,
                                                    out.method_out);
                !s.ok())
                return s;
        }
        const double total =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count();
        // Renderer stage times of pinhole and accum (the table methods report their own stages).
        raster::FrameStats run_sum;
        if (!job.table_method) {
            run_sum = report.render_sum;
            if (report.renders > 0)
                out.counts = report.last_render;
        }
        if (is_accum)
            out.accum = std::get<dof::AccumStats>(report.method_stats);
        out.times.add(total, run_sum, report);
    }
    return {};
}

// The scene, decoding only the textures this shading samples, in parallel on the render's pool;
// its import warnings printed.
Result<raster::Scene> loadRenderScene(const RenderArgs& args, const raster::RenderOptions& options,
                                      raster::TaskPool& pool, raster::ImportStats& load_stats) {
    raster::ImportOptions import_options;
    import_options.roles = raster::sampledTextureRoles(options.shading);
    import_options.pool = &pool;
    import_options.memory_budget = options.memory_budget;
    Result<raster::Scene> scene = loadScene(args.scene, import_options, &load_stats);
    if (scene.ok())
        for (const std::string& w : scene->warnings)
            std::fprintf(stderr, "focal: warning: %s\n", w.c_str());
    return scene;
}

void printDryRun(const RenderArgs& args, const dof::ResolvedLens& lens,
                 const raster::RenderOptions& options, uint64_t request_bytes) {
    std::printf("focal: dry run: %s, aperture radius %g, focus distance %g (%s), needs at "
                "least %s of a %s memory budget\n",
                requestText(args, lens.view).c_str(), double(lens.lens.aperture_radius),
                double(lens.lens.focus_distance), focusSourceName(lens.focus_source),
                raster::formatBytes(request_bytes).c_str(),
                options.memory_budget.limited()
                    ? raster::formatBytes(options.memory_budget.bytes).c_str()
                    : "unlimited");
}

// -o (every file) and --depth-out.
Status writeOutputs(const RenderArgs& args, const RenderedFrame& frame) {
    const ImageData color_out{frame.width, frame.height, 4, frame.color};
    for (const std::string& output : args.outputs)
        if (Status s = writeImage(output, color_out); !s.ok())
            return s;
    if (args.depth_out.empty())
        return {};
    // The method's depth (dof::FrameImage::depth): the pinhole's for pinhole, accum and gather.
    return writeImage(args.depth_out, ImageData{frame.width, frame.height, 1, frame.depth});
}

void printWrote(const RenderArgs& args, const RenderedFrame& frame) {
    std::printf("focal: wrote %s", args.outputs.front().c_str());
    for (size_t i = 1; i < args.outputs.size(); ++i)
        std::printf(", %s", args.outputs[i].c_str());
    if (!args.depth_out.empty())
        std::printf(" and %s", args.depth_out.c_str());
    if (args.method == "accum")
        std::printf(" (%ux%u, accum %u views, %.1f ms)\n", frame.width, frame.height,
                    frame.accum_views, frame.ms_median);
    else
        std::printf(" (%ux%u, %s, %.1f ms)\n", frame.width, frame.height, args.method.c_str(),
                    frame.ms_median);
}

// What a loaded scene depends on besides the file: the textures the shading samples and the
// memory budget they are loaded under.
std::string sceneKey(const RenderArgs& args) {
    return args.scene + "\n" + args.shading + "\n" + args.memory_budget;
}

} // namespace

Result<LoadedScene> loadSceneFor(const RenderArgs& args) {
    const raster::RenderOptions options = renderOptionsOf(args);
    raster::TaskPool pool(args.threads);
    LoadedScene loaded;
    loaded.key = sceneKey(args);
    Result<raster::Scene> scene = loadRenderScene(args, options, pool, loaded.load);
    if (!scene.ok())
        return scene.status();
    loaded.scene = std::move(*scene);
    return loaded;
}

Result<RenderedFrame> renderFrame(const RenderArgs& args, const LoadedScene* loaded) {
    if (Status s = checkRenderArgs(args); !s.ok())
        return s;
    const bool is_accum = args.method == "accum";
    const MethodEntry* table_method = findMethod(args.methods, args.method);
    if (args.method == "pinhole" && hasLensOptions(args))
        std::fprintf(stderr, "focal: warning: lens options have no effect with --method %s\n",
                     args.method.c_str());
    const dof::LensRequest request = lensRequestOf(args).value(); // checked above
    Result<dof::ApertureShape> aperture_shape = resolveAperture(args);
    if (!aperture_shape.ok())
        return aperture_shape.status();
    const raster::RenderOptions options = renderOptionsOf(args);
    raster::TaskPool pool(args.threads);
    LoadedScene own;
    if (!loaded || loaded->key != sceneKey(args)) {
        Result<raster::Scene> scene = loadRenderScene(args, options, pool, own.load);
        if (!scene.ok())
            return scene.status();
        own.scene = std::move(*scene);
        loaded = &own;
    }
    const raster::Scene& scene = loaded->scene;
    Result<raster::View> camera = resolveView(scene, args);
    if (!camera.ok())
        return camera.status();
    // A focal length implies the field of view (Blender, vertical sensor fit).
    const raster::View view = dof::photographicView(*camera, request);
    if (Status s = raster::validate(view); !s.ok())
        return s;
    const TargetStorage targets = targetStorageOf(args);
    warnDepthPrecision(scene, view, options.depth_format, targets.depth, table_method != nullptr);
    // Absurd requests fail here, in milliseconds, before any rendering.
    const uint64_t request_bytes =
        requestMinimumBytes(args, view, options, table_method, pool.workerCount());
    if (Status s =
            raster::checkMemory(options.memory_budget, requestText(args, view), request_bytes);
        !s.ok())
        return s;

    // Every frame of this command (autofocus, each --repeat run, the dumps) is rendered by one
    // FrameRenderer: it keeps the renderer, the methods' buffers and the pinhole frame. A dry run
    // renders nothing: autofocus falls back to the scene's bounds.
    dof::FrameRenderer frames(pool);
    RunsResult runs;
    Result<dof::ResolvedLens> lens =
        args.dry_run ? dof::resolveLens(request, scene, view, {})
                     : frames.resolveLens(request, scene, view, options, &runs.counts);
    if (!lens.ok())
        return lens.status();
    Result<dof::LensSampleSet> lens_samples =
        dof::LensSampleSet::create(*aperture_shape, lensPatternOf(args.lens_pattern),
                                   args.method != "pinhole" ? args.samples : 1, args.seed);
    if (!lens_samples.ok())
        return lens_samples.status();
    RenderedFrame out;
    out.width = view.width;
    out.height = view.height;
    if (args.dry_run) {
        printDryRun(args, *lens, options, request_bytes);
        return out;
    }

    // The image every run writes (linear RGBA) and the depth --depth-out asks for.
    const size_t pixels = size_t(view.width) * view.height;
    out.color.resize(pixels * 4);
    out.depth.resize(args.depth_out.empty() ? 0 : pixels);
    const dof::FrameImage image{out.color.data(), size_t(view.width) * 4,
                                out.depth.empty() ? nullptr : out.depth.data(), view.width};
    const MethodContext context{lens->view, *lens_samples, options, targets.color, targets.depth};
    const RenderJob job{args, scene, options, *lens, table_method, context, frames};
    if (Status s = renderRuns(job, *lens_samples, image, out.color, runs); !s.ok())
        return s;
    if (is_accum && runs.accum.skipped)
        std::fprintf(stderr, "focal: note: accum rendered once: %s\n",
                     runs.accum.skip_reason.c_str());
    Result<nlohmann::json> target_stats =
        dumpTargets(frames, scene, lens->view, options, args, targets);
    if (!target_stats.ok())
        return target_stats.status();
    out.ms_median = runs.times.medianTotal();
    out.accum_views = is_accum ? runs.accum.views : 0;
    const RenderRecord record{args,
                              lens->view,
                              request,
                              *lens,
                              *aperture_shape,
                              runs.times,
                              loaded->load,
                              runs.counts,
                              is_accum ? &runs.accum : nullptr,
                              table_method ? &runs.method_out : nullptr,
                              targets,
                              std::move(*target_stats)};
    out.stats = renderStatsJson(record);
    return out;
}

int runRender(const RenderArgs& args) {
    Result<RenderedFrame> frame = renderFrame(args);
    if (!frame.ok())
        return fail(frame.status().message());
    if (args.dry_run)
        return 0;
    if (Status s = writeOutputs(args, *frame); !s.ok())
        return fail(s.message());
    if (!args.stats_path.empty())
        if (Status s = writeRenderStats(args.stats_path, frame->stats); !s.ok())
            return fail(s.message());
    printWrote(args, *frame);
    return 0;
}

} // namespace focal
