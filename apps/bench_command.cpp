#include "apps/bench_command.h"

#include "apps/dof_method.h"
#include "apps/equal_error.h"
#include "apps/image_io.h"
#include "apps/render_command.h"
#include "apps/scene_source.h"
#include "apps/text_file.h"

#include <dof/metrics.h>
#include <raster/camera.h>
#include <raster/scene.h>
#include <scenes/builtin.h>

#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <spawn.h>
#include <sstream>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

namespace focal {

using raster::Result;
using raster::Status;
using Json = nlohmann::ordered_json;
namespace fs = std::filesystem;

namespace {

constexpr float kPi = 3.14159265358979f;
constexpr float kBandThreshold = 0.05f; // as `focal compare` defaults
constexpr float kBandRadius = 4.0f;
constexpr float kDiffScale = 0.1f;

// One parameter setting of a method: a label and the `focal render` options it adds. A method's
// settings always pass the same option names, because the table methods keep their option values
// between parses (apps/dof_method.h: the args object is owned by the entry).
struct Setting {
    std::string label;
    std::vector<std::string> args;
    bool scaling = false;  // the setting of the thread-scaling study (else the first)
    bool temporal = false; // the setting of the temporal study (else the last)
};

// The sweeps. accum's N doubles from 4 to 256 so that every equal-error target between the
// cheapest and the best accum is bracketed by two neighbouring settings (apps/equal_error.h);
// the other methods cover their useful range. The studies keep the settings they had before
// the sweeps grew: accum N = 16 (quick: 8) for both; the others' first for scaling, last for
// temporal.
std::vector<Setting> settingsFor(const std::string& method, bool quick) {
    if (method == "pinhole")
        return {{"default", {}}};
    if (method == "accum") {
        const std::vector<int> ns =
            quick ? std::vector<int>{4, 8, 16, 32} : std::vector<int>{4, 8, 16, 32, 64, 128, 256};
        const int study = quick ? 8 : 16;
        std::vector<Setting> out;
        for (int n : ns)
            out.push_back({"N=" + std::to_string(n),
                           {"--samples", std::to_string(n)},
                           n == study,
                           n == study});
        return out;
    }
    if (method == "gather") {
        auto g = [](const char* r) {
            return Setting{std::string("R=") + r, {"--gather-max-radius", r}};
        };
        if (quick)
            return {g("16")};
        return {g("8"), g("16"), g("32")};
    }
    if (method == "multiview") {
        auto m = [](const char* spacing, const char* samples) {
            return Setting{std::string("spacing=") + spacing + ",N=" + samples,
                           {"--layers", "0", "--layer-spacing", spacing, "--samples", samples}};
        };
        if (quick)
            return {m("4", "16")};
        Setting first = m("4", "16");
        first.scaling = true;
        return {m("4", "8"), first, m("2", "32"), m("1", "64")};
    }
    if (method == "multilayer") {
        auto m = [](const char* n) {
            return Setting{std::string("frags=") + n, {"--fragments-per-pixel", n}};
        };
        if (quick)
            return {m("4")};
        return {m("2"), m("4"), m("8")};
    }
    return {{"default", {}}};
}

// The setting a study uses: the one flagged by `flag`, else the first (scaling) or last.
Setting studySetting(const std::string& method, bool quick, bool Setting::*flag) {
    const std::vector<Setting> all = settingsFor(method, quick);
    for (const Setting& s : all)
        if (s.*flag)
            return s;
    return flag == &Setting::scaling ? all.front() : all.back();
}

std::vector<std::string> allMethods() {
    std::vector<std::string> names = {"pinhole", "accum"};
    for (const MethodEntry& m : methodTable())
        names.push_back(m.name);
    return names;
}

int usage(const std::string& message) {
    std::fprintf(stderr, "focal: error: %s (see focal bench --help)\n", message.c_str());
    return 2;
}

int fail(const std::string& message) {
    std::fprintf(stderr, "focal: error: %s\n", message.c_str());
    return 1;
}

std::string fnv1a(const std::string& text) {
    uint64_t h = 1469598103934665603ull;
    for (unsigned char c : text) {
        h ^= c;
        h *= 1099511628211ull;
    }
    char buf[17];
    std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
    return buf;
}

std::string safeName(const std::string& text) {
    std::string s;
    for (char c : text)
        s += std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '.' ? c : '_';
    return s;
}

std::string fmt(const char* f, double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, f, v);
    return buf;
}

std::string num(float v) {
    std::ostringstream s;
    s.precision(9);
    s << v;
    return s.str();
}

double median(std::vector<double> v) {
    if (v.empty())
        return 0.0;
    std::sort(v.begin(), v.end());
    const size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

Json number(double v) {
    return std::isfinite(v) ? Json(v) : Json();
}

// Peak resident memory. Writing "5" to /proc/self/clear_refs resets VmHWM (Linux >= 4.0), so
// the peak read after a run is that run's; where the reset is refused the value is the
// process-wide peak so far (scope "process").
bool resetPeakRss() {
    std::ofstream f("/proc/self/clear_refs");
    f << "5";
    f.flush();
    return bool(f);
}

// A "VmXXX:  N kB" field of /proc/self/status, in MiB (0 when absent).
double statusMiB(const char* field) {
    std::ifstream f("/proc/self/status");
    std::string line;
    const size_t n = std::strlen(field);
    while (std::getline(f, line))
        if (line.compare(0, n, field) == 0)
            return std::atof(line.c_str() + n) / 1024.0;
    return 0.0;
}

// The outcome of one `focal render` call made in-process.
struct RenderRun {
    int exit_code = 0;
    Json stats;
    double peak_rss_mib = 0.0;  // VmHWM after the run
    double start_rss_mib = 0.0; // VmRSS before it: the peak minus this is what the run added
    std::string peak_scope = "run";
};

// Parses `args` as `focal render ARGS` and runs it, with stdout silenced (its "wrote" line).
RenderRun renderInProcess(const std::vector<std::string>& args, const std::string& stats_path) {
    RenderRun r;
    CLI::App app;
    RenderArgs ra;
    CLI::App* cmd = addRenderCommand(app, ra);
    (void)cmd;
    std::vector<std::string> argv = {"render"};
    argv.insert(argv.end(), args.begin(), args.end());
    argv.insert(argv.end(), {"--stats", stats_path, "--no-progress"});
    std::reverse(argv.begin(), argv.end()); // CLI11 parses a vector back to front
    try {
        app.parse(argv);
    } catch (const CLI::ParseError& e) {
        std::fprintf(stderr, "focal: error: bench made a bad render command: %s\n", e.what());
        r.exit_code = 2;
        return r;
    }
    const bool reset = resetPeakRss();
    if (!reset)
        r.peak_scope = "process";
    r.start_rss_mib = statusMiB("VmRSS:");
    std::fflush(stdout);
    const int saved = ::dup(1);
    const int devnull = ::open("/dev/null", O_WRONLY);
    if (saved >= 0 && devnull >= 0)
        ::dup2(devnull, 1);
    r.exit_code = runRender(ra);
    std::fflush(stdout);
    if (saved >= 0 && devnull >= 0)
        ::dup2(saved, 1);
    if (devnull >= 0)
        ::close(devnull);
    if (saved >= 0)
        ::close(saved);
    r.peak_rss_mib = statusMiB("VmHWM:");
    if (r.exit_code == 0) {
        std::ifstream f(stats_path);
        r.stats = Json::parse(f, nullptr, false);
        if (r.stats.is_discarded())
            r.exit_code = 1;
    }
    return r;
}

dof::ImageRef refOf(const ImageData& img) {
    return {img.pixels.data(), img.width, img.height, img.channels};
}

// A scene to benchmark: its spec and the camera/lens options every render of it gets.
struct BenchScene {
    std::string spec;
    std::string name;              // file-safe
    std::vector<std::string> lens; // e.g. --aperture-radius for glTF files without a lens hint
    std::string identity;          // file size + mtime for glTF files (reference cache key)
    raster::View view;             // the default camera at the bench resolution
    float aperture_radius = 0.0f;
    float focus_distance = 1.0f;
};

Result<BenchScene> prepareScene(const std::string& spec, uint32_t width, uint32_t height) {
    // Only the view and lens are taken from the scene here (the renders run in focal render
    // processes), so no image is decoded.
    raster::ImportOptions no_images;
    no_images.roles = raster::TextureRoles{};
    Result<raster::Scene> scene = loadScene(spec, no_images);
    if (!scene.ok())
        return scene.status();
    BenchScene s;
    s.spec = spec;
    s.name = safeName(spec.rfind("builtin:", 0) == 0
                          ? spec.substr(8)
                          : fs::path(spec).parent_path().parent_path().filename().string() + "_" +
                                fs::path(spec).stem().string());
    const raster::Bounds bounds = raster::worldBounds(*scene);
    s.view = scene->cameras.empty() ? raster::viewFramingBounds(bounds, width, height)
                                    : raster::viewFromCamera(scene->cameras[0], width, height);
    if (scene->lens) {
        s.aperture_radius = scene->lens->aperture_radius;
        s.focus_distance = scene->lens->focus_distance;
    } else {
        // No lens hint: an aperture of 1% of the scene's diagonal, focus on the centre pixel
        // (focal render's autofocus).
        s.aperture_radius = bounds.empty ? 0.01f : 0.01f * glm::length(bounds.max - bounds.min);
        s.lens = {"--aperture-radius", num(s.aperture_radius)};
        s.focus_distance = s.view.focus_distance;
    }
    std::error_code ec;
    if (spec.rfind("builtin:", 0) != 0) {
        const auto size = fs::file_size(spec, ec);
        const auto time = fs::last_write_time(spec, ec).time_since_epoch().count();
        s.identity = std::to_string(size) + "@" + std::to_string(time);
    }
    return s;
}

// The glTF scenes under `dir`: DIR/NAME/glTF/*.gltf (Khronos sample layout) or DIR/**.gl{tf,b}.
std::vector<std::string> findSceneFiles(const std::string& dir) {
    std::vector<std::string> files;
    std::error_code ec;
    if (!fs::is_directory(dir, ec))
        return files;
    for (auto it = fs::recursive_directory_iterator(dir, ec);
         !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
        const std::string ext = it->path().extension().string();
        if (it->is_regular_file() && (ext == ".gltf" || ext == ".glb") &&
            it->path().parent_path().filename() == "glTF")
            files.push_back(it->path().string());
    }
    std::sort(files.begin(), files.end());
    return files;
}

struct Reference {
    ImageData color;
    ImageData depth;
    std::vector<uint8_t> band;
    uint64_t band_pixels = 0;
    std::string key;
    std::string png;
    double ms = 0.0;
    bool cached = false;
};

// Renders (or loads from the cache) `accum` with `samples` views for `common` render options.
// The key hashes every option that affects the image plus the scene file's identity.
// `threads` is not part of the key: the bits do not depend on it (DESIGN.md, determinism).
Result<Reference> reference(const BenchScene& scene, const std::vector<std::string>& common,
                            uint32_t samples, uint32_t threads, const std::string& cache_dir,
                            const std::string& tmp_dir) {
    Reference ref;
    std::string keytext = "focal-bench-ref-v1|" + scene.spec + "|" + scene.identity;
    for (const std::string& a : common)
        keytext += "|" + a;
    keytext += "|method=accum|samples=" + std::to_string(samples) +
               "|seed=0|pixel-jitter=off|lens-pattern=hammersley|depth-format=float32|"
               "shading=material|texture-filter=sampler";
    ref.key = fnv1a(keytext);
    const std::string base = (fs::path(cache_dir) / ref.key).string();
    const std::string color_path = base + ".exr", depth_path = base + "_depth.exr";
    std::error_code ec;
    if (fs::exists(color_path, ec) && fs::exists(depth_path, ec) && fs::exists(base + ".json")) {
        ref.cached = true;
        std::ifstream f(base + ".json");
        Json j = Json::parse(f, nullptr, false);
        if (!j.is_discarded() && j.contains("time_ms"))
            ref.ms = j["time_ms"].value("total", 0.0);
    } else {
        std::vector<std::string> args = common;
        args.insert(args.end(),
                    {"--method", "accum", "--samples", std::to_string(samples), "-o", color_path,
                     "--depth-out", depth_path, "--threads", std::to_string(threads)});
        RenderRun r = renderInProcess(args, (fs::path(tmp_dir) / "ref_stats.json").string());
        if (r.exit_code != 0)
            return Status::error("the reference render of " + scene.spec + " failed");
        r.stats["bench_key"] = keytext;
        if (Status s = writeTextFile(base + ".json", r.stats.dump(2) + "\n"); !s.ok())
            return s;
        ref.ms = r.stats["time_ms"].value("total", 0.0);
    }
    Result<ImageData> color = readImage(color_path);
    if (!color.ok())
        return color.status();
    Result<ImageData> depth = readImage(depth_path);
    if (!depth.ok())
        return depth.status();
    ref.color = std::move(*color);
    ref.depth = std::move(*depth);
    ref.band = dof::discontinuityBand(refOf(ref.depth), kBandThreshold, kBandRadius);
    for (uint8_t m : ref.band)
        ref.band_pixels += m;
    return ref;
}

// Flattens a stats JSON's parameters into row columns.
void addParams(Json& row, const Json& stats) {
    if (stats.contains("lens")) {
        const auto& l = stats["lens"];
        row["aperture_radius"] = l.value("aperture_radius", 0.0);
        row["focus_distance"] = l.value("focus_distance", 0.0);
        row["coc_at_infinity_px"] = l.value("coc_at_infinity_px", 0.0);
        row["lens_pattern"] = l.value("lens_pattern", std::string());
    }
    if (stats.contains("accum"))
        row["samples"] = stats["accum"].value("samples", 0);
    else if (stats.contains("lens") && stats["lens"].contains("samples"))
        row["samples"] = stats["lens"]["samples"];
    if (stats.contains("params") && stats["params"].is_object())
        for (const auto& [k, v] : stats["params"].items())
            if (v.is_primitive())
                row["param_" + k] = v;
    if (stats.contains("triangles"))
        row["triangles_in"] = stats["triangles"].value("in", 0);
}

void addTimes(Json& row, const Json& stats) {
    std::vector<double> totals;
    for (const auto& run : stats["runs"])
        totals.push_back(run.value("total", 0.0));
    row["ms_median"] = median(totals);
    row["ms_min"] = totals.empty() ? 0.0 : *std::min_element(totals.begin(), totals.end());
    row["ms_max"] = totals.empty() ? 0.0 : *std::max_element(totals.begin(), totals.end());
    for (const auto& [stage, ms] : stats["time_ms"].items())
        if (stage != "total")
            row["stage_ms_" + stage] = ms;
}

void addMetrics(Json& row, const std::string& prefix, const Result<dof::ErrorMetrics>& m) {
    if (!m.ok()) {
        row[prefix + "psnr_srgb_db"] = nullptr;
        row[prefix + "psnr_linear_db"] = nullptr;
        row[prefix + "ssim"] = nullptr;
        row[prefix + "mean_abs_error"] = nullptr;
        return;
    }
    row[prefix + "psnr_srgb_db"] = number(m->psnr_srgb_db);
    row[prefix + "psnr_linear_db"] = number(m->psnr_linear_db);
    row[prefix + "ssim"] = number(m->ssim);
    row[prefix + "mean_abs_error"] = m->mean_abs_error;
}

std::string csvCell(const Json& v) {
    if (v.is_null())
        return "";
    if (v.is_string()) {
        std::string s = v.get<std::string>();
        if (s.find_first_of(",\"\n") == std::string::npos)
            return s;
        std::string q = "\"";
        for (char c : s)
            q += c == '"' ? std::string("\"\"") : std::string(1, c);
        return q + "\"";
    }
    if (v.is_boolean())
        return v.get<bool>() ? "1" : "0";
    return v.dump();
}

std::string toCsv(const Json& rows) {
    std::vector<std::string> columns;
    std::set<std::string> seen;
    for (const auto& row : rows)
        for (const auto& [k, v] : row.items())
            if (seen.insert(k).second)
                columns.push_back(k);
    std::string out;
    for (size_t i = 0; i < columns.size(); ++i)
        out += (i ? "," : "") + columns[i];
    out += "\n";
    for (const auto& row : rows) {
        for (size_t i = 0; i < columns.size(); ++i) {
            if (i)
                out += ",";
            if (row.contains(columns[i]))
                out += csvCell(row[columns[i]]);
        }
        out += "\n";
    }
    return out;
}

double psnrOf(const Json& row) {
    const Json& p = row["psnr_srgb_db"];
    return p.is_number() ? p.get<double>() : 200.0; // identical to the reference: off the scale
}

// Marks the Pareto front (no other row is both faster and more accurate) among `idx`.
void markPareto(Json& rows, const std::vector<size_t>& idx) {
    std::vector<size_t> order = idx;
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
        const double ta = rows[a]["ms_median"], tb = rows[b]["ms_median"];
        return ta != tb ? ta < tb : psnrOf(rows[a]) > psnrOf(rows[b]);
    });
    double best = -1e300;
    for (size_t i : order) {
        const bool front = psnrOf(rows[i]) > best;
        rows[i]["pareto"] = front;
        if (front)
            best = psnrOf(rows[i]);
    }
}

bool haveGnuplot() {
    return std::system("command -v gnuplot >/dev/null 2>&1") == 0;
}

// Writes DIR/plots/<scene>.{dat,gp} and runs gnuplot on it: median time (log x) against sRGB
// PSNR, one point style per method, min-max time as error bars, the Pareto front as a line.
Status plotScene(const std::string& dir, const std::string& scene, const Json& rows,
                 const std::vector<size_t>& idx, const std::vector<std::string>& methods,
                 const std::string& title) {
    const std::string base = (fs::path(dir) / "plots" / ("bench_" + scene)).string();
    std::string dat;
    int blocks = 0;
    std::vector<std::string> titles;
    for (const std::string& m : methods) {
        std::string block;
        for (size_t i : idx)
            if (rows[i]["method"] == m && rows[i]["psnr_srgb_db"].is_number())
                block += fmt("%.6g", rows[i]["ms_median"].get<double>()) + " " +
                         fmt("%.6g", rows[i]["psnr_srgb_db"].get<double>()) + " " +
                         fmt("%.6g", rows[i]["ms_min"].get<double>()) + " " +
                         fmt("%.6g", rows[i]["ms_max"].get<double>()) + " \"" +
                         rows[i]["setting"].get<std::string>() + "\"\n";
        if (block.empty())
            continue;
        dat += "# " + m + "\n" + block + "\n\n";
        titles.push_back(m);
        ++blocks;
    }
    std::vector<size_t> front;
    for (size_t i : idx)
        if (rows[i].value("pareto", false) && rows[i]["psnr_srgb_db"].is_number())
            front.push_back(i);
    std::sort(front.begin(), front.end(), [&](size_t a, size_t b) {
        return rows[a]["ms_median"].get<double>() < rows[b]["ms_median"].get<double>();
    });
    dat += "# pareto\n";
    for (size_t i : front)
        dat += fmt("%.6g", rows[i]["ms_median"].get<double>()) + " " +
               fmt("%.6g", rows[i]["psnr_srgb_db"].get<double>()) + "\n";
    dat += "\n\n";
    static const char* kColors[] = {"#000000", "#0072b2", "#e69f00",
                                    "#009e73", "#cc79a7", "#d55e00"};
    if (Status s = writeTextFile(base + ".dat", dat); !s.ok())
        return s;
    std::string gp = "set terminal pngcairo size 900,600 noenhanced font ',10'\n"
                     "set output '" +
                     base +
                     ".png'\n"
                     "set title '" +
                     title +
                     "'\n"
                     "set logscale x\nset xlabel 'median wall time per frame (ms, log scale)'\n"
                     "set ylabel 'PSNR against the accum reference (sRGB, dB)'\n"
                     "set key bottom right\nset grid\n"
                     "plot ";
    for (int b = 0; b < blocks; ++b)
        gp += "'" + base + ".dat' index " + std::to_string(b) +
              " using 1:2:3:4 with xerrorbars pt " + std::to_string(5 + 2 * b) +
              " ps 1.5 lc rgb '" + kColors[size_t(b) % 6] + "' title '" + titles[size_t(b)] +
              "', '" + base + ".dat' index " + std::to_string(b) +
              " using 1:2:5 with labels offset 0,1 font ',8' notitle, ";
    gp += "'" + base + ".dat' index " + std::to_string(blocks) +
          " using 1:2 with lines lw 2 dt 2 lc rgb 'gray50' title 'Pareto front'\n";
    if (Status s = writeTextFile(base + ".gp", gp); !s.ok())
        return s;
    const std::string cmd = "gnuplot '" + base + ".gp' 2>'" + base + ".log'";
    if (std::system(cmd.c_str()) != 0)
        return Status::error("gnuplot failed on " + base + ".gp (see " + base + ".log)");
    return {};
}

std::string htmlEscape(const std::string& s) {
    std::string o;
    for (char c : s)
        o += c == '<' ? "&lt;" : c == '>' ? "&gt;" : c == '&' ? "&amp;" : std::string(1, c);
    return o;
}

// Wall time of `focal render ARGS` run as a child process of this binary (/proc/self/exe), its
// stdout and stderr discarded: what a user waits for (start-up, scene load, autofocus, render,
// image write). NaN when it cannot start or fails.
double timeRenderProcess(const std::vector<std::string>& args) {
    constexpr double kFailed = std::numeric_limits<double>::quiet_NaN();
    std::error_code ec;
    const std::string exe = fs::read_symlink("/proc/self/exe", ec).string();
    if (ec)
        return kFailed;
    std::vector<std::string> argv = {exe, "render"};
    argv.insert(argv.end(), args.begin(), args.end());
    std::vector<char*> cargv;
    for (std::string& a : argv)
        cargv.push_back(a.data());
    cargv.push_back(nullptr);
    posix_spawn_file_actions_t files;
    if (::posix_spawn_file_actions_init(&files) != 0)
        return kFailed;
    ::posix_spawn_file_actions_addopen(&files, 1, "/dev/null", O_WRONLY, 0);
    ::posix_spawn_file_actions_addopen(&files, 2, "/dev/null", O_WRONLY, 0);
    std::fflush(stdout);
    std::fflush(stderr);
    const auto start = std::chrono::steady_clock::now();
    pid_t pid = 0;
    const int spawned = ::posix_spawn(&pid, exe.c_str(), &files, nullptr, cargv.data(), environ);
    ::posix_spawn_file_actions_destroy(&files);
    if (spawned != 0)
        return kFailed;
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0)
        if (errno != EINTR)
            return kFailed;
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return WIFEXITED(status) && WEXITSTATUS(status) == 0 ? ms : kFailed;
}

// The issue-18 error targets: full-frame SSIM and sRGB PSNR against the reference.
struct ErrorTarget {
    const char* label;
    const char* metric; // a results.json row column
    double value;
};
constexpr ErrorTarget kErrorTargets[] = {{"SSIM 0.97", "ssim", 0.97},
                                         {"SSIM 0.98", "ssim", 0.98},
                                         {"PSNR 35 dB", "psnr_srgb_db", 35.0},
                                         {"PSNR 40 dB", "psnr_srgb_db", 40.0}};

constexpr const char* kEqualErrorDefinition =
    "Speed-up at equal error = accum's time to reach the target / the time of the method's "
    "cheapest setting that reaches it (full-frame SSIM or sRGB PSNR against the reference). "
    "accum's time: the metric's running maximum over increasing N, interpolated linearly in "
    "log2 N between the two sweep settings that bracket the target; the time at that N "
    "interpolated linearly in N between them. '>x': accum never reached the target (its largest "
    "N's time is a lower bound); '<=x': accum's smallest N already reaches it (an upper bound). "
    "render = the render's own median time (scene load excluded); process = median wall time "
    "of a whole `focal render` process (start-up, load, render, image write).";

// A main row as a sweep point for `metric`. A null metric with a number SSIM is +inf
// (identical to the reference); a null SSIM is a failed comparison (NaN: ignored).
SweepPoint sweepPointOf(const Json& row, const std::string& metric) {
    SweepPoint p;
    p.setting = row["setting"].get<std::string>();
    const auto samples = row.find("samples");
    p.samples = samples != row.end() && samples->is_number() ? samples->get<double>() : 0.0;
    p.render_ms = row["ms_median"].get<double>();
    const auto process = row.find("process_ms_median");
    p.process_ms = process != row.end() && process->is_number()
                       ? process->get<double>()
                       : std::numeric_limits<double>::quiet_NaN();
    const Json& v = row[metric];
    p.value = v.is_number()           ? v.get<double>()
              : row["ssim"].is_null() ? std::numeric_limits<double>::quiet_NaN()
                                      : std::numeric_limits<double>::infinity();
    return p;
}

Json accumCostJson(const AccumCost& c) {
    Json j = {{"reach", reachName(c.reach)}};
    if (c.reach == AccumReach::NoData)
        return j;
    j["samples"] = c.samples;
    j["ms"] = c.ms;
    if (c.reach == AccumReach::Interpolated) {
        j["below"] = c.below;
        j["above"] = c.above;
    }
    return j;
}

Json speedUpJson(const SpeedUp& s, std::span<const SweepPoint> method) {
    const bool ratio = s.bound == RatioBound::Exact || s.bound == RatioBound::AtLeast ||
                       s.bound == RatioBound::AtMost;
    return {{"accum_ms", s.accum.reach == AccumReach::NoData ? Json() : Json(s.accum.ms)},
            {"method_ms", s.method.reached ? Json(s.method.ms) : Json()},
            {"setting", s.method.reached ? Json(method[s.method.index].setting) : Json()},
            {"ratio", ratio ? number(s.ratio) : Json()},
            {"bound", boundName(s.bound)},
            {"text", formatSpeedUp(s)}};
}

// One scene's equal-error results: per target accum's cost and per layered method the
// speed-up, for render and whole-process time.
Json equalErrorOfScene(const std::string& spec, const Json& rows, const std::vector<size_t>& idx,
                       const std::vector<std::string>& layered) {
    Json targets = Json::array();
    for (const ErrorTarget& target : kErrorTargets) {
        auto sweep = [&](const std::string& method) {
            std::vector<SweepPoint> pts;
            for (size_t i : idx)
                if (rows[i]["method"] == method)
                    pts.push_back(sweepPointOf(rows[i], target.metric));
            return pts;
        };
        const std::vector<SweepPoint> accum = sweep("accum");
        Json t = {{"target", target.label}, {"metric", target.metric}, {"value", target.value}};
        t["accum"] = {
            {"render", accumCostJson(accumCostToReach(accum, target.value, TimeKind::Render))},
            {"process", accumCostJson(accumCostToReach(accum, target.value, TimeKind::Process))}};
        Json methods = Json::object();
        for (const std::string& m : layered) {
            const std::vector<SweepPoint> pts = sweep(m);
            methods[m] = {
                {"render",
                 speedUpJson(speedUpAtEqualError(accum, pts, target.value, TimeKind::Render), pts)},
                {"process",
                 speedUpJson(speedUpAtEqualError(accum, pts, target.value, TimeKind::Process),
                             pts)}};
        }
        t["methods"] = methods;
        targets.push_back(t);
    }
    return {{"scene", spec}, {"targets", targets}};
}

// A table: a header and rows of cells, rendered as Markdown (report, equal_error.md) or HTML.
struct Table {
    std::vector<std::string> header;
    std::vector<std::vector<std::string>> rows;
};

// accum's cell: the N it needs and its render / process time.
std::string accumCell(const Json& render, const Json& process) {
    auto ms = [](const Json& c) {
        return c["reach"] == "no_data" ? std::string("-") : fmt("%.1f", c["ms"].get<double>());
    };
    const std::string reach = render["reach"].get<std::string>();
    if (reach == "no_data")
        return "no data";
    const std::string rel = reach == "interpolated"    ? "N="
                            : reach == "first_setting" ? "N<="
                                                       : "N>";
    const std::string bound = reach == "interpolated" ? "" : reach == "first_setting" ? "<=" : ">";
    return rel + fmt("%.3g", render["samples"].get<double>()) + ": " + bound + ms(render) + " / " +
           (process["reach"] == "no_data" ? "" : bound) + ms(process) + " ms";
}

// A method's cell: render / process speed-up with the setting(s) that achieve them.
std::string speedUpCell(const Json& render, const Json& process) {
    const std::string r = render["text"].get<std::string>(), p = process["text"].get<std::string>();
    if (render["setting"].is_null())
        return r;
    const std::string rs = render["setting"].get<std::string>();
    if (process["setting"].is_null() || process["setting"] == rs)
        return r + " / " + p + " (" + rs + ")";
    return r + " (" + rs + ") / " + p + " (" + process["setting"].get<std::string>() + ")";
}

Table equalErrorTable(const Json& scenes, const std::vector<std::string>& layered) {
    Table t;
    t.header = {"scene", "target", "accum N: ms render / process"};
    for (const std::string& m : layered)
        t.header.push_back(m + " render / process");
    for (const Json& scene : scenes)
        for (const Json& target : scene["targets"]) {
            std::vector<std::string> row = {
                scene.value("name", scene["scene"].get<std::string>()),
                target["target"].get<std::string>(),
                accumCell(target["accum"]["render"], target["accum"]["process"])};
            for (const std::string& m : layered)
                row.push_back(
                    speedUpCell(target["methods"][m]["render"], target["methods"][m]["process"]));
            t.rows.push_back(row);
        }
    return t;
}

std::string markdownTable(const Table& t) {
    std::vector<size_t> width(t.header.size(), 3);
    for (size_t c = 0; c < t.header.size(); ++c) {
        width[c] = std::max(width[c], t.header[c].size());
        for (const auto& row : t.rows)
            width[c] = std::max(width[c], row[c].size());
    }
    auto line = [&](const std::vector<std::string>& cells) {
        std::string s = "|";
        for (size_t c = 0; c < cells.size(); ++c)
            s += " " + cells[c] + std::string(width[c] - cells[c].size(), ' ') + " |";
        return s + "\n";
    };
    std::vector<std::string> rule;
    for (size_t w : width)
        rule.push_back(std::string(w, '-'));
    std::string out = line(t.header) + line(rule);
    for (const auto& row : t.rows)
        out += line(row);
    return out;
}

std::string htmlTable(const Table& t) {
    std::string out = "<table border='1'><tr>";
    for (const std::string& h : t.header)
        out += "<th>" + htmlEscape(h) + "</th>";
    out += "</tr>";
    for (const auto& row : t.rows) {
        out += "<tr>";
        for (const std::string& cell : row)
            out += "<td>" + htmlEscape(cell) + "</td>";
        out += "</tr>";
    }
    return out + "</table>";
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
        return usage("--temporal-frames must be 0 or at least 2");
    const std::vector<std::string> known = allMethods();
    if (args.methods.empty())
        args.methods = known;
    for (const std::string& m : args.methods)
        if (std::find(known.begin(), known.end(), m) == known.end()) {
            std::string list;
            for (const std::string& k : known)
                list += " " + k;
            return usage("unknown method '" + m + "' (valid:" + list + ")");
        }
    if (args.scenes.empty()) {
        for (const scenes::BuiltinInfo& info : scenes::builtinScenes())
            args.scenes.push_back("builtin:" + std::string(info.name));
        for (const std::string& f : findSceneFiles(args.scene_dir))
            args.scenes.push_back(f);
    }

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
    const std::string tmp = (out / "runs").string();

    // Count the work for the progress line.
    size_t total = 0, done = 0;
    for (size_t s = 0; s < scenes.size(); ++s)
        for (const std::string& m : args.methods)
            total += settingsFor(m, args.quick).size();
    std::vector<uint32_t> thread_counts = {1, 2};
    for (uint32_t t = 4; t <= std::thread::hardware_concurrency(); t *= 2)
        thread_counts.push_back(t);
    if (!args.no_scaling)
        total += thread_counts.size() * args.methods.size();
    auto progress = [&](const std::string& what) {
        ++done;
        const double elapsed =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - bench_start).count();
        std::fprintf(stderr, "focal: bench [%zu/%zu %3.0fs] %s\n", done, total, elapsed,
                     what.c_str());
        std::fflush(stderr);
    };

    Json rows = Json::array();
    Json scene_info = Json::array();
    std::map<std::string, std::vector<size_t>> rows_of_scene;
    for (const BenchScene& scene : scenes) {
        std::vector<std::string> common = {scene.spec, "--width", std::to_string(args.width),
                                           "--height", std::to_string(args.height)};
        common.insert(common.end(), scene.lens.begin(), scene.lens.end());
        std::fprintf(stderr, "focal: bench: %s: reference (accum, %u views)...\n",
                     scene.spec.c_str(), args.ref_samples);
        Result<Reference> ref =
            reference(scene, common, args.ref_samples, args.threads, cache, tmp);
        if (!ref.ok())
            return fail(ref.status().message());
        const std::string ref_png = "images/" + scene.name + "_reference.png";
        if (Status s = writeImage((out / ref_png).string(), ref->color); !s.ok())
            return fail(s.message());
        scene_info.push_back({{"scene", scene.spec},
                              {"name", scene.name},
                              {"reference_key", ref->key},
                              {"reference_samples", args.ref_samples},
                              {"reference_ms", ref->ms},
                              {"reference_cached", ref->cached},
                              {"reference_png", ref_png},
                              {"band_pixels", ref->band_pixels}});

        auto runSetting = [&](const std::string& method, const Setting& setting, uint32_t threads,
                              const std::string& study) -> Result<size_t> {
            const std::string id = safeName(scene.name + "_" + method + "_" + setting.label + "_t" +
                                            std::to_string(threads));
            const std::string exr = (out / "runs" / (id + ".exr")).string();
            std::vector<std::string> a = common;
            if (method == "pinhole") // it has no lens: drop the lens options (and the warning)
                a.resize(5);
            a.insert(a.end(), {"--threads", std::to_string(threads), "--method", method, "--repeat",
                               std::to_string(args.repeat), "-o", exr});
            a.insert(a.end(), setting.args.begin(), setting.args.end());
            RenderRun r = renderInProcess(a, (out / "runs" / (id + ".json")).string());
            if (r.exit_code != 0)
                return Status::error(scene.spec + ": --method " + method + " " + setting.label +
                                     " failed");
            Result<ImageData> img = readImage(exr);
            if (!img.ok())
                return img.status();
            Json row;
            row["scene"] = scene.spec;
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
            addMetrics(row, "", dof::compareImages(refOf(*img), refOf(ref->color)));
            row["band_pixels"] = ref->band_pixels;
            if (ref->band_pixels > 0)
                addMetrics(row, "band_",
                           dof::compareImages(refOf(*img), refOf(ref->color), &ref->band));
            else
                addMetrics(row, "band_", Status::error("no band"));
            row["reference_samples"] = args.ref_samples;
            row["reference_key"] = ref->key;
            std::string opts;
            for (const std::string& o : setting.args)
                opts += (opts.empty() ? "" : " ") + o;
            row["render_options"] = opts;
            addParams(row, r.stats);
            // Scene load, kept apart from the render's time (--stats' load.time_ms.total).
            row["load_ms"] = r.stats.value(Json::json_pointer("/load/time_ms/total"), 0.0);
            // Whole-process time of the same render (not for pinhole: it has no equal-error
            // ratio).
            if (study == "main" && method != "pinhole" && args.process_repeat > 0) {
                std::vector<std::string> p = common;
                p.insert(p.end(),
                         {"--threads", std::to_string(threads), "--method", method, "-o",
                          (out / "runs" / (id + "_process.exr")).string(), "--no-progress"});
                p.insert(p.end(), setting.args.begin(), setting.args.end());
                std::vector<double> ms;
                for (uint32_t k = 0; k < args.process_repeat; ++k)
                    if (const double t = timeRenderProcess(p); std::isfinite(t))
                        ms.push_back(t);
                if (ms.size() < args.process_repeat)
                    std::fprintf(stderr,
                                 "focal: bench: %s %s %s: %zu of %u render processes "
                                 "failed\n",
                                 scene.spec.c_str(), method.c_str(), setting.label.c_str(),
                                 args.process_repeat - ms.size(), args.process_repeat);
                row["process_ms_median"] = ms.empty() ? Json() : Json(median(ms));
                row["process_runs"] = ms.size();
            }
            if (study == "main") {
                const std::string png = "images/" + id + ".png";
                const std::string diff = "images/" + id + "_diff.png";
                ImageData d{img->width, img->height, 3,
                            dof::falseColorDifference(refOf(*img), refOf(ref->color), kDiffScale)};
                if (Status s = writeImage((out / png).string(), *img); !s.ok())
                    return s;
                if (Status s = writeImage((out / diff).string(), d); !s.ok())
                    return s;
                row["image"] = png;
                row["diff_image"] = diff;
            }
            rows.push_back(row);
            progress(scene.name + " " + method + " " + setting.label + " threads=" +
                     std::to_string(threads) + ": " + fmt("%.1f ms", row["ms_median"]) +
                     (row.contains("process_ms_median") && row["process_ms_median"].is_number()
                          ? fmt(" (process %.1f ms)", row["process_ms_median"])
                          : std::string()) +
                     ", PSNR " +
                     (row["psnr_srgb_db"].is_number() ? fmt("%.2f dB", row["psnr_srgb_db"])
                                                      : std::string("inf")));
            return rows.size() - 1;
        };

        for (const std::string& method : args.methods)
            for (const Setting& setting : settingsFor(method, args.quick)) {
                Result<size_t> i = runSetting(method, setting, args.threads, "main");
                if (!i.ok()) {
                    // One failing setting (e.g. a method's capacity limit on a big scene) is a
                    // result too: record it and go on with the others.
                    std::fprintf(stderr, "focal: bench: %s %s %s failed: %s\n", scene.spec.c_str(),
                                 method.c_str(), setting.label.c_str(),
                                 i.status().message().c_str());
                    rows.push_back(Json{{"scene", scene.spec},
                                        {"study", "failed"},
                                        {"method", method},
                                        {"setting", setting.label},
                                        {"error", i.status().message()}});
                    ++done;
                    continue;
                }
                rows_of_scene[scene.spec].push_back(*i);
            }
        markPareto(rows, rows_of_scene[scene.spec]);

        // Thread scaling on the first scene: each method's first setting at 1, 2, 4... threads.
        if (!args.no_scaling && &scene == &scenes.front())
            for (const std::string& method : args.methods)
                for (uint32_t t : thread_counts) {
                    Result<size_t> i = runSetting(
                        method, studySetting(method, args.quick, &Setting::scaling), t, "scaling");
                    if (!i.ok())
                        return fail(i.status().message());
                }
    }

    // Speed-up at equal error over accum, per scene, target and layered method.
    std::vector<std::string> layered;
    for (const std::string& m : args.methods)
        if (m != "pinhole" && m != "accum")
            layered.push_back(m);
    Json equal_error = {{"definition", kEqualErrorDefinition}, {"targets", Json::array()}};
    for (const ErrorTarget& t : kErrorTargets)
        equal_error["targets"].push_back(
            {{"target", t.label}, {"metric", t.metric}, {"value", t.value}});
    equal_error["methods"] = layered;
    equal_error["process_repeat"] = args.process_repeat;
    Json equal_scenes = Json::array();
    const bool have_accum =
        std::find(args.methods.begin(), args.methods.end(), "accum") != args.methods.end();
    if (have_accum && !layered.empty())
        for (const BenchScene& scene : scenes) {
            Json e = equalErrorOfScene(scene.spec, rows, rows_of_scene[scene.spec], layered);
            e["name"] = scene.name;
            equal_scenes.push_back(e);
        }
    else
        equal_error["note"] = "needs accum and at least one layered method in --methods";
    equal_error["scenes"] = equal_scenes;
    const Table equal_table = equalErrorTable(equal_scenes, layered);
    const std::string equal_title =
        "Speed-up over accum at equal error (" + std::to_string(args.width) + "x" +
        std::to_string(args.height) + ", " + std::to_string(args.threads) +
        " threads, reference accum " + std::to_string(args.ref_samples) + " views)";

    // Parallel efficiency t1 / (n * tn) of the scaling rows.
    std::map<std::string, double> t1;
    for (const auto& row : rows)
        if (row["study"] == "scaling" && row["threads"] == 1)
            t1[row["method"].get<std::string>()] = row["ms_median"].get<double>();
    for (auto& row : rows)
        if (row["study"] == "scaling") {
            const double base = t1[row["method"].get<std::string>()];
            const double tn = row["ms_median"].get<double>();
            const double n = row["threads"].get<double>();
            row["speedup"] = tn > 0 ? base / tn : 0.0;
            row["parallel_efficiency"] = tn > 0 ? base / (n * tn) : 0.0;
        }

    // Temporal stability on the first scene: K frames of a focus pull (d_f from 0.85x to 1.15x)
    // with the eye moving sideways by 2% of the focus distance in total. Flicker of a sequence
    // = mean over frame pairs of the mean |I_k - I_k-1| (linear RGB); the excess flicker
    // compares each method's frame differences with the reference's.
    Json temporal = Json::array();
    if (args.temporal_frames >= 2 && !scenes.empty()) {
        const BenchScene& scene = scenes.front();
        const raster::View& v = scene.view;
        const uint32_t k_frames = args.temporal_frames;
        auto frameArgs = [&](uint32_t k) {
            const float t = float(k) / float(k_frames - 1);
            const float df = scene.focus_distance * (0.85f + 0.3f * t);
            const glm::vec3 eye = v.eye + v.right * (0.02f * scene.focus_distance * t);
            const glm::vec3 target = eye + v.forward * scene.focus_distance;
            auto vec = [](glm::vec3 p) { return num(p.x) + "," + num(p.y) + "," + num(p.z); };
            return std::vector<std::string>{scene.spec,
                                            "--width",
                                            std::to_string(args.width),
                                            "--height",
                                            std::to_string(args.height),
                                            "--eye",
                                            vec(eye),
                                            "--target",
                                            vec(target),
                                            "--up",
                                            vec(v.up),
                                            "--yfov",
                                            num(v.yfov * 180.0f / kPi),
                                            "--aperture-radius",
                                            num(scene.aperture_radius),
                                            "--focus-distance",
                                            num(df)};
        };
        std::vector<ImageData> ref_frames;
        for (uint32_t k = 0; k < k_frames; ++k) {
            std::fprintf(stderr, "focal: bench: temporal reference frame %u/%u\n", k + 1, k_frames);
            Result<Reference> r =
                reference(scene, frameArgs(k), args.temporal_ref_samples, args.threads, cache, tmp);
            if (!r.ok())
                return fail(r.status().message());
            ref_frames.push_back(std::move(r->color));
        }
        auto meanAbs = [](const ImageData& a, const ImageData& b) {
            double sum = 0.0;
            const size_t n = size_t(a.width) * a.height;
            for (size_t i = 0; i < n; ++i)
                for (uint32_t c = 0; c < 3; ++c)
                    sum += std::fabs(double(a.pixels[i * a.channels + c]) -
                                     double(b.pixels[i * b.channels + c]));
            return sum / double(3 * n);
        };
        auto excess = [](const ImageData& a0, const ImageData& a1, const ImageData& r0,
                         const ImageData& r1) {
            double sum = 0.0;
            const size_t n = size_t(a0.width) * a0.height;
            for (size_t i = 0; i < n; ++i)
                for (uint32_t c = 0; c < 3; ++c) {
                    const size_t j = i * a0.channels + c, q = i * r0.channels + c;
                    sum += std::fabs((double(a1.pixels[j]) - double(a0.pixels[j])) -
                                     (double(r1.pixels[q]) - double(r0.pixels[q])));
                }
            return sum / double(3 * n);
        };
        double ref_flicker = 0.0;
        for (uint32_t k = 1; k < k_frames; ++k)
            ref_flicker += meanAbs(ref_frames[k], ref_frames[k - 1]);
        ref_flicker /= double(k_frames - 1);
        for (const std::string& method : args.methods) {
            // The most accurate setting, except accum's N = 16 (its best would be the
            // temporal reference itself).
            const Setting setting = studySetting(method, args.quick, &Setting::temporal);
            std::vector<ImageData> frames;
            double psnr_sum = 0.0;
            for (uint32_t k = 0; k < k_frames; ++k) {
                const std::string exr =
                    (out / "runs" / ("temporal_" + safeName(method) + ".exr")).string();
                std::vector<std::string> a = frameArgs(k);
                if (method == "pinhole")
                    a.resize(a.size() - 4); // no lens: drop --aperture-radius, --focus-distance
                a.insert(a.end(), {"--threads", std::to_string(args.threads), "--method", method,
                                   "-o", exr});
                a.insert(a.end(), setting.args.begin(), setting.args.end());
                RenderRun r = renderInProcess(a, (out / "runs" / "temporal_stats.json").string());
                if (r.exit_code != 0)
                    return fail(scene.spec + ": temporal frame of " + method + " failed");
                Result<ImageData> img = readImage(exr);
                if (!img.ok())
                    return fail(img.status().message());
                Result<dof::ErrorMetrics> m = dof::compareImages(refOf(*img), refOf(ref_frames[k]));
                psnr_sum += m.ok() && std::isfinite(m->psnr_srgb_db) ? m->psnr_srgb_db : 100.0;
                frames.push_back(std::move(*img));
            }
            double flicker = 0.0, extra = 0.0;
            for (uint32_t k = 1; k < k_frames; ++k) {
                flicker += meanAbs(frames[k], frames[k - 1]);
                extra += excess(frames[k - 1], frames[k], ref_frames[k - 1], ref_frames[k]);
            }
            flicker /= double(k_frames - 1);
            extra /= double(k_frames - 1);
            temporal.push_back({{"scene", scene.spec},
                                {"method", method},
                                {"setting", setting.label},
                                {"frames", k_frames},
                                {"reference_samples", args.temporal_ref_samples},
                                {"flicker", flicker},
                                {"reference_flicker", ref_flicker},
                                {"flicker_ratio", ref_flicker > 0 ? flicker / ref_flicker : 0.0},
                                {"excess_flicker", extra},
                                {"mean_psnr_srgb_db", psnr_sum / double(k_frames)}});
            std::fprintf(stderr, "focal: bench: temporal %s: flicker %.5f (reference %.5f)\n",
                         method.c_str(), flicker, ref_flicker);
        }
    }

    // Plots.
    std::string plot_note;
    const bool plots = !args.no_plots && haveGnuplot();
    if (args.no_plots)
        plot_note = "plots skipped (--no-plots)";
    else if (!plots)
        plot_note = "gnuplot not found: plots skipped (apt-get install gnuplot-nox)";
    for (const BenchScene& scene : scenes)
        if (plots)
            if (Status s = plotScene(
                    out.string(), scene.name, rows, rows_of_scene[scene.spec], args.methods,
                    scene.spec + ", " + std::to_string(args.width) + "x" +
                        std::to_string(args.height) + ", " + std::to_string(args.threads) +
                        " threads, reference " + std::to_string(args.ref_samples) + " views");
                !s.ok()) {
                plot_note = s.message();
                break;
            }
    if (!plot_note.empty())
        std::fprintf(stderr, "focal: bench: %s\n", plot_note.c_str());

    // results.csv / results.json.
    const double elapsed_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - bench_start).count();
    Json doc;
    doc["focal_bench"] = 1;
    doc["quick"] = args.quick;
    doc["width"] = args.width;
    doc["height"] = args.height;
    doc["threads"] = args.threads;
    doc["hardware_threads"] = std::thread::hardware_concurrency();
    doc["repeat"] = args.repeat;
    doc["reference_samples"] = args.ref_samples;
    doc["reference_note"] = args.ref_samples < 1024
                                ? "reference below 1024 views: a smoke test, not a result"
                                : "reference of at least 1024 views";
    doc["peak_rss_note"] =
        "peak_rss_mib: VmHWM of the bench process (process-wide: includes the bench's own "
        "images), reset before each run through /proc/self/clear_refs (scope 'run'; 'process' = "
        "reset refused, peak since start); peak_rss_added_mib: that peak minus VmRSS before the "
        "run, i.e. what the run (scene load included) added";
    doc["elapsed_s"] = elapsed_s;
    doc["scenes"] = scene_info;
    doc["rows"] = rows;
    doc["temporal"] = temporal;
    doc["equal_error"] = equal_error;
    if (!plot_note.empty())
        doc["plot_note"] = plot_note;
    if (Status s = writeTextFile((out / "results.json").string(), doc.dump(2) + "\n"); !s.ok())
        return fail(s.message());
    if (Status s = writeTextFile((out / "results.csv").string(), toCsv(rows)); !s.ok())
        return fail(s.message());
    if (Status s = writeTextFile((out / "temporal.csv").string(), toCsv(temporal)); !s.ok())
        return fail(s.message());
    const std::string equal_md = markdownTable(equal_table);
    if (Status s = writeTextFile((out / "equal_error.md").string(),
                                 equal_title + ".\n\n" + kEqualErrorDefinition + "\n\n" + equal_md);
        !s.ok())
        return fail(s.message());

    // index.html: per scene the plot, the reference and each method's best image within a few
    // time budgets (geometric steps between the fastest and slowest main run) with its
    // difference image.
    std::string html = "<!doctype html><html><head><meta charset='utf-8'><title>focal bench"
                       "</title><style>body{font-family:sans-serif}td{vertical-align:top;"
                       "text-align:center;font-size:12px}img{image-rendering:pixelated}"
                       "</style></head><body><h1>focal bench</h1>";
    html += "<p>" + std::to_string(args.width) + "x" + std::to_string(args.height) + ", " +
            std::to_string(args.threads) + " threads, " + std::to_string(args.repeat) +
            " runs per setting, reference: accum with " + std::to_string(args.ref_samples) +
            " views" + (args.ref_samples < 1024 ? " (<b>below 1024: smoke test only</b>)" : "") +
            ". Results: <a href='results.csv'>results.csv</a>, <a href='results.json'>"
            "results.json</a>, <a href='temporal.csv'>temporal.csv</a>.</p>";
    if (!plot_note.empty())
        html += "<p>" + htmlEscape(plot_note) + "</p>";
    if (!equal_scenes.empty())
        html += "<h2>" + htmlEscape(equal_title) + "</h2><p>" + htmlEscape(kEqualErrorDefinition) +
                "</p>" + htmlTable(equal_table);
    for (const BenchScene& scene : scenes) {
        const std::vector<size_t>& idx = rows_of_scene[scene.spec];
        html += "<h2>" + htmlEscape(scene.spec) + "</h2>";
        if (plots)
            html += "<p><img src='plots/bench_" + scene.name + ".png' width='720'></p>";
        double tmin = 1e300, tmax = 0.0;
        for (size_t i : idx) {
            tmin = std::min(tmin, rows[i]["ms_median"].get<double>());
            tmax = std::max(tmax, rows[i]["ms_median"].get<double>());
        }
        std::vector<double> budgets;
        for (int b = 0; b < 3 && !idx.empty(); ++b)
            budgets.push_back(tmin * std::pow(tmax / std::max(tmin, 1e-9), (b + 1) / 3.0) * 1.0001);
        html += "<table><tr><th>budget</th><th>reference</th>";
        for (const std::string& m : args.methods)
            html += "<th>" + m + "</th>";
        html += "</tr>";
        for (double budget : budgets) {
            html += "<tr><td>&le; " + fmt("%.1f", budget) + " ms</td><td><img src='images/" +
                    scene.name + "_reference.png'></td>";
            for (const std::string& m : args.methods) {
                const Json* best = nullptr;
                for (size_t i : idx)
                    if (rows[i]["method"] == m && rows[i]["ms_median"].get<double>() <= budget &&
                        (!best || psnrOf(rows[i]) > psnrOf(*best)))
                        best = &rows[i];
                if (!best) {
                    html += "<td>over budget</td>";
                    continue;
                }
                html +=
                    "<td><img src='" + (*best)["image"].get<std::string>() + "'><br><img src='" +
                    (*best)["diff_image"].get<std::string>() + "'><br>" +
                    htmlEscape((*best)["setting"].get<std::string>()) + ", " +
                    fmt("%.1f ms", (*best)["ms_median"]) + ", " +
                    ((*best)["psnr_srgb_db"].is_number() ? fmt("%.2f dB", (*best)["psnr_srgb_db"])
                                                         : std::string("exact")) +
                    "</td>";
            }
            html += "</tr>";
        }
        html += "</table>";
    }
    if (!temporal.empty()) {
        html += "<h2>Temporal stability (" + htmlEscape(scenes.front().spec) +
                ")</h2><table border='1'><tr><th>method</th><th>setting</th><th>flicker</th>"
                "<th>reference flicker</th><th>ratio</th><th>excess</th><th>mean PSNR</th></tr>";
        for (const auto& t : temporal)
            html += "<tr><td>" + t["method"].get<std::string>() + "</td><td>" +
                    htmlEscape(t["setting"].get<std::string>()) + "</td><td>" +
                    fmt("%.5f", t["flicker"]) + "</td><td>" + fmt("%.5f", t["reference_flicker"]) +
                    "</td><td>" + fmt("%.2f", t["flicker_ratio"]) + "</td><td>" +
                    fmt("%.5f", t["excess_flicker"]) + "</td><td>" +
                    fmt("%.2f", t["mean_psnr_srgb_db"]) + "</td></tr>";
        html += "</table>";
    }
    html += "</body></html>\n";
    if (Status s = writeTextFile((out / "index.html").string(), html); !s.ok())
        return fail(s.message());
    if (!equal_scenes.empty())
        std::printf("%s\n%s\n", equal_title.c_str(), equal_md.c_str());
    std::printf("focal: bench wrote %zu rows to %s (results.csv, results.json, equal_error.md, "
                "index.html) in %.1f s\n",
                rows.size(), out.string().c_str(), elapsed_s);
    return 0;
}

} // namespace focal
