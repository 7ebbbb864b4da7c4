// `focal compare A B`: error metrics between two images (dof/metrics.h) over all pixels and,
// with a depth image, over the band of pixels near depth discontinuities; optional false-colour
// difference image. Text report on stdout, or JSON with --json.
#pragma once

#include <CLI/CLI.hpp>

#include <string>

namespace focal {

struct CompareArgs {
    std::string a;
    std::string b;
    std::string depth; // linear depth EXR (focal render --depth-out)
    std::string diff;  // false-colour difference image to write
    bool json = false;
    float band_threshold = 0.05f; // relative depth jump that makes an edge
    float band_radius = 4.0f;     // band half-width in pixels
    float diff_scale = 0.1f;      // sRGB difference that saturates the false colour
};

// Registers the subcommand; `args` must outlive parsing.
CLI::App* addCompareCommand(CLI::App& app, CompareArgs& args);

// Runs it; returns the exit code (errors are printed).
int runCompare(const CompareArgs& args);

} // namespace focal
