// `focal bench`'s plots: per scene, median time (log x) against sRGB PSNR, one point style per
// method, min-max time as error bars, the Pareto front as a line. Consumes the result rows;
// writes DIR/plots/bench_<scene>.{dat,gp,png,log} through gnuplot.
#pragma once

#include "apps/bench_rows.h"

#include <raster/status.h>

#include <cstddef>
#include <string>
#include <vector>

namespace focal {

// True when a gnuplot program is on the PATH.
bool haveGnuplot();

// Plots the main rows `idx` of `rows` (one scene's) for `methods` under `title`.
raster::Status plotScene(const std::string& dir, const std::string& scene, const Json& rows,
                         const std::vector<size_t>& idx, const std::vector<std::string>& methods,
                         const std::string& title);

} // namespace focal
