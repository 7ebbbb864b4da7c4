#include "apps/bench_command.h"

#include "apps/bench_equal_error_report.h"
#include "apps/bench_plots.h"
#include "apps/bench_reference.h"
#include "apps/bench_render.h"
#include "apps/bench_results.h"
#include "apps/bench_scene.h"
#include "apps/bench_sweep.h"
#include "apps/bench_temporal.h"
#include "apps/dof_method.h"
#include "apps/report_text.h"

#include <scenes/builtin.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <thread>

namespace focal {

using raster::Result;
using raster::Status;
namespace fs = std::filesystem;

namespace {

int usage(const std::string& message) {
    std::fprintf(stderr, "focal: error: %s (see focal bench --help)\n", message.c_str());
    return 2;
}

int fail(const std::string& message) {
    std::fprintf(stderr, "focal: error: %s\n", message.c_str());
    return 1;
}

// --quick's smaller run, the method names checked and the default scene list; "" or a usage
// error.
std::string completeArgs(BenchArgs& args) {
    if (args.quick) {
        args.width = 160;
        args.height = 120;
        args.repeat = 2;
        args.process_repeat = std::min(args.process_repeat, 1u);
        args.ref_samples = 64;
        args.temporal_frames = std::min(args.temporal_frames, 3u);
        args.temporal_ref_samples = 16;
        if (args.scenes.empty())
            args.scenes = {"builtin:demo", "builtin:railing"};
    }
    if (args.temporal_frames == 1)
        return "--temporal-frames must be 0 or at least 2";
    const std::vector<std::string> known = methodNames();
    if (args.methods.empty())
        args.methods = known;
    for (const std::string& m : args.methods)
        if (std::find(known.begin(), known.end(), m) == known.end()) {
            std::string list;
            for (const std::string& k : known)
                list += " " + k;
            return "unknown method '" + m + "' (valid:" + list + ")";
        }
    if (args.scenes.empty()) {
        for (const scenes::BuiltinInfo& info : scenes::builtinScenes())
            args.scenes.push_back("builtin:" + std::string(info.name));
        for (const std::string& f : findSceneFiles(args.scene_dir))
            args.scenes.push_back(f);
    }
    return {};
}

// One line on stderr per finished run: "focal: bench [done/total elapsed] what".
class Progress {
public:
    Progress(size_t total, std::chrono::steady_clock::time_point start)
        : total_(total), start_(start) {}
    void step(const std::string& what) {
        ++done_;
        const double elapsed =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
        std::fprintf(stderr, "focal: bench [%zu/%zu %3.0fs] %s\n", done_, total_, elapsed,
                     what.c_str());
        std::fflush(stderr);
    }
    void skip() { ++done_; }

private:
    size_t total_;
    size_t done_ = 0;
    std::chrono::steady_clock::time_point start_;
};

// Thread counts of the scaling study: 1, 2, then powers of two up to the hardware's.
std::vector<uint32_t> scalingThreadCounts() {
    std::vector<uint32_t> counts = {1, 2};
    for (uint32_t t = 4; t <= std::thread::hardware_concurrency(); t *= 2)
        counts.push_back(t);
    return counts;
}

// What every run of one scene shares.
struct SceneRuns {
    const BenchArgs& args;
    const BenchScene& scene;
    std::vector<std::string> common; // the scene, the size and its lens options
    const LoadedScene& loaded;       // the scene, loaded once for all its runs
    const Reference& ref;
    fs::path out;
};

// Whole-process times of the run `id`, as process_ms_median and process_runs.
void addProcessTimes(const SceneRuns& c, const std::string& method, const Setting& setting,
                     uint32_t threads, const std::string& id, Json& row) {
    std::vector<std::string> p = c.common;
    p.insert(p.end(), {"--threads", std::to_string(threads), "--method", method, "-o",
                       (c.out / "runs" / (id + "_process.exr")).string(), "--no-progress"});
    p.insert(p.end(), setting.args.begin(), setting.args.end());
    std::vector<double> ms;
    for (uint32_t k = 0; k < c.args.process_repeat; ++k)
        if (const double t = timeRenderProcess(p); std::isfinite(t))
            ms.push_back(t);
    if (ms.size() < c.args.process_repeat)
        std::fprintf(stderr, "focal: bench: %s %s %s: %zu of %u render processes failed\n",
                     c.scene.spec.c_str(), method.c_str(), setting.label.c_str(),
                     c.args.process_repeat - ms.size(), c.args.process_repeat);
    row["process_ms_median"] = ms.empty() ? Json() : Json(median(ms));
    row["process_runs"] = ms.size();
}

// The image and its false-colour difference to the reference under OUT/images.
Status addImages(const SceneRuns& c, const std::string& id, const ImageData& img, Json& row) {
    const std::string png = "images/" + id + ".png";
    const std::string diff = "images/" + id + "_diff.png";
    ImageData d{img.width, img.height, 3,
                dof::falseColorDifference(imageRefOf(img), imageRefOf(c.ref.color), kDiffScale)};
    if (Status s = writeImage((c.out / png).string(), img); !s.ok())
        return s;
    if (Status s = writeImage((c.out / diff).string(), d); !s.ok())
        return s;
    row["image"] = png;
    row["diff_image"] = diff;
    return {};
}

// Renders `method` at `setting` on `threads` threads (--repeat runs in one process), compares it
// with the reference and returns its row. The main study also times whole processes and keeps
// the image with its difference.
Result<Json> runCase(const SceneRuns& c, const std::string& method, const Setting& setting,
                     uint32_t threads, const std::string& study) {
    const BenchArgs& args = c.args;
    const std::string id = safeName(c.scene.name + "_" + method + "_" + setting.label + "_t" +
                                    std::to_string(threads));
    std::vector<std::string> a = c.common;
    if (method == "pinhole") // it has no lens: drop the lens options (and the warning)
        a.resize(5);
    a.insert(a.end(), {"--threads", std::to_string(threads), "--method", method, "--repeat",
                       std::to_string(args.repeat)});
    a.insert(a.end(), setting.args.begin(), setting.args.end());
    RenderRun r = renderInMemory(a, &c.loaded);
    if (r.exit_code != 0)
        return Status::error(c.scene.spec + ": --method " + method + " " + setting.label +
                             " failed");
    const ImageData* img = &r.image;
    Json row;
    row["scene"] = c.scene.spec;
    row["study"] = study;
    row["method"] = method;
    row["setting"] = setting.label;
    row["width"] = args.width;
    row["height"] = args.height;
    row["threads"] = threads;
    row["repeat"] = args.repeat;
    addTimes(row, r.stats);
    row["peak_rss_mib"] = r.peak_rss_mib;
    row["peak_rss_added_mib"] = r.peak_rss_mib - r.start_rss_mib;
    row["peak_rss_scope"] = r.peak_scope;
    addMetrics(row, "", dof::compareImages(imageRefOf(*img), imageRefOf(c.ref.color)));
    row["band_pixels"] = c.ref.band_pixels;
    if (c.ref.band_pixels > 0)
        addMetrics(row, "band_",
                   dof::compareImages(imageRefOf(*img), imageRefOf(c.ref.color), &c.ref.band));
    else
        addMetrics(row, "band_", Status::error("no band"));
    row["reference_samples"] = args.ref_samples;
    row["reference_key"] = c.ref.key;
    std::string opts;
    for (const std::string& o : setting.args)
        opts += (opts.empty() ? "" : " ") + o;
    row["render_options"] = opts;
    addParams(row, r.stats);
    // Scene load, kept apart from the render's time (--stats' load.time_ms.total).
    row["load_ms"] = r.stats.value(Json::json_pointer("/load/time_ms/total"), 0.0);
    // Whole-process time of the same render (not for pinhole: it has no equal-error ratio).
    if (study == "main" && method != "pinhole" && args.process_repeat > 0)
        addProcessTimes(c, method, setting, threads, id, row);
    if (study == "main")
        if (Status s = addImages(c, id, *img, row); !s.ok())
            return s;
    return row;
}

std::string progressText(const Json& row) {
    return row["method"].get<std::string>() + " " + row["setting"].get<std::string>() +
           " threads=" + std::to_string(row["threads"].get<uint32_t>()) + ": " +
           fmt("%.1f ms", row["ms_median"]) +
           (row.contains("process_ms_median") && row["process_ms_median"].is_number()
                ? fmt(" (process %.1f ms)", row["process_ms_median"])
                : std::string()) +
           ", PSNR " +
           (row["psnr_srgb_db"].is_number() ? fmt("%.2f dB", row["psnr_srgb_db"])
                                            : std::string("inf"));
}

// Every method's main settings on one scene. One failing setting (e.g. a method's capacity
// limit on a big scene) is a result too: it is recorded and the others go on.
void runMainStudy(const SceneRuns& c, BenchResults& results, Progress& progress) {
    for (const std::string& method : c.args.methods)
        for (const Setting& setting : settingsFor(method, c.args.quick)) {
            Result<Json> row = runCase(c, method, setting, c.args.threads, "main");
            if (!row.ok()) {
                std::fprintf(stderr, "focal: bench: %s %s %s failed: %s\n", c.scene.spec.c_str(),
                             method.c_str(), setting.label.c_str(), row.status().message().c_str());
                results.rows.push_back(Json{{"scene", c.scene.spec},
                                            {"study", "failed"},
                                            {"method", method},
                                            {"setting", setting.label},
                                            {"error", row.status().message()}});
                progress.skip();
                continue;
            }
            results.rows.push_back(std::move(*row));
            results.rows_of_scene[c.scene.spec].push_back(results.rows.size() - 1);
            progress.step(c.scene.name + " " + progressText(results.rows.back()));
        }
    markPareto(results.rows, results.rows_of_scene[c.scene.spec]);
}

// Rounds of the scaling study (runScalingStudy).
constexpr size_t kScalingRounds = 3;

// Thread scaling: each method's scaling setting at 1, 2, 4... threads. The thread counts take
// turns over kScalingRounds rounds, and each count keeps its round of median time: a slow spell
// of a shared machine then falls on every count alike instead of on one row of the ratio t1 / tn.
Status runScalingStudy(const SceneRuns& c, BenchResults& results, Progress& progress) {
    const std::vector<uint32_t> counts = scalingThreadCounts();
    for (const std::string& method : c.args.methods) {
        const Setting setting = studySetting(method, c.args.quick, &Setting::scaling);
        std::vector<std::vector<Json>> rounds(counts.size());
        for (size_t round = 0; round < kScalingRounds; ++round)
            for (size_t i = 0; i < counts.size(); ++i) {
                Result<Json> row = runCase(c, method, setting, counts[i], "scaling");
                if (!row.ok())
                    return row.status();
                progress.step(c.scene.name + " " + progressText(*row));
                rounds[i].push_back(std::move(*row));
            }
        for (std::vector<Json>& rows : rounds) {
            std::vector<double> ms;
            for (const Json& row : rows)
                ms.push_back(row["ms_median"].get<double>());
            std::sort(rows.begin(), rows.end(), [](const Json& a, const Json& b) {
                return a["ms_median"].get<double>() < b["ms_median"].get<double>();
            });
            Json kept = std::move(rows[rows.size() / 2]);
            kept["scaling_rounds_ms"] = ms; // every round's median, in run order
            results.rows.push_back(std::move(kept));
        }
    }
    return {};
}

// The scene's reference (rendered or cached), its PNG and its results.json "scenes" entry.
Result<Reference> sceneReference(const BenchArgs& args, const BenchScene& scene,
                                 const std::vector<std::string>& common, const LoadedScene& loaded,
                                 const fs::path& out, const std::string& cache,
                                 BenchResults& results) {
    std::fprintf(stderr, "focal: bench: %s: reference (accum, %u views)...\n", scene.spec.c_str(),
                 args.ref_samples);
    Result<Reference> ref =
        reference(scene, common, args.ref_samples, args.threads, cache, &loaded);
    if (!ref.ok())
        return ref;
    const std::string ref_png = "images/" + scene.name + "_reference.png";
    if (Status s = writeImage((out / ref_png).string(), ref->color); !s.ok())
        return s;
    results.scene_info.push_back({{"scene", scene.spec},
                                  {"name", scene.name},
                                  {"reference_key", ref->key},
                                  {"reference_samples", args.ref_samples},
                                  {"reference_ms", ref->ms},
                                  {"reference_cached", ref->cached},
                                  {"reference_png", ref_png},
                                  {"band_pixels", ref->band_pixels}});
    return ref;
}

// Speed-up at equal error over accum, per scene, target and layered method.
void addEqualError(const BenchArgs& args, const std::vector<BenchScene>& scenes,
                   BenchResults& results) {
    std::vector<std::string> layered;
    for (const std::string& m : args.methods)
        if (m != "pinhole" && m != "accum")
            layered.push_back(m);
    results.equal_error = equalErrorHeader(layered, args.process_repeat);
    Json equal_scenes = Json::array();
    const bool have_accum =
        std::find(args.methods.begin(), args.methods.end(), "accum") != args.methods.end();
    if (have_accum && !layered.empty())
        for (const BenchScene& scene : scenes) {
            Json e = equalErrorOfScene(scene.spec, results.rows, results.rows_of_scene[scene.spec],
                                       layered);
            e["name"] = scene.name;
            equal_scenes.push_back(e);
        }
    else
        results.equal_error["note"] = "needs accum and at least one layered method in --methods";
    results.equal_error["scenes"] = equal_scenes;
    results.equal_table = equalErrorTable(equal_scenes, layered);
    results.equal_title = "Speed-up over accum at equal error (" + std::to_string(args.width) +
                          "x" + std::to_string(args.height) + ", " + std::to_string(args.threads) +
                          " threads, reference accum " + std::to_string(args.ref_samples) +
                          " views)";
}

// One plot per scene when gnuplot is there; else, or on the first failure, a note.
void addPlots(const BenchArgs& args, const std::vector<BenchScene>& scenes, const fs::path& out,
              BenchResults& results) {
    results.plots = !args.no_plots && haveGnuplot();
    if (args.no_plots)
        results.plot_note = "plots skipped (--no-plots)";
    else if (!results.plots)
        results.plot_note = "gnuplot not found: plots skipped (apt-get install gnuplot-nox)";
    for (const BenchScene& scene : scenes)
        if (results.plots)
            if (Status s = plotScene(out.string(), scene.name, results.rows,
                                     results.rows_of_scene[scene.spec], args.methods,
                                     scene.spec + ", " + std::to_string(args.width) + "x" +
                                         std::to_string(args.height) + ", " +
                                         std::to_string(args.threads) + " threads, reference " +
                                         std::to_string(args.ref_samples) + " views");
                !s.ok()) {
                results.plot_note = s.message();
                break;
            }
    if (!results.plot_note.empty())
        std::fprintf(stderr, "focal: bench: %s\n", results.plot_note.c_str());
}

} // namespace

CLI::App* addBenchCommand(CLI::App& app, BenchArgs& args) {
    CLI::App* cmd = app.add_subcommand(
        "bench", "Run time against error: every scene x method x setting against a cached accum "
                 "reference; CSV, JSON, plots and an HTML page in -o DIR");
    args.threads = std::max(1u, std::thread::hardware_concurrency());
    cmd->add_option("--scenes", args.scenes,
                    "scenes (builtin:NAME or glTF files) [default: every built-in scene and the "
                    "glTF files under --scene-dir]");
    cmd->add_option("--methods", args.methods,
                    "methods [default: pinhole accum gather multilayer multiview]");
    cmd->add_option("-o,--output", args.output, "output folder")->required();
    cmd->add_option("--ref-cache", args.ref_cache,
                    "folder of cached reference renders, shared between runs [default: DIR/refs]");
    cmd->add_option("--scene-dir", args.scene_dir,
                    "also bench the glTF files DIR/*/glTF/*.gl{tf,b} when the folder exists")
        ->capture_default_str();
    cmd->add_flag("--quick", args.quick,
                  "CI smoke run: 160x120, builtin:demo and builtin:railing, 1 setting per "
                  "method (accum: N = 4, 8, 16, 32), 2 runs, 1 process run, a 64-view reference "
                  "(below the 1024 real results need)");
    cmd->add_option("--width", args.width, "image width")
        ->capture_default_str()
        ->check(CLI::Range(16, 4096));
    cmd->add_option("--height", args.height, "image height")
        ->capture_default_str()
        ->check(CLI::Range(16, 4096));
    cmd->add_option("--repeat", args.repeat, "timed runs per setting")
        ->capture_default_str()
        ->check(CLI::Range(1, 1000));
    cmd->add_option("--process-repeat", args.process_repeat,
                    "timed whole `focal render` processes per setting, for the equal-error "
                    "speed-up's process time (0: none; --quick: at most 1)")
        ->capture_default_str()
        ->check(CLI::Range(0, 1000));
    cmd->add_option("--ref-samples", args.ref_samples, "accum views of the reference")
        ->capture_default_str()
        ->check(CLI::Range(1, 1 << 20));
    cmd->add_option("--temporal-frames", args.temporal_frames,
                    "frames K of the focus pull + camera move (0: no temporal study)")
        ->capture_default_str()
        ->check(CLI::Range(0, 1000));
    cmd->add_option("--temporal-ref-samples", args.temporal_ref_samples,
                    "accum views of each temporal reference frame")
        ->capture_default_str()
        ->check(CLI::Range(1, 1 << 20));
    cmd->add_option("--threads", args.threads, "worker threads of the main runs")
        ->capture_default_str()
        ->check(CLI::Range(0, 256));
    cmd->add_flag("--no-scaling", args.no_scaling, "skip the thread-scaling study");
    cmd->add_flag("--no-plots", args.no_plots, "do not run gnuplot");
    return cmd;
}

int runBench(BenchArgs args) {
    const auto bench_start = std::chrono::steady_clock::now();
    if (const std::string problem = completeArgs(args); !problem.empty())
        return usage(problem);
    // Load every scene first, so a typo fails before any work.
    std::vector<BenchScene> scenes;
    for (const std::string& spec : args.scenes) {
        Result<BenchScene> s = prepareScene(spec, args.width, args.height);
        if (!s.ok())
            return usage(s.status().message());
        scenes.push_back(std::move(*s));
    }
    const fs::path out(args.output);
    const std::string cache = args.ref_cache.empty() ? (out / "refs").string() : args.ref_cache;
    std::error_code ec;
    for (const fs::path& p : {out, out / "runs", out / "images", out / "plots", fs::path(cache)})
        if (fs::create_directories(p, ec); ec)
            return fail(p.string() + ": cannot create folder: " + ec.message());

    size_t total = 0;
    for (const std::string& m : args.methods)
        total += scenes.size() * settingsFor(m, args.quick).size();
    if (!args.no_scaling)
        total += kScalingRounds * scalingThreadCounts().size() * args.methods.size();
    Progress progress(total, bench_start);

    BenchResults results;
    for (const BenchScene& scene : scenes) {
        std::vector<std::string> common = {scene.spec, "--width", std::to_string(args.width),
                                           "--height", std::to_string(args.height)};
        common.insert(common.end(), scene.lens.begin(), scene.lens.end());
        // Loaded once: every run's render time excludes it, and the rows' load_ms is this load's.
        Result<LoadedScene> loaded = loadBenchScene(common);
        if (!loaded.ok())
            return fail(loaded.status().message());
        Result<Reference> ref = sceneReference(args, scene, common, *loaded, out, cache, results);
        if (!ref.ok())
            return fail(ref.status().message());
        const SceneRuns runs{args, scene, common, *loaded, *ref, out};
        runMainStudy(runs, results, progress);
        if (!args.no_scaling && &scene == &scenes.front())
            if (Status s = runScalingStudy(runs, results, progress); !s.ok())
                return fail(s.message());
    }
    addEqualError(args, scenes, results);
    addScalingEfficiency(results.rows);
    if (args.temporal_frames >= 2 && !scenes.empty()) {
        Result<Json> temporal = temporalStudy(args, scenes.front(), cache);
        if (!temporal.ok())
            return fail(temporal.status().message());
        results.temporal = std::move(*temporal);
    }
    addPlots(args, scenes, out, results);

    const double elapsed_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - bench_start).count();
    if (Status s = writeResultFiles(args, results, out.string(), elapsed_s); !s.ok())
        return fail(s.message());
    if (Status s = writeIndexHtml(args, scenes, results, out.string()); !s.ok())
        return fail(s.message());
    if (!results.equal_error["scenes"].empty())
        std::printf("%s\n%s\n", results.equal_title.c_str(),
                    markdownTable(results.equal_table).c_str());
    std::printf("focal: bench wrote %zu rows to %s (results.csv, results.json, equal_error.md, "
                "index.html) in %.1f s\n",
                results.rows.size(), out.string().c_str(), elapsed_s);
    return 0;
}

} // namespace focal
