// How `focal bench` runs one render: in-process through the `focal render` command (parse +
// runRender, stdout silenced) with its --stats JSON and peak memory, or as a whole child process
// for the user's wall time. Consumes `focal render` arguments; produces the run's outcome, owned
// by the caller. Images and stats are written where the arguments say.
#pragma once

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace focal {

// The outcome of one `focal render` call made in-process.
struct RenderRun {
    int exit_code = 0;
    nlohmann::ordered_json stats; // the --stats file, parsed
    double peak_rss_mib = 0.0;    // VmHWM after the run
    double start_rss_mib = 0.0;   // VmRSS before it: the peak minus this is what the run added
    std::string peak_scope = "run";
};

// Parses `args` as `focal render ARGS --stats STATS_PATH --no-progress` and runs it. A bad
// argument list exits 2 (printed); a stats file that does not parse counts as a failure.
RenderRun renderInProcess(const std::vector<std::string>& args, const std::string& stats_path);

// Wall time in ms of `focal render ARGS` run as a child process of this binary (/proc/self/exe),
// its stdout and stderr discarded: what a user waits for (start-up, scene load, autofocus,
// render, image write). NaN when it cannot start or fails.
double timeRenderProcess(const std::vector<std::string>& args);

} // namespace focal
