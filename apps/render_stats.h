// `focal render --stats FILE`: every parameter a render used, where its lens came from, stage
// times (ms; per run and the median of --repeat runs) and counts, as JSON (docs/stats-schema.md).
// Consumes the command's arguments and what the frames reported (all caller-owned); writes the
// file atomically.
#pragma once

#include "apps/dof_method.h"
#include "apps/render_command.h"
#include "apps/render_request.h"

#include <dof/accum.h>
#include <dof/frame_renderer.h>
#include <dof/lens_resolution.h>
#include <raster/gltf_import.h>
#include <raster/status.h>

#include <nlohmann/json.hpp>

#include <string>
#include <utility>
#include <vector>

namespace focal {

// The stats' names of where the lens values came from ("cli", "fstop", ... "focus-pixel").
const char* apertureSourceName(dof::ApertureSource source);
const char* focusSourceName(dof::FocusSource source);

// The times of `--repeat K` runs: each run's and their medians.
class RunTimes {
public:
    // One run: its wall time, the renderer's stage times summed over its Renderer::render calls
    // and the frame's method stages.
    void add(double total_ms, const raster::FrameStats& renders, const dof::FrameReport& report);
    double medianTotal() const;
    nlohmann::json medians() const; // total, geometry, binning, raster, then each method stage
    const nlohmann::json& runs() const { return runs_; }

private:
    std::vector<double> totals_, geometry_, binning_, raster_;
    std::vector<std::pair<std::string, std::vector<double>>> stages_;
    nlohmann::json runs_ = nlohmann::json::array();
};

// What one `focal render` did, for the stats file.
struct RenderRecord {
    const RenderArgs& args;
    const raster::View& view;
    const dof::LensRequest& request;
    const dof::ResolvedLens& lens;
    const dof::ApertureShape& aperture;
    const RunTimes& times;
    const raster::ImportStats& load;
    const raster::FrameStats& counts;       // the last Renderer::render call's
    const dof::AccumStats* accum = nullptr; // --method accum
    const MethodOutput* method = nullptr;   // the table's methods
    TargetStorage targets;                  // the table's methods
    nlohmann::json target_stats;            // --dump-layers / --dump-fragments
};

// The --stats object of a render (docs/stats-schema.md), and its file.
nlohmann::json renderStatsJson(const RenderRecord& record);
raster::Status writeRenderStats(const std::string& path, const nlohmann::json& stats);

} // namespace focal
