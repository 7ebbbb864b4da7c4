#include "apps/bench_results.h"

#include "apps/bench_equal_error_report.h"
#include "apps/report_text.h"
#include "apps/text_file.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <thread>

namespace focal {

namespace fs = std::filesystem;

raster::Status writeResultFiles(const BenchArgs& args, const BenchResults& results,
                                const std::string& out_dir, const double elapsed_s) {
    const fs::path out(out_dir);
    Json doc;
    doc["focal_bench"] = 1;
    doc["quick"] = args.quick;
    doc["width"] = args.width;
    doc["height"] = args.height;
    doc["threads"] = args.threads;
    doc["hardware_threads"] = std::thread::hardware_concurrency();
    doc["repeat"] = args.repeat;
    doc["reference_samples"] = args.ref_samples;
    doc["reference_note"] = args.ref_samples < 1024
                                ? "reference below 1024 views: a smoke test, not a result"
                                : "reference of at least 1024 views";
    doc["peak_rss_note"] =
        "peak_rss_mib: VmHWM of the bench process (process-wide: includes the bench's own "
        "images), reset before each run through /proc/self/clear_refs (scope 'run'; 'process' = "
        "reset refused, peak since start); peak_rss_added_mib: that peak minus VmRSS before the "
        "run, i.e. what the run (scene load included) added";
    doc["elapsed_s"] = elapsed_s;
    doc["scenes"] = results.scene_info;
    doc["rows"] = results.rows;
    doc["temporal"] = results.temporal;
    doc["equal_error"] = results.equal_error;
    if (!results.plot_note.empty())
        doc["plot_note"] = results.plot_note;
    if (raster::Status s = writeTextFile((out / "results.json").string(), doc.dump(2) + "\n");
        !s.ok())
        return s;
    if (raster::Status s = writeTextFile((out / "results.csv").string(), toCsv(results.rows));
        !s.ok())
        return s;
    if (raster::Status s = writeTextFile((out / "temporal.csv").string(), toCsv(results.temporal));
        !s.ok())
        return s;
    return writeTextFile((out / "equal_error.md").string(), results.equal_title + ".\n\n" +
                                                                kEqualErrorDefinition + "\n\n" +
                                                                markdownTable(results.equal_table));
}

namespace {

// One scene's section: its plot and, per time budget, the reference and each method's best
// image within the budget.
std::string sceneSection(const BenchArgs& args, const BenchScene& scene,
                         const BenchResults& results) {
    const Json& rows = results.rows;
    const auto found = results.rows_of_scene.find(scene.spec);
    const std::vector<size_t> idx =
        found == results.rows_of_scene.end() ? std::vector<size_t>{} : found->second;
    std::string html = "<h2>" + htmlEscape(scene.spec) + "</h2>";
    if (results.plots)
        html += "<p><img src='plots/bench_" + scene.name + ".png' width='720'></p>";
    double tmin = 1e300, tmax = 0.0;
    for (size_t i : idx) {
        tmin = std::min(tmin, rows[i]["ms_median"].get<double>());
        tmax = std::max(tmax, rows[i]["ms_median"].get<double>());
    }
    std::vector<double> budgets;
    for (int b = 0; b < 3 && !idx.empty(); ++b)
        budgets.push_back(tmin * std::pow(tmax / std::max(tmin, 1e-9), (b + 1) / 3.0) * 1.0001);
    html += "<table><tr><th>budget</th><th>reference</th>";
    for (const std::string& m : args.methods)
        html += "<th>" + m + "</th>";
    html += "</tr>";
    for (double budget : budgets) {
        html += "<tr><td>&le; " + fmt("%.1f", budget) + " ms</td><td><img src='images/" +
                scene.name + "_reference.png'></td>";
        for (const std::string& m : args.methods) {
            const Json* best = nullptr;
            for (size_t i : idx)
                if (rows[i]["method"] == m && rows[i]["ms_median"].get<double>() <= budget &&
                    (!best || psnrOf(rows[i]) > psnrOf(*best)))
                    best = &rows[i];
            if (!best) {
                html += "<td>over budget</td>";
                continue;
            }
            html += "<td><img src='" + (*best)["image"].get<std::string>() + "'><br><img src='" +
                    (*best)["diff_image"].get<std::string>() + "'><br>" +
                    htmlEscape((*best)["setting"].get<std::string>()) + ", " +
                    fmt("%.1f ms", (*best)["ms_median"]) + ", " +
                    ((*best)["psnr_srgb_db"].is_number() ? fmt("%.2f dB", (*best)["psnr_srgb_db"])
                                                         : std::string("exact")) +
                    "</td>";
        }
        html += "</tr>";
    }
    return html + "</table>";
}

std::string temporalSection(const std::string& spec, const Json& temporal) {
    std::string html = "<h2>Temporal stability (" + htmlEscape(spec) +
                       ")</h2><table border='1'><tr><th>method</th><th>setting</th><th>flicker"
                       "</th><th>reference flicker</th><th>ratio</th><th>excess</th><th>mean "
                       "PSNR</th></tr>";
    for (const auto& t : temporal)
        html += "<tr><td>" + t["method"].get<std::string>() + "</td><td>" +
                htmlEscape(t["setting"].get<std::string>()) + "</td><td>" +
                fmt("%.5f", t["flicker"]) + "</td><td>" + fmt("%.5f", t["reference_flicker"]) +
                "</td><td>" + fmt("%.2f", t["flicker_ratio"]) + "</td><td>" +
                fmt("%.5f", t["excess_flicker"]) + "</td><td>" +
                fmt("%.2f", t["mean_psnr_srgb_db"]) + "</td></tr>";
    return html + "</table>";
}

} // namespace

raster::Status writeIndexHtml(const BenchArgs& args, const std::vector<BenchScene>& scenes,
                              const BenchResults& results, const std::string& out_dir) {
    std::string html = "<!doctype html><html><head><meta charset='utf-8'><title>focal bench"
                       "</title><style>body{font-family:sans-serif}td{vertical-align:top;"
                       "text-align:center;font-size:12px}img{image-rendering:pixelated}"
                       "</style></head><body><h1>focal bench</h1>";
    html += "<p>" + std::to_string(args.width) + "x" + std::to_string(args.height) + ", " +
            std::to_string(args.threads) + " threads, " + std::to_string(args.repeat) +
            " runs per setting, reference: accum with " + std::to_string(args.ref_samples) +
            " views" + (args.ref_samples < 1024 ? " (<b>below 1024: smoke test only</b>)" : "") +
            ". Results: <a href='results.csv'>results.csv</a>, <a href='results.json'>"
            "results.json</a>, <a href='temporal.csv'>temporal.csv</a>.</p>";
    if (!results.plot_note.empty())
        html += "<p>" + htmlEscape(results.plot_note) + "</p>";
    if (!results.equal_error["scenes"].empty())
        html += "<h2>" + htmlEscape(results.equal_title) + "</h2><p>" +
                htmlEscape(kEqualErrorDefinition) + "</p>" + htmlTable(results.equal_table);
    for (const BenchScene& scene : scenes)
        html += sceneSection(args, scene, results);
    if (!results.temporal.empty())
        html += temporalSection(scenes.front().spec, results.temporal);
    html += "</body></html>\n";
    return writeTextFile((fs::path(out_dir) / "index.html").string(), html);
}

} // namespace focal
