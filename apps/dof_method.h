// How `focal render --method NAME` runs a depth-of-field method that lives in dof/: each method
// adds its own options to the render command, turns them into its dof::MethodSettings and, after
// each frame rendered by dof::FrameRenderer, writes its --stats parameters and counts and its
// debug files. Each `focal render` command line makes its own table of methods
// (makeMethodTable, apps/methods.cpp: one line per method), which holds that command line's option
// values; render_command.cpp dispatches through it.
#pragma once

#include <dof/frame_renderer.h>
#include <dof/lens_samples.h>
#include <raster/camera.h>
#include <raster/renderer.h>
#include <raster/status.h>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace focal {

// What every method's options are turned into settings with: the pinhole view through the lens
// centre, the lens samples shared with accum (--samples, --lens-pattern, --aperture-shape/
// -blades/-rotation/-image, --seed) and the raster options (--tile, --depth-format, --shading,
// --texture-filter, --no-simd, --memory-budget).
struct MethodContext {
    const raster::View& view;
    const dof::LensSampleSet& lens_samples;
    const raster::RenderOptions& options;
    // Storage of the layered target / fragment lists (--precision 16|32, --target-color,
    // --target-depth); unset: the method's own default (e.g. Selgrad et al.: half colour, float
    // depth).
    std::optional<raster::ColorFormat> target_color;
    std::optional<raster::DepthFormat> target_depth;
};

// What a method records in --stats for one frame.
struct MethodOutput {
    nlohmann::json params; // every parameter the method used
    nlohmann::json counts; // method-specific counters
};

struct MethodEntry {
    std::string name;
    std::string summary; // one line for --help
    // Adds the method's options to `focal render`: its settings table's
    // (apps/settings_options.h) and its files. The values live in an args object the entry owns.
    std::function<void(CLI::App& render)> add_options;
    // The settings of one frame from the options; fails on values the parser cannot judge. The
    // settings may point into the entry's args object (kept until the next call).
    std::function<raster::Result<dof::MethodSettings>(const MethodContext&)> settings;
    // After a frame rendered with those settings into `rgba` (linear RGBA, view-sized): the
    // --stats parameters and counts, and the method's extra files (debug pictures, level images).
    std::function<raster::Status(const MethodContext&, const dof::MethodSettings&,
                                 const dof::FrameRenderer&, const dof::FrameReport&,
                                 const std::vector<float>& rgba, MethodOutput&)>
        finish;
    // Optional: a lower bound of the bytes a run holds for `view` with `samples` lens samples on
    // `workers` workers, checked against --memory-budget before anything is rendered.
    std::function<uint64_t(const raster::View& view, uint32_t samples, uint32_t workers)>
        minimum_bytes;
};

// The methods beyond pinhole and accum, in a fixed order, each with fresh option values.
std::vector<MethodEntry> makeMethodTable();

// Every `--method` name: pinhole and accum, then the table's methods in order.
std::vector<std::string> methodNames();

// The entry of `table` for `name`; null for pinhole, accum and unknown names.
const MethodEntry* findMethod(const std::vector<MethodEntry>& table, const std::string& name);

} // namespace focal
