// `focal steps` and `focal probe` (issue 22): the stage stepper. `steps` renders one frame with
// the render command's options and a stage observer (dof/frame_observer.h) and writes a folder
// that opens from the file system in a browser: every stage of the frame in order, the probes of
// a grid of pixels, and the result beside the accum reference (docs/steps-format.md,
// docs/steps.md). `probe` prints what made one pixel as JSON, the same object the page shows.
#pragma once

#include "apps/render_command.h"

#include <CLI/CLI.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace focal {

struct StepsArgs {
    RenderArgs render;
    std::string out_dir;
    uint32_t probe_grid = 16;         // probe every probe_grid pixels (0: none)
    std::vector<std::string> probes;  // and these "X,Y"
    uint32_t reference_samples = 256; // accum's lens samples for the side-by-side
    std::vector<std::string> command; // the command line, for the page to show
};

struct ProbeArgs {
    RenderArgs render;
    std::string pixel; // "X,Y"
};

CLI::App* addStepsCommand(CLI::App& app, StepsArgs& args);
CLI::App* addProbeCommand(CLI::App& app, ProbeArgs& args);

// Run them; return the exit code (errors are printed).
int runSteps(StepsArgs& args);
int runProbe(ProbeArgs& args);

} // namespace focal
