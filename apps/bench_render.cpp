#include "apps/bench_render.h"

#include "apps/render_command.h"
#include "apps/settings_options.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <limits>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

namespace focal {

namespace {

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

// Parses `focal render ARGS --no-progress -o -` into `ra`; the -o is dropped after parsing (CLI11
// requires one; the bench keeps images in memory).
bool parseRenderArgs(const std::vector<std::string>& args, CLI::App& app, RenderArgs& ra) {
    addRenderCommand(app, ra);
    std::vector<std::string> argv = {"render"};
    argv.insert(argv.end(), args.begin(), args.end());
    argv.insert(argv.end(), {"--no-progress", "-o", "-"});
    std::reverse(argv.begin(), argv.end()); // CLI11 parses a vector back to front
    try {
        app.parse(argv);
    } catch (const CLI::ParseError& e) {
        std::fprintf(stderr, "focal: error: bench made a bad render command: %s\n", e.what());
        return false;
    }
    ra.outputs.clear();
    return true;
}

} // namespace

RenderRun renderInMemory(const std::vector<std::string>& args, const LoadedScene* scene) {
    RenderRun r;
    CLI::App app;
    RenderArgs ra;
    if (!parseRenderArgs(args, app, ra)) {
        r.exit_code = 2;
        return r;
    }
    if (!resetPeakRss())
        r.peak_scope = "process";
    r.start_rss_mib = statusMiB("VmRSS:");
    raster::Result<RenderedFrame> frame = renderFrame(ra, scene);
    r.peak_rss_mib = statusMiB("VmHWM:");
    if (!frame.ok()) {
        std::fprintf(stderr, "focal: error: %s\n",
                     withOptionNames(frame.status().message()).c_str());
        r.exit_code = 1;
        return r;
    }
    r.image = ImageData{frame->width, frame->height, 4, std::move(frame->color)};
    if (!frame->depth.empty())
        r.depth = ImageData{frame->width, frame->height, 1, std::move(frame->depth)};
    r.stats = nlohmann::ordered_json(frame->stats); // the same keys, in the same (sorted) order
    return r;
}

raster::Result<LoadedScene> loadBenchScene(const std::vector<std::string>& args) {
    CLI::App app;
    RenderArgs ra;
    if (!parseRenderArgs(args, app, ra))
        return raster::Status::error("bench made a bad render command");
    return loadSceneFor(ra);
}

double timeRenderProcess(const std::vector<std::string>& args) {
    constexpr double kFailed = std::numeric_limits<double>::quiet_NaN();
    std::error_code ec;
    const std::string exe = std::filesystem::read_symlink("/proc/self/exe", ec).string();
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

} // namespace focal
