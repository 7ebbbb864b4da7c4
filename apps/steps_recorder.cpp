#include "apps/steps_recorder.h"

#include "apps/false_colour.h"
#include "apps/image_io.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

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

std::string number(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.4g", v);
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
    probe_json_.push_back({{"x", probe.x},
                           {"y", probe.y},
                           {"rgba", rgbaJson(probe.rgba)},
                           {"fragments", std::move(fragments)},
                           {"method", nlohmann::json::object()},
                           {"draw", std::move(draw)}});
}

} // namespace focal
