#include "apps/render_stats.h"

#include "apps/report_text.h"
#include "apps/settings_options.h"
#include "apps/text_file.h"

#include <cmath>

namespace focal {

using nlohmann::json;

namespace {

constexpr float kPi = 3.14159265358979f;

// The version of the --stats layout (docs/stats-schema.md): bumped on any change that could break
// a reader (a removed or renamed field, a changed meaning or unit), not for new fields.
constexpr int kStatsSchemaVersion = 2; // docs/stats-schema.md: version 2 renamed method params

const char* apertureKindName(dof::ApertureKind k) {
    return k == dof::ApertureKind::Polygon ? "polygon"
           : k == dof::ApertureKind::Image ? "image"
                                           : "circle";
}

json lensJson(const RenderRecord& r) {
    const RenderArgs& args = r.args;
    const dof::ThinLens& lens = r.lens.lens;
    json lj = {{"aperture_radius", lens.aperture_radius},
               {"aperture_source", apertureSourceName(r.lens.aperture_source)},
               {"focus_distance", lens.focus_distance},
               {"focus_source", focusSourceName(r.lens.focus_source)},
               {"focal_length_px", lens.focal_length_px},
               {"coc_at_infinity_px", dof::cocRadiusPx(lens, INFINITY)},
               {"aperture_shape", apertureKindName(r.aperture.kind)},
               {"lens_pattern", args.lens_pattern},
               {"seed", args.seed}};
    if (args.fstop)
        lj["fstop"] = *args.fstop;
    if (args.focal_length_mm) {
        lj["focal_length_mm"] = *args.focal_length_mm;
        lj["sensor_height_mm"] = args.sensor_height_mm.value_or(dof::kDefaultSensorHeightMm);
    }
    if (r.request.focus_pixel)
        lj["focus_pixel"] = {r.request.focus_pixel->x, r.request.focus_pixel->y};
    if (r.aperture.kind == dof::ApertureKind::Polygon) {
        lj["aperture_blades"] = r.aperture.blades;
        lj["aperture_rotation_deg"] = r.aperture.rotation_deg;
    }
    if (r.aperture.kind == dof::ApertureKind::Image)
        lj["aperture_image"] = args.aperture_image;
    return lj;
}

json accumJson(const RenderArgs& args, const dof::AccumStats& a) {
    json aj = settingsJson(dof::accumParams(), args.accum);
    aj["samples"] = args.samples;
    aj["views"] = a.views;
    aj["renders"] = a.renders;
    aj["skipped"] = a.skipped;
    if (a.skipped)
        aj["skip_reason"] = a.skip_reason;
    if (a.coc.covered)
        aj["visible_coc_px"] = {
            {"min", a.coc.min_px}, {"max", a.coc.max_px}, {"max_abs", a.coc.max_abs_px}};
    return aj;
}

// The table method's parameters and counts, its tracing cost per lens ray and per (ray, layer)
// step from the median time, and the target storage.
void addTableMethod(const RenderRecord& r, json& j) {
    j["params"] = r.method->params;
    j["counts"] = r.method->counts;
    const json& c = r.method->counts;
    const std::pair<const char*, const char*> units[] = {{"rays", "per_ray"},
                                                         {"layer_steps", "per_layer_step"}};
    if (j["time_ms"].contains("tracing"))
        for (const auto& [count, name] : units)
            if (c.contains(count) && c[count].get<uint64_t>() > 0)
                j["tracing_ns"][name] =
                    j["time_ms"]["tracing"].get<double>() * 1e6 / double(c[count].get<uint64_t>());
    j["lens"]["samples"] = r.args.samples;
    if (r.targets.color)
        j["target_color"] = *r.targets.color == raster::ColorFormat::Half ? "half" : "float32";
    if (r.targets.depth)
        j["target_depth"] =
            *r.targets.depth == raster::DepthFormat::Unorm16 ? "unorm16" : "float32";
}

json loadJson(const raster::ImportStats& load) {
    return {{"time_ms",
             {{"total", load.ms_total},
              {"parse", load.ms_parse},
              {"images", load.ms_images},
              {"decode", load.ms_decode},
              {"mipmaps", load.ms_mipmaps},
              {"scene", load.ms_scene}}},
            {"images_decoded", load.images_decoded},
            {"images_skipped", load.images_skipped}};
}

} // namespace

const char* apertureSourceName(dof::ApertureSource source) {
    switch (source) {
    case dof::ApertureSource::Request:
        return "cli";
    case dof::ApertureSource::FStop:
        return "fstop";
    case dof::ApertureSource::Scene:
        return "scene";
    case dof::ApertureSource::Default:
        break;
    }
    return "default";
}

const char* focusSourceName(dof::FocusSource source) {
    switch (source) {
    case dof::FocusSource::Request:
        return "cli";
    case dof::FocusSource::FocusPixel:
        return "focus-pixel";
    case dof::FocusSource::ViewFocus:
        return "target";
    case dof::FocusSource::Scene:
        return "scene";
    case dof::FocusSource::Autofocus:
        return "autofocus";
    case dof::FocusSource::Bounds:
        return "bounds";
    case dof::FocusSource::ViewDefault:
        break;
    }
    return "view";
}

void RunTimes::add(double total_ms, const raster::FrameStats& renders,
                   const dof::FrameReport& report) {
    totals_.push_back(total_ms);
    geometry_.push_back(renders.ms_geometry);
    binning_.push_back(renders.ms_binning);
    raster_.push_back(renders.ms_raster);
    json one = {{"total", total_ms},
                {"geometry", renders.ms_geometry},
                {"binning", renders.ms_binning},
                {"raster", renders.ms_raster}};
    for (size_t k = 0; k < report.stage_ms.size(); ++k) {
        const auto& [stage, ms] = report.stage_ms[k];
        one[stage] = ms;
        if (stages_.size() <= k)
            stages_.push_back({stage, {}});
        stages_[k].second.push_back(ms);
    }
    runs_.push_back(one);
}

double RunTimes::medianTotal() const {
    return median(totals_);
}

json RunTimes::medians() const {
    json t = {{"total", median(totals_)},
              {"geometry", median(geometry_)},
              {"binning", median(binning_)},
              {"raster", median(raster_)}};
    for (const auto& [stage, ms] : stages_)
        t[stage] = median(ms);
    return t;
}

json renderStatsJson(const RenderRecord& r) {
    const RenderArgs& args = r.args;
    const raster::View& v = r.view;
    json j;
    j["schema"] = "focal.render-stats";
    j["schema_version"] = kStatsSchemaVersion;
    j["scene"] = args.scene;
    // No -o: a frame kept in memory (focal bench).
    j["output"] = args.outputs.empty() ? json() : json(args.outputs.front());
    j["outputs"] = args.outputs;
    j["simd"] = !args.no_simd;
    if (!r.target_stats.is_null())
        j["targets"] = r.target_stats;
    j["method"] = args.method;
    j["width"] = args.width;
    j["height"] = args.height;
    j["threads"] = args.threads;
    j["tile"] = args.tile;
    j["depth_format"] = args.depth_format;
    j["shading"] = args.shading;
    j["texture_filter"] = args.texture_filter;
    j["repeat"] = args.repeat;
    j["camera"] = {{"eye", {v.eye.x, v.eye.y, v.eye.z}},
                   {"forward", {v.forward.x, v.forward.y, v.forward.z}},
                   {"up", {v.up.x, v.up.y, v.up.z}},
                   {"yfov_deg", v.yfov * 180.0f / kPi},
                   {"near", v.znear},
                   {"far", v.zfar},
                   {"focus_distance", v.focus_distance}};
    j["lens"] = lensJson(r);
    j["time_ms"] = r.times.medians();
    if (r.lens.ms_focus > 0.0)
        j["time_ms"]["focus"] = r.lens.ms_focus;
    // Scene loading, once per process (not part of time_ms, which is per render).
    j["load"] = loadJson(r.load);
    if (r.accum)
        j["accum"] = accumJson(args, *r.accum);
    if (r.method)
        addTableMethod(r, j);
    j["runs"] = r.times.runs();
    j["triangles"] = {{"in", r.counts.triangles_in},
                      {"culled", r.counts.triangles_culled},
                      {"clipped", r.counts.triangles_clipped},
                      {"setup", r.counts.triangles_setup}};
    j["fragments"] = {{"covered", r.counts.fragments_covered},
                      {"passed", r.counts.fragments_passed}};
    return j;
}

raster::Status writeRenderStats(const std::string& path, const nlohmann::json& stats) {
    return writeTextFile(path, stats.dump(2) + "\n");
}

} // namespace focal
