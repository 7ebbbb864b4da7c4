#include "apps/bench_rows.h"

#include "apps/report_text.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

namespace focal {

Json jsonNumber(double v) {
    return std::isfinite(v) ? Json(v) : Json();
}

void addParams(Json& row, const Json& stats) {
    if (stats.contains("lens")) {
        const auto& l = stats["lens"];
        row["aperture_radius"] = l.value("aperture_radius", 0.0);
        row["focus_distance"] = l.value("focus_distance", 0.0);
        row["coc_at_infinity_px"] = l.value("coc_at_infinity_px", 0.0);
        row["lens_pattern"] = l.value("lens_pattern", std::string());
    }
    if (stats.contains("accum"))
        row["samples"] = stats["accum"].value("samples", 0);
    else if (stats.contains("lens") && stats["lens"].contains("samples"))
        row["samples"] = stats["lens"]["samples"];
    if (stats.contains("params") && stats["params"].is_object())
        for (const auto& [k, v] : stats["params"].items())
            if (v.is_primitive())
                row["param_" + k] = v;
    if (stats.contains("triangles"))
        row["triangles_in"] = stats["triangles"].value("in", 0);
}

void addTimes(Json& row, const Json& stats) {
    std::vector<double> totals;
    for (const auto& run : stats["runs"])
        totals.push_back(run.value("total", 0.0));
    row["ms_median"] = median(totals);
    row["ms_min"] = totals.empty() ? 0.0 : *std::min_element(totals.begin(), totals.end());
    row["ms_max"] = totals.empty() ? 0.0 : *std::max_element(totals.begin(), totals.end());
    for (const auto& [stage, ms] : stats["time_ms"].items())
        if (stage != "total")
            row["stage_ms_" + stage] = ms;
}

void addMetrics(Json& row, const std::string& prefix, const raster::Result<dof::ErrorMetrics>& m) {
    if (!m.ok()) {
        row[prefix + "psnr_srgb_db"] = nullptr;
        row[prefix + "psnr_linear_db"] = nullptr;
        row[prefix + "ssim"] = nullptr;
        row[prefix + "mean_abs_error"] = nullptr;
        return;
    }
    row[prefix + "psnr_srgb_db"] = jsonNumber(m->psnr_srgb_db);
    row[prefix + "psnr_linear_db"] = jsonNumber(m->psnr_linear_db);
    row[prefix + "ssim"] = jsonNumber(m->ssim);
    row[prefix + "mean_abs_error"] = m->mean_abs_error;
}

double psnrOf(const Json& row) {
    const Json& p = row["psnr_srgb_db"];
    return p.is_number() ? p.get<double>() : 200.0;
}

void markPareto(Json& rows, const std::vector<size_t>& idx) {
    std::vector<size_t> order = idx;
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
        const double ta = rows[a]["ms_median"], tb = rows[b]["ms_median"];
        return ta != tb ? ta < tb : psnrOf(rows[a]) > psnrOf(rows[b]);
    });
    double best = -1e300;
    for (size_t i : order) {
        const bool front = psnrOf(rows[i]) > best;
        rows[i]["pareto"] = front;
        if (front)
            best = psnrOf(rows[i]);
    }
}

void addScalingEfficiency(Json& rows) {
    std::map<std::string, double> t1;
    for (const auto& row : rows)
        if (row["study"] == "scaling" && row["threads"] == 1)
            t1[row["method"].get<std::string>()] = row["ms_median"].get<double>();
    for (auto& row : rows)
        if (row["study"] == "scaling") {
            const double base = t1[row["method"].get<std::string>()];
            const double tn = row["ms_median"].get<double>();
            const double n = row["threads"].get<double>();
            row["speedup"] = tn > 0 ? base / tn : 0.0;
            row["parallel_efficiency"] = tn > 0 ? base / (n * tn) : 0.0;
        }
}

namespace {

std::string csvCell(const Json& v) {
    if (v.is_null())
        return "";
    if (v.is_boolean())
        return v.get<bool>() ? "1" : "0";
    // Strings as they are, anything else (numbers, arrays) as JSON; quoted when it holds a
    // comma, a quote or a line break.
    const std::string s = v.is_string() ? v.get<std::string>() : v.dump();
    if (s.find_first_of(",\"\n") == std::string::npos)
        return s;
    std::string q = "\"";
    for (char c : s)
        q += c == '"' ? std::string("\"\"") : std::string(1, c);
    return q + "\"";
}

} // namespace

std::string toCsv(const Json& rows) {
    std::vector<std::string> columns;
    std::set<std::string> seen;
    for (const auto& row : rows)
        for (const auto& [k, v] : row.items())
            if (seen.insert(k).second)
                columns.push_back(k);
    std::string out;
    for (size_t i = 0; i < columns.size(); ++i)
        out += (i ? "," : "") + columns[i];
    out += "\n";
    for (const auto& row : rows) {
        for (size_t i = 0; i < columns.size(); ++i) {
            if (i)
                out += ",";
            if (row.contains(columns[i]))
                out += csvCell(row[columns[i]]);
        }
        out += "\n";
    }
    return out;
}

} // namespace focal
