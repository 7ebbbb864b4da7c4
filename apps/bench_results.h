// What one `focal bench` run found, and the files that report it: results.json, results.csv,
// temporal.csv, equal_error.md and index.html in the output folder. Consumes the bench's
// arguments, scenes and results (all caller-owned); writes files only.
#pragma once

#include "apps/bench_command.h"
#include "apps/bench_rows.h"
#include "apps/bench_scene.h"
#include "apps/report_table.h"

#include <raster/status.h>

#include <cstddef>
#include <map>
#include <string>
#include <vector>

namespace focal {

struct BenchResults {
    Json rows = Json::array();       // one per run: main, scaling and failed settings
    Json scene_info = Json::array(); // per scene: its reference
    std::map<std::string, std::vector<size_t>> rows_of_scene; // main rows by scene spec
    Json temporal = Json::array();
    Json equal_error;  // the header and, under "scenes", each scene's speed-ups
    Table equal_table; // the same as a table
    std::string equal_title;
    bool plots = false;    // plots/bench_<scene>.png exist
    std::string plot_note; // why there are no plots, when there are none
};

// Writes results.json, results.csv, temporal.csv and equal_error.md into `out_dir`.
raster::Status writeResultFiles(const BenchArgs& args, const BenchResults& results,
                                const std::string& out_dir, double elapsed_s);

// Writes index.html: per scene the plot, the reference and each method's best image within a
// few time budgets (geometric steps between the fastest and slowest main run) with its
// difference image; the equal-error and temporal tables.
raster::Status writeIndexHtml(const BenchArgs& args, const std::vector<BenchScene>& scenes,
                              const BenchResults& results, const std::string& out_dir);

} // namespace focal
