// The rows of `focal bench`'s results: one JSON object per run (scene, study, method, setting,
// times, memory, error metrics, the render's parameters), the Pareto front and thread-scaling
// columns added over all rows, and the CSV form of any row list. Pure functions over JSON values
// the caller owns.
#pragma once

#include <dof/metrics.h>
#include <raster/status.h>

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace focal {

// The bench's JSON: keys kept in insertion order, so files read in the order they were built.
using Json = nlohmann::ordered_json;

// A finite number, else null (JSON has no NaN or infinity).
Json jsonNumber(double v);

// Flattens a `focal render --stats` document's lens, samples, method parameters (param_*) and
// triangle count into row columns.
void addParams(Json& row, const Json& stats);

// The runs' total times (ms_median, ms_min, ms_max) and the median stage times (stage_ms_*).
void addTimes(Json& row, const Json& stats);

// PREFIXpsnr_srgb_db, PREFIXpsnr_linear_db, PREFIXssim, PREFIXmean_abs_error; nulls on failure.
void addMetrics(Json& row, const std::string& prefix, const raster::Result<dof::ErrorMetrics>& m);

// The row's sRGB PSNR; 200 dB (off the scale) when it is identical to the reference.
double psnrOf(const Json& row);

// Marks `pareto` on the rows `idx`: true when no other of them is both faster and more accurate.
void markPareto(Json& rows, const std::vector<size_t>& idx);

// speedup = t1 / tn and parallel_efficiency = t1 / (n tn) on the rows of the scaling study.
void addScalingEfficiency(Json& rows);

// Every row as a CSV line under one header: the union of the rows' keys in first-seen order.
std::string toCsv(const Json& rows);

} // namespace focal
