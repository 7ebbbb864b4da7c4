// How `focal bench` runs one render: in memory, through the function `focal render` is built on
// (renderFrame: one dof::FrameRenderer for the --repeat runs) with the scene loaded once, giving
// the image, the --stats object and the peak memory; or as a whole child process for the user's
// wall time. Consumes `focal render` option lists (the sweeps are spelled from the settings
// tables); produces the run's outcome, owned by the caller. Nothing is written to disk.
#pragma once

#include "apps/image_io.h"
#include "apps/render_command.h"

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace focal {

// The outcome of one render made in memory.
struct RenderRun {
    int exit_code = 0;
    ImageData image;              // linear RGBA
    ImageData depth;              // with --depth-out: the method's depth (1 channel)
    nlohmann::ordered_json stats; // what --stats would write
    double peak_rss_mib = 0.0;    // VmHWM after the run
    double start_rss_mib = 0.0;   // VmRSS before it: the peak minus this is what the run added
    std::string peak_scope = "run";
};

// Parses `args` as the options of `focal render ARGS --no-progress` (no -o: the image stays in
// memory) and renders them with renderFrame on `scene` when it was loaded for these options. A
// bad option list is exit code 2, a failed render 1 (both printed).
RenderRun renderInMemory(const std::vector<std::string>& args, const LoadedScene* scene);

// The scene of `args` (the same option list), loaded once for every run of a bench scene.
raster::Result<LoadedScene> loadBenchScene(const std::vector<std::string>& args);

// Wall time in ms of `focal render ARGS` run as a child process of this binary (/proc/self/exe),
// its stdout and stderr discarded: what a user waits for (start-up, scene load, autofocus,
// render, image write). NaN when it cannot start or fails.
double timeRenderProcess(const std::vector<std::string>& args);

} // namespace focal
