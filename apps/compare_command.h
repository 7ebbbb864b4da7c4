// `focal compare A B`: error metrics between two images (dof/metrics.h) over all pixels and,
// with a depth image, over the band of pixels near depth discontinuities; optional false-colour
// difference image. Text report on stdout, or JSON with --json (docs/compare-schema.md).
// With thresholds (--max-abs, --min-psnr, --min-ssim, --max-differing) it is a CI gate: exit 0
// when every threshold holds, 1 when one does not (each failing metric named on stderr; images
// of different sizes also fail), 2 on usage or I/O errors; --diff is then written on failure only.
#pragma once

#include <CLI/CLI.hpp>

#include <cstdint>
#include <optional>
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
    // Gate thresholds (unset: not checked).
    std::optional<double> max_abs;         // largest |a - b| of linear RGB
    std::optional<double> min_psnr;        // linear PSNR, dB
    std::optional<double> min_ssim;        // SSIM
    std::optional<uint64_t> max_differing; // pixels differing by more than `tolerance`
    float tolerance = 0.0f;                // per channel, linear values, alpha included
    bool gated() const { return max_abs || min_psnr || min_ssim || max_differing; }
};

// Registers the subcommand; `args` must outlive parsing.
CLI::App* addCompareCommand(CLI::App& app, CompareArgs& args);

// Runs it; returns the exit code (errors are printed).
int runCompare(const CompareArgs& args);

} // namespace focal
