#include "apps/steps_recorder.h"

#include "apps/false_colour.h"
#include "apps/image_io.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <type_traits>
#include <variant>

namespace focal {

using raster::Status;

namespace {

// "multiview.layers" image 3 -> "images/multiview_layers_03.png".
std::string imageFile(const std::string& stage_id, size_t index) {
    std::string name = stage_id;
    std::replace(name.begin(), name.end(), '.', '_');
    char suffix[32];
    std::snprintf(suffix, sizeof suffix, "_%02zu.png", index);
    return "images/" + name + suffix;
}

std::string number(float v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.4g", double(v));
    return buf;
}

// The picture of a stage image, and what its colours mean (appended to the caption).
ImageData picture(const dof::StageImage& img, std::string& legend) {
    ImageData out{img.width, img.height, 3, std::vector<float>(size_t(img.width) * img.height * 3)};
    const auto at = [&](uint32_t x, uint32_t y) {
        return img.pixels + size_t(y) * img.stride + size_t(x) * img.channels;
    };
    const auto put = [&](uint32_t x, uint32_t y, glm::vec3 c) {
        float* p = out.pixels.data() + (size_t(y) * img.width + x) * 3;
        p[0] = c.r, p[1] = c.g, p[2] = c.b;
    };
    // The range of the finite values of channel 0.
    float lo = INFINITY, hi = -INFINITY;
    for (uint32_t y = 0; y < img.height; ++y)
        for (uint32_t x = 0; x < img.width; ++x)
            if (const float v = *at(x, y); std::isfinite(v))
                lo = std::min(lo, v), hi = std::max(hi, v);
    const bool any = lo <= hi;
    switch (img.kind) {
    case dof::StageImageKind::Color:
        // Colours over black (alpha, coverage or opacity, is in the caption's words).
        for (uint32_t y = 0; y < img.height; ++y)
            for (uint32_t x = 0; x < img.width; ++x)
                put(x, y, glm::vec3(at(x, y)[0], at(x, y)[1], at(x, y)[2]));
        break;
    case dof::StageImageKind::Distance: {
        // Grey in 1/d: near white, far dark; nothing there is dark blue.
        const float inv_near = any ? 1.0f / lo : 1.0f, inv_far = any ? 1.0f / hi : 0.0f;
        for (uint32_t y = 0; y < img.height; ++y)
            for (uint32_t x = 0; x < img.width; ++x) {
                const float d = *at(x, y);
                if (!std::isfinite(d) || d <= 0.0f) {
                    put(x, y, {0.0f, 0.0f, 0.05f});
                    continue;
                }
                const float t =
                    inv_near > inv_far ? (1.0f / d - inv_far) / (inv_near - inv_far) : 1.0f;
                put(x, y, glm::vec3(0.03f + 0.97f * t * t));
            }
        legend = any ? "grey in 1/d: white at d = " + number(lo) + ", dark at d = " + number(hi) +
                           "; dark blue: nothing"
                     : "nothing there (dark blue)";
        break;
    }
    case dof::StageImageKind::Signed: {
        const float m = any ? std::max(std::abs(lo), std::abs(hi)) : 0.0f;
        for (uint32_t y = 0; y < img.height; ++y)
            for (uint32_t x = 0; x < img.width; ++x) {
                const float t = m > 0.0f ? std::clamp(*at(x, y) / m, -1.0f, 1.0f) : 0.0f;
                put(x, y,
                    t < 0.0f ? glm::vec3(0.05f, 0.25f, 1.0f) * -t
                             : glm::vec3(1.0f, 0.3f, 0.05f) * t);
            }
        legend = "blue negative, red positive, black 0; full colour at |v| = " + number(m);
        break;
    }
    case dof::StageImageKind::Count: {
        const float m = any ? hi : 0.0f;
        for (uint32_t y = 0; y < img.height; ++y)
            for (uint32_t x = 0; x < img.width; ++x)
                put(x, y, heat(m > 0.0f ? *at(x, y) / m : 0.0f));
        legend = "heat map from 0 (black) to " + number(m) + " (white)";
        break;
    }
    case dof::StageImageKind::Id:
        for (uint32_t y = 0; y < img.height; ++y)
            for (uint32_t x = 0; x < img.width; ++x) {
                const float v = *at(x, y);
                put(x, y, v < 0.0f ? glm::vec3(0.0f) : idColour(uint32_t(v)));
            }
        legend = "one colour per identifier; black: none";
        break;
    }
    return out;
}

nlohmann::json rgbaJson(const float* v) {
    return {finiteOrNull(v[0]), finiteOrNull(v[1]), finiteOrNull(v[2]), finiteOrNull(v[3])};
}

} // namespace

nlohmann::json finiteOrNull(double v) {
    return std::isfinite(v) ? nlohmann::json(v) : nullptr;
}

nlohmann::json finiteOrNull(float v) {
    return finiteOrNull(double(v));
}

StepsRecorder::StepsRecorder(std::string folder, std::vector<glm::uvec2> probes)
    : folder_(std::move(folder)), probes_(std::move(probes)) {}

void StepsRecorder::stage(const dof::Stage& stage) {
    nlohmann::json j = {
        {"id", stage.id},       {"group", stage.group},
        {"title", stage.title}, {"paper", stage.paper},
        {"text", stage.text},   {"ms", stage.ms >= 0.0 ? nlohmann::json(stage.ms) : nullptr}};
    nlohmann::json counts = nlohmann::json::object();
    for (const auto& [name, v] : stage.counts)
        counts[name] = finiteOrNull(v);
    j["counts"] = std::move(counts);
    nlohmann::json images = nlohmann::json::array();
    for (size_t i = 0; i < stage.images.size(); ++i) {
        const dof::StageImage& img = stage.images[i];
        std::string legend;
        const ImageData pic = picture(img, legend);
        const std::string file = imageFile(stage.id, i);
        if (!folder_.empty() && status_.ok())
            status_ = writeImage(folder_ + "/" + file, pic);
        nlohmann::json im = {{"name", img.name},     {"file", file},       {"width", img.width},
                             {"height", img.height}, {"scale", img.scale}, {"caption", img.caption},
                             {"legend", legend}};
        images.push_back(std::move(im));
    }
    j["images"] = std::move(images);
    nlohmann::json tables = nlohmann::json::array();
    for (const dof::StageTable& t : stage.tables) {
        nlohmann::json rows = nlohmann::json::array();
        for (const std::vector<double>& r : t.rows) {
            nlohmann::json row = nlohmann::json::array();
            for (double v : r)
                row.push_back(finiteOrNull(v));
            rows.push_back(std::move(row));
        }
        tables.push_back({{"name", t.name}, {"columns", t.columns}, {"rows", std::move(rows)}});
    }
    j["tables"] = std::move(tables);
    nlohmann::json plots = nlohmann::json::array();
    for (const dof::StagePoints& p : stage.plots) {
        nlohmann::json points = nlohmann::json::array();
        for (const glm::vec2& v : p.points)
            points.push_back({v.x, v.y});
        plots.push_back({{"name", p.name},
                         {"kind", "points"},
                         {"x_label", p.x_label},
                         {"y_label", p.y_label},
                         {"x_range", {p.x_range.x, p.x_range.y}},
                         {"y_range", {p.y_range.x, p.y_range.y}},
                         {"points", std::move(points)}});
    }
    j["plots"] = std::move(plots);
    stages_.push_back(std::move(j));
}

namespace {

nlohmann::json rgbJson(glm::vec3 v) {
    return {finiteOrNull(v.r), finiteOrNull(v.g), finiteOrNull(v.b)};
}

nlohmann::json shape(const char* kind, nlohmann::json points, std::string label,
                     std::vector<std::string> stages) {
    nlohmann::json j = {{"kind", kind}, {"label", std::move(label)}, {"stages", std::move(stages)}};
    if (std::string(kind) == "polyline")
        j["points"] = std::move(points);
    else
        j["at"] = std::move(points);
    return j;
}

const char* stepResultName(dof::MultiviewStepResult r) {
    switch (r) {
    case dof::MultiviewStepResult::Skipped:
        return "skipped";
    case dof::MultiviewStepResult::Passed:
        return "passed";
    case dof::MultiviewStepResult::Hit:
        return "hit";
    case dof::MultiviewStepResult::Cone:
        return "cone";
    case dof::MultiviewStepResult::MissedCone:
        return "missed cone";
    }
    return "?";
}

const char* cullName(dof::MultiviewLayerCull c) {
    switch (c) {
    case dof::MultiviewLayerCull::Empty:
        return "empty";
    case dof::MultiviewLayerCull::Tile:
        return "culled for the tile";
    case dof::MultiviewLayerCull::Pixel:
        return "culled for the pixel";
    case dof::MultiviewLayerCull::ConesOnly:
        return "cones only";
    case dof::MultiviewLayerCull::None:
        return "visited";
    }
    return "?";
}

// Each method's record (dof/frame_observer.h PixelProbe::method) as JSON, and the shapes that
// show it over the stage pictures.
void methodJson(const dof::AccumPixelProbe& p, nlohmann::json& out, nlohmann::json&) {
    nlohmann::json views = nlohmann::json::array();
    for (const dof::AccumViewSample& v : p.views)
        views.push_back({{"lens", {v.lens.x, v.lens.y}},
                         {"pixel_shift", {v.pixel_shift.x, v.pixel_shift.y}},
                         {"weight", v.weight},
                         {"rgba", rgbaJson(v.rgba)},
                         {"stored_depth", v.depth}});
    out = {{"views", std::move(views)}, {"rgba", rgbaJson(p.rgba)}};
}

void methodJson(const dof::GatherPixelProbe& p, nlohmann::json& out, nlohmann::json& draw) {
    const auto taps = [](const std::vector<dof::GatherTap>& list) {
        nlohmann::json j = nlohmann::json::array();
        for (const dof::GatherTap& t : list)
            j.push_back({{"x", t.x},
                         {"y", t.y},
                         {"offset", t.offset},
                         {"weight", t.weight},
                         {"overlap", t.overlap},
                         {"intensity", t.intensity},
                         {"leakage", t.leakage},
                         {"rgba", rgbaJson(t.rgba)}});
        return j;
    };
    out = {{"coc_px", p.coc_px},
           {"radius_px", p.radius_px},
           {"vertical_reach", p.vertical_reach},
           {"horizontal_reach", p.horizontal_reach},
           {"copied_vertical", p.copied_vertical},
           {"copied_horizontal", p.copied_horizontal},
           {"vertical_rgba", rgbaJson(p.vertical_rgba)},
           {"rgba", rgbaJson(p.rgba)},
           {"vertical", taps(p.vertical)},
           {"horizontal", taps(p.horizontal)}};
    const double cx = p.x + 0.5, cy = p.y + 0.5;
    draw.push_back(
        shape("circle", {cx, cy}, "|C| = " + std::to_string(p.coc_px) + " px", {"gather.coc"}));
    draw.back()["r"] = std::abs(p.coc_px);
    // The taps with a weight, as the span of each pass.
    const auto span = [&](const std::vector<dof::GatherTap>& list, const char* stage,
                          const char* label) {
        int32_t lo = 0, hi = 0;
        for (const dof::GatherTap& t : list)
            if (t.weight > 0.0f)
                lo = std::min(lo, t.offset), hi = std::max(hi, t.offset);
        const bool vertical = std::string(stage) == "gather.vertical";
        nlohmann::json pts = vertical ? nlohmann::json{{cx, cy + lo}, {cx, cy + hi}}
                                      : nlohmann::json{{cx + lo, cy}, {cx + hi, cy}};
        draw.push_back(shape("polyline", std::move(pts), label, {stage}));
    };
    span(p.vertical, "gather.vertical", "vertical taps with weight");
    span(p.horizontal, "gather.horizontal", "horizontal taps with weight");
}

void methodJson(const dof::MultiviewPixelProbe& p, nlohmann::json& out, nlohmann::json& draw) {
    nlohmann::json layers = nlohmann::json::array();
    for (size_t l = 0; l < p.layers.size(); ++l)
        layers.push_back({{"layer", l}, {"cull", cullName(p.layers[l])}});
    nlohmann::json rays = nlohmann::json::array();
    for (size_t i = 0; i < p.rays.size(); ++i) {
        const dof::MultiviewRayRecord& r = p.rays[i];
        nlohmann::json steps = nlohmann::json::array();
        for (const dof::MultiviewLayerStep& st : r.steps)
            steps.push_back({{"layer", st.layer},
                             {"culled", st.culled},
                             {"tested", st.tested},
                             {"false_position_steps", st.false_position_steps},
                             {"binary_steps", st.binary_steps},
                             {"fetches", st.fetches},
                             {"result", stepResultName(st.result)},
                             {"coverage", st.coverage},
                             {"c1", rgbJson(st.c1)},
                             {"transparent", st.transparent},
                             {"color_after", rgbJson(st.color)},
                             {"transmit_after", st.transmit}});
        const char* end = r.discarded ? "discarded" : (r.layer < 0 ? "background" : "hit");
        rays.push_back({{"lens", {r.lens.x, r.lens.y}},
                        {"weight", r.weight},
                        {"end", end},
                        {"layer", r.layer},
                        {"start_px", {r.start_px.x, r.start_px.y}},
                        {"end_px", {r.end_px.x, r.end_px.y}},
                        {"partial_hits", r.partial_hits},
                        {"missed_cones", r.missed_cones},
                        {"rgba", rgbaJson(r.rgba)},
                        {"steps", std::move(steps)}});
        draw.push_back(shape("polyline", {{r.start_px.x, r.start_px.y}, {r.end_px.x, r.end_px.y}},
                             "ray " + std::to_string(i) + " (" + end + ")",
                             {"targets.layers", "multiview.nbuffer", "multiview.mipmaps",
                              "multiview.tracing", "raster.color"}));
    }
    out = {{"skipped", p.skipped},
           {"in_focus", p.in_focus},
           {"layers", std::move(layers)},
           {"rays", std::move(rays)},
           {"rgba", rgbaJson(p.rgba)}};
}

void methodJson(const dof::MultilayerPixelProbe& p, nlohmann::json& out, nlohmann::json& draw) {
    nlohmann::json reads = nlohmann::json::array();
    float widest = 0.0f;
    for (const dof::MultilayerProbeRead& r : p.reads) {
        reads.push_back({{"level", r.level},
                         {"kind", dof::levelKindName(r.kind)},
                         {"side", r.side},
                         {"slice", r.slice},
                         {"cell", {r.x, r.y}},
                         {"segment", r.segment},
                         {"blend", r.blend},
                         {"accepted", r.accepted},
                         {"depth", r.depth},
                         {"coc_px", r.coc_px},
                         {"tap_weight", r.tap_weight},
                         {"level_weight", r.level_weight},
                         {"share", r.share},
                         {"weight", r.weight},
                         {"rgba", rgbaJson(r.rgba)}});
        if (r.accepted && r.weight > 0.0f)
            widest = std::max(widest, std::abs(r.coc_px));
    }
    nlohmann::json slices = nlohmann::json::array();
    for (const dof::MultilayerProbeSlice& sl : p.slices)
        slices.push_back({{"segment", sl.segment},
                          {"levels", {sl.lo, sl.hi}},
                          {"depth", sl.depth},
                          {"limit", finiteOrNull(sl.limit)},
                          {"t", sl.t},
                          {"blended", sl.blended},
                          {"new_group", sl.new_group},
                          {"take", sl.take},
                          {"k", sl.k},
                          {"coverage", sl.coverage}});
    out = {{"reads", std::move(reads)},
           {"slices", std::move(slices)},
           {"coverage", p.coverage},
           {"background", {p.background[0], p.background[1], p.background[2]}},
           {"rgba", rgbaJson(p.rgba)}};
    // The largest circle of confusion among the fragments that gave the pixel colour: how far
    // the levels it read reach.
    draw.push_back(shape("circle", {p.x + 0.5, p.y + 0.5},
                         "largest |C| read: " + std::to_string(widest) + " px",
                         {"multilayer.collect", "multilayer.levels", "multilayer.accumulate"}));
    draw.back()["r"] = widest;
}

} // namespace

void StepsRecorder::probe(const dof::PixelProbe& probe) {
    nlohmann::json fragments = nlohmann::json::array();
    for (const dof::ProbeFragment& f : probe.fragments)
        fragments.push_back({{"depth", finiteOrNull(f.distance)},
                             {"primitive", f.primitive},
                             {"rgba", rgbaJson(f.rgba)}});
    nlohmann::json draw = nlohmann::json::array();
    draw.push_back({{"kind", "point"},
                    {"at", {probe.x + 0.5, probe.y + 0.5}},
                    {"label", "probed pixel"},
                    {"stages", {"*"}}});
    nlohmann::json method = nlohmann::json::object();
    std::visit(
        [&](const auto& m) {
            if constexpr (!std::is_same_v<std::decay_t<decltype(m)>, std::monostate>)
                methodJson(m, method, draw);
        },
        probe.method);
    probe_json_.push_back({{"x", probe.x},
                           {"y", probe.y},
                           {"rgba", rgbaJson(probe.rgba)},
                           {"fragments", std::move(fragments)},
                           {"method", std::move(method)},
                           {"draw", std::move(draw)}});
}

} // namespace focal
