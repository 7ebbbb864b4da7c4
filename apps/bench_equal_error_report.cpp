#include "apps/bench_equal_error_report.h"

#include "apps/equal_error.h"
#include "apps/report_text.h"

#include <limits>
#include <span>

namespace focal {

const char* const kEqualErrorDefinition =
    "Speed-up at equal error = accum's time to reach the target / the time of the method's "
    "cheapest setting that reaches it (full-frame SSIM or sRGB PSNR against the reference). "
    "accum's time: the metric's running maximum over increasing N, interpolated linearly in "
    "log2 N between the two sweep settings that bracket the target; the time at that N "
    "interpolated linearly in N between them. '>x': accum never reached the target (its largest "
    "N's time is a lower bound); '<=x': accum's smallest N already reaches it (an upper bound). "
    "render = the render's own median time (scene load excluded); process = median wall time "
    "of a whole `focal render` process (start-up, load, render, image write).";

namespace {

// The issue-18 error targets: full-frame SSIM and sRGB PSNR against the reference.
struct ErrorTarget {
    const char* label;
    const char* metric; // a results.json row column
    double value;
};
constexpr ErrorTarget kErrorTargets[] = {{"SSIM 0.97", "ssim", 0.97},
                                         {"SSIM 0.98", "ssim", 0.98},
                                         {"PSNR 35 dB", "psnr_srgb_db", 35.0},
                                         {"PSNR 40 dB", "psnr_srgb_db", 40.0}};

// A main row as a sweep point for `metric`. A null metric with a number SSIM is +inf
// (identical to the reference); a null SSIM is a failed comparison (NaN: ignored).
SweepPoint sweepPointOf(const Json& row, const std::string& metric) {
    SweepPoint p;
    p.setting = row["setting"].get<std::string>();
    const auto samples = row.find("samples");
    p.samples = samples != row.end() && samples->is_number() ? samples->get<double>() : 0.0;
    p.render_ms = row["ms_median"].get<double>();
    const auto process = row.find("process_ms_median");
    p.process_ms = process != row.end() && process->is_number()
                       ? process->get<double>()
                       : std::numeric_limits<double>::quiet_NaN();
    const Json& v = row[metric];
    p.value = v.is_number()           ? v.get<double>()
              : row["ssim"].is_null() ? std::numeric_limits<double>::quiet_NaN()
                                      : std::numeric_limits<double>::infinity();
    return p;
}

Json accumCostJson(const AccumCost& c) {
    Json j = {{"reach", reachName(c.reach)}};
    if (c.reach == AccumReach::NoData)
        return j;
    j["samples"] = c.samples;
    j["ms"] = c.ms;
    if (c.reach == AccumReach::Interpolated) {
        j["below"] = c.below;
        j["above"] = c.above;
    }
    return j;
}

Json speedUpJson(const SpeedUp& s, std::span<const SweepPoint> method) {
    const bool ratio = s.bound == RatioBound::Exact || s.bound == RatioBound::AtLeast ||
                       s.bound == RatioBound::AtMost;
    return {{"accum_ms", s.accum.reach == AccumReach::NoData ? Json() : Json(s.accum.ms)},
            {"method_ms", s.method.reached ? Json(s.method.ms) : Json()},
            {"setting", s.method.reached ? Json(method[s.method.index].setting) : Json()},
            {"ratio", ratio ? jsonNumber(s.ratio) : Json()},
            {"bound", boundName(s.bound)},
            {"text", formatSpeedUp(s)}};
}

// accum's cell: the N it needs and its render / process time.
std::string accumCell(const Json& render, const Json& process) {
    auto ms = [](const Json& c) {
        return c["reach"] == "no_data" ? std::string("-") : fmt("%.1f", c["ms"].get<double>());
    };
    const std::string reach = render["reach"].get<std::string>();
    if (reach == "no_data")
        return "no data";
    const std::string rel = reach == "interpolated"    ? "N="
                            : reach == "first_setting" ? "N<="
                                                       : "N>";
    const std::string bound = reach == "interpolated" ? "" : reach == "first_setting" ? "<=" : ">";
    return rel + fmt("%.3g", render["samples"].get<double>()) + ": " + bound + ms(render) + " / " +
           (process["reach"] == "no_data" ? "" : bound) + ms(process) + " ms";
}

// A method's cell: render / process speed-up with the setting(s) that achieve them.
std::string speedUpCell(const Json& render, const Json& process) {
    const std::string r = render["text"].get<std::string>(), p = process["text"].get<std::string>();
    if (render["setting"].is_null())
        return r;
    const std::string rs = render["setting"].get<std::string>();
    if (process["setting"].is_null() || process["setting"] == rs)
        return r + " / " + p + " (" + rs + ")";
    return r + " (" + rs + ") / " + p + " (" + process["setting"].get<std::string>() + ")";
}

} // namespace

Json equalErrorOfScene(const std::string& spec, const Json& rows, const std::vector<size_t>& idx,
                       const std::vector<std::string>& layered) {
    Json targets = Json::array();
    for (const ErrorTarget& target : kErrorTargets) {
        auto sweep = [&](const std::string& method) {
            std::vector<SweepPoint> pts;
            for (size_t i : idx)
                if (rows[i]["method"] == method)
                    pts.push_back(sweepPointOf(rows[i], target.metric));
            return pts;
        };
        const std::vector<SweepPoint> accum = sweep("accum");
        Json t = {{"target", target.label}, {"metric", target.metric}, {"value", target.value}};
        t["accum"] = {
            {"render", accumCostJson(accumCostToReach(accum, target.value, TimeKind::Render))},
            {"process", accumCostJson(accumCostToReach(accum, target.value, TimeKind::Process))}};
        Json methods = Json::object();
        for (const std::string& m : layered) {
            const std::vector<SweepPoint> pts = sweep(m);
            methods[m] = {
                {"render",
                 speedUpJson(speedUpAtEqualError(accum, pts, target.value, TimeKind::Render), pts)},
                {"process",
                 speedUpJson(speedUpAtEqualError(accum, pts, target.value, TimeKind::Process),
                             pts)}};
        }
        t["methods"] = methods;
        targets.push_back(t);
    }
    return {{"scene", spec}, {"targets", targets}};
}

Json equalErrorHeader(const std::vector<std::string>& layered, uint32_t process_repeat) {
    Json header = {{"definition", kEqualErrorDefinition}, {"targets", Json::array()}};
    for (const ErrorTarget& t : kErrorTargets)
        header["targets"].push_back(
            {{"target", t.label}, {"metric", t.metric}, {"value", t.value}});
    header["methods"] = layered;
    header["process_repeat"] = process_repeat;
    return header;
}

Table equalErrorTable(const Json& scenes, const std::vector<std::string>& layered) {
    Table t;
    t.header = {"scene", "target", "accum N: ms render / process"};
    for (const std::string& m : layered)
        t.header.push_back(m + " render / process");
    for (const Json& scene : scenes)
        for (const Json& target : scene["targets"]) {
            std::vector<std::string> row = {
                scene.value("name", scene["scene"].get<std::string>()),
                target["target"].get<std::string>(),
                accumCell(target["accum"]["render"], target["accum"]["process"])};
            for (const std::string& m : layered)
                row.push_back(
                    speedUpCell(target["methods"][m]["render"], target["methods"][m]["process"]));
            t.rows.push_back(row);
        }
    return t;
}

} // namespace focal
