#include "apps/method_multiview.h"

#include "apps/image_io.h"
#include "apps/settings_options.h"

#include <dof/multiview.h>
#include <dof/n_buffer.h>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace focal {

namespace {

struct MultiviewArgs {
    dof::MultiviewSettings settings; // the table's options (dof::multiviewParams)
    std::string env_map;
    float env_intensity = 1.0f;
    std::string debug_out;   // prefix of the debug pictures; empty: none
    std::string debug_pixel; // "X,Y"; empty: the image centre
    // Read by the settings of the last frame: the environment map and the debug pixel's rays.
    dof::EnvironmentMap env;
    std::vector<dof::MultiviewRayRecord> debug_rays;
};

// --- Debug pictures (--multiview-debug-out): layers, N-buffer levels, one pixel's rays ---------

// An RGB picture under construction (linear float).
struct Canvas {
    uint32_t width = 0, height = 0;
    std::vector<float> rgb;
    Canvas(uint32_t w, uint32_t h, glm::vec3 fill) : width(w), height(h), rgb(size_t(w) * h * 3) {
        for (size_t i = 0; i < size_t(w) * h; ++i)
            rgb[i * 3] = fill.r, rgb[i * 3 + 1] = fill.g, rgb[i * 3 + 2] = fill.b;
    }
    void set(int64_t x, int64_t y, glm::vec3 c) {
        if (x < 0 || y < 0 || x >= int64_t(width) || y >= int64_t(height))
            return;
        float* p = rgb.data() + (size_t(y) * width + size_t(x)) * 3;
        p[0] = c.r, p[1] = c.g, p[2] = c.b;
    }
    glm::vec3 get(uint32_t x, uint32_t y) const {
        const float* p = rgb.data() + (size_t(y) * width + x) * 3;
        return {p[0], p[1], p[2]};
    }
    // A line from a to b (DDA, one dot per pixel step).
    void line(glm::vec2 a, glm::vec2 b, glm::vec3 c) {
        const float steps = std::max(std::fabs(b.x - a.x), std::fabs(b.y - a.y));
        const uint32_t n = uint32_t(std::ceil(steps)) + 1;
        for (uint32_t i = 0; i <= n; ++i) {
            const glm::vec2 p = a + (b - a) * (float(i) / float(n));
            set(int64_t(std::floor(p.x)), int64_t(std::floor(p.y)), c);
        }
    }
    void dot(glm::vec2 p, int r, glm::vec3 c) {
        for (int dy = -r; dy <= r; ++dy)
            for (int dx = -r; dx <= r; ++dx)
                if (dx * dx + dy * dy <= r * r)
                    set(int64_t(std::floor(p.x)) + dx, int64_t(std::floor(p.y)) + dy, c);
    }
    raster::Status write(const std::string& path) const {
        ImageData img;
        img.width = width;
        img.height = height;
        img.channels = 3;
        img.pixels = rgb;
        return writeImage(path, img);
    }
};

// A distinct colour per layer (cycled), for ray ends and legends.
glm::vec3 layerColour(int32_t l) {
    static constexpr std::array<std::array<float, 3>, 8> kPalette = {{{1.0f, 0.25f, 0.1f},
                                                                      {0.1f, 0.8f, 0.2f},
                                                                      {0.2f, 0.4f, 1.0f},
                                                                      {1.0f, 0.85f, 0.1f},
                                                                      {0.9f, 0.2f, 0.9f},
                                                                      {0.1f, 0.9f, 0.9f},
                                                                      {1.0f, 0.55f, 0.1f},
                                                                      {0.6f, 0.35f, 1.0f}}};
    if (l < 0)
        return glm::vec3(0.6f); // background
    const std::array<float, 3>& p = kPalette[size_t(l) % kPalette.size()];
    return {p[0], p[1], p[2]};
}

// Tiles of size tw x th laid out in `cols` columns with a 2-pixel gutter.
Canvas montage(uint32_t count, uint32_t tw, uint32_t th, uint32_t cols) {
    const uint32_t rows = (count + cols - 1) / cols;
    const uint32_t c = std::min(count, cols);
    return Canvas(c * (tw + 2) + 2, rows * (th + 2) + 2, glm::vec3(1.0f));
}
glm::uvec2 tileOrigin(uint32_t i, uint32_t tw, uint32_t th, uint32_t cols) {
    return {2 + (i % cols) * (tw + 2), 2 + (i / cols) * (th + 2)};
}

// Writes PREFIX_layers.png (colour of every layer; empty texels as a grey checkerboard),
// PREFIX_depths.png (each layer's depth, near = white, far = dark; empty = dark red),
// PREFIX_nbuffer.png (N-buffer levels of the nearest layer the pixel's rays hit: min depth as
// grey, §4.3), PREFIX_rays.png
// (the traced rays of one pixel over the output, ending in their hit layer's colour) and
// PREFIX_lens.png (the pixel's lens samples coloured by the layer they hit, with a white rim
// where a partial or missed cone gave part of the colour).
raster::Status writeDebugPictures(const std::string& prefix, const raster::View& view,
                                  const raster::LayeredTarget& lt, const std::vector<float>& out,
                                  const std::vector<dof::MultiviewRayRecord>& rays, uint32_t px,
                                  uint32_t py, float d_near, float d_far) {
    const uint32_t w = lt.width, h = lt.height, m = lt.layer_count;
    const uint32_t scale = std::max(1u, (w + 239) / 240); // tiles at most 240 pixels wide
    const uint32_t tw = w / scale, th = h / scale, cols = 4;
    const float inv_near = 1.0f / std::max(d_near, 1e-6f);
    const float inv_far = 1.0f / std::max(d_far, d_near * 1.0001f);
    auto grey = [&](float d) { // in 1/d, where the layers are uniform (Eq. 4)
        const float g = std::clamp((1.0f / d - inv_far) / (inv_near - inv_far), 0.0f, 1.0f);
        return glm::vec3(0.08f + 0.92f * g);
    };
    Canvas colours = montage(m, tw, th, cols), depths = montage(m, tw, th, cols);
    for (uint32_t l = 0; l < m; ++l) {
        const glm::uvec2 o = tileOrigin(l, tw, th, cols);
        for (uint32_t y = 0; y < th; ++y)
            for (uint32_t x = 0; x < tw; ++x) {
                const size_t i = lt.index(l, size_t(y * scale) * w + x * scale);
                const glm::vec4 c = lt.color.load(i);
                const bool check = ((x / 6) + (y / 6)) % 2 == 0;
                colours.set(o.x + x, o.y + y,
                            c.a > 0.0f ? glm::vec3(c) : glm::vec3(check ? 0.22f : 0.3f));
                const float d = lt.depth.load(i);
                depths.set(o.x + x, o.y + y,
                           c.a > 0.0f ? grey(raster::distanceFromDepth(view, d))
                                      : glm::vec3(0.25f, 0.02f, 0.02f));
            }
        // The layer's colour as a bar on the tile's top edge, matching the ray picture.
        for (uint32_t x = 0; x < tw; ++x)
            for (uint32_t y = 0; y < 3; ++y)
                colours.set(o.x + x, o.y + y, layerColour(int32_t(l)));
    }
    if (raster::Status st = colours.write(prefix + "_layers.png"); !st.ok())
        return st;
    if (raster::Status st = depths.write(prefix + "_depths.png"); !st.ok())
        return st;

    // N-buffer of the nearest layer the pixel's rays hit (else the first non-empty layer).
    std::vector<uint32_t> hits(m, 0);
    for (const dof::MultiviewRayRecord& r : rays)
        if (r.layer >= 0 && !r.discarded)
            ++hits[size_t(r.layer)];
    uint32_t nl = uint32_t(
        std::find_if(hits.begin(), hits.end(), [](uint32_t c) { return c > 0; }) - hits.begin());
    if (nl == m)
        nl = 0;
    std::vector<float> depth(lt.pixelCount());
    auto fillDepth = [&](uint32_t l) {
        bool any = false;
        for (size_t i = 0; i < depth.size(); ++i) {
            const size_t li = lt.index(l, i);
            const bool covered = lt.color.load(li).a > 0.0f;
            depth[i] = covered ? lt.depth.load(li) : 2.0f;
            any = any || covered;
        }
        return any;
    };
    if (hits[nl] == 0)
        for (nl = 0; nl + 1 < m && !fillDepth(nl); ++nl) {
        }
    fillDepth(nl);
    dof::NBuffer nb;
    dof::buildNBuffer(depth.data(), w, h, 7, nb);
    Canvas levels = montage(nb.levelCount(), tw, th, cols);
    for (uint32_t k = 0; k < nb.levelCount(); ++k) {
        const glm::uvec2 o = tileOrigin(k, tw, th, cols);
        for (uint32_t y = 0; y < th; ++y)
            for (uint32_t x = 0; x < tw; ++x) {
                const float d = nb.at(k, x * scale, y * scale);
                levels.set(o.x + x, o.y + y,
                           d <= raster::kFarDepth ? grey(raster::distanceFromDepth(view, d))
                                                  : glm::vec3(0.25f, 0.02f, 0.02f));
            }
    }
    if (raster::Status st = levels.write(prefix + "_nbuffer.png"); !st.ok())
        return st;

    // The pixel's rays over a magnified crop of the output.
    glm::vec2 lo{float(px), float(py)}, hi{float(px) + 1.0f, float(py) + 1.0f};
    for (const dof::MultiviewRayRecord& r : rays) {
        lo = glm::min(lo, glm::min(r.start_px, r.end_px));
        hi = glm::max(hi, glm::max(r.start_px, r.end_px));
    }
    const float margin = 4.0f + 0.15f * std::max(hi.x - lo.x, hi.y - lo.y);
    lo = glm::max(glm::floor(lo - margin), glm::vec2(0.0f));
    hi = glm::min(glm::ceil(hi + margin), glm::vec2(float(w), float(h)));
    const float zoom = std::max(1.0f, std::floor(480.0f / std::max(hi.x - lo.x, hi.y - lo.y)));
    Canvas crop(uint32_t((hi.x - lo.x) * zoom), uint32_t((hi.y - lo.y) * zoom), glm::vec3(0.0f));
    for (uint32_t y = 0; y < crop.height; ++y)
        for (uint32_t x = 0; x < crop.width; ++x) {
            const uint32_t sx = std::min(uint32_t(lo.x + float(x) / zoom), w - 1);
            const uint32_t sy = std::min(uint32_t(lo.y + float(y) / zoom), h - 1);
            const float* p = out.data() + (size_t(sy) * w + sx) * 4;
            crop.set(x, y, 0.5f * glm::vec3(p[0], p[1], p[2])); // dimmed, so the rays stand out
        }
    auto toCrop = [&](glm::vec2 p) { return (p - lo) * zoom; };
    for (const dof::MultiviewRayRecord& r : rays) {
        const glm::vec3 c = r.discarded ? glm::vec3(1.0f, 0.0f, 0.0f) : layerColour(r.layer);
        crop.line(toCrop(r.start_px), toCrop(r.end_px), 0.6f * c);
        crop.dot(toCrop(r.end_px), 2, c);
    }
    crop.dot(toCrop(glm::vec2(px, py) + 0.5f), 3, glm::vec3(1.0f));
    if (raster::Status st = crop.write(prefix + "_rays.png"); !st.ok())
        return st;

    // The lens plane: each sample where it sits on the aperture, coloured by its hit layer.
    Canvas lens(241, 241, glm::vec3(0.1f));
    for (uint32_t y = 0; y < 241; ++y)
        for (uint32_t x = 0; x < 241; ++x) {
            const glm::vec2 v((float(x) - 120.0f) / 110.0f, (120.0f - float(y)) / 110.0f);
            if (glm::dot(v, v) <= 1.0f)
                lens.set(x, y, glm::vec3(0.2f));
        }
    for (const dof::MultiviewRayRecord& r : rays) {
        const glm::vec2 at(120.5f + 110.0f * r.lens.x, 120.5f - 110.0f * r.lens.y);
        if (r.partial_hits + r.missed_cones > 0) // part of its colour came from a cone (§4.4)
            lens.dot(at, 4, glm::vec3(1.0f));
        lens.dot(at, 3, r.discarded ? glm::vec3(1.0f, 0.0f, 0.0f) : layerColour(r.layer));
    }
    return lens.write(prefix + "_lens.png");
}

raster::Result<dof::MethodSettings> multiviewSettings(MultiviewArgs& a, const MethodContext& in) {
    dof::MultiviewSettings s = a.settings;
    s.color_format = in.target_color.value_or(raster::ColorFormat::Half);
    s.depth_format = in.target_depth.value_or(raster::DepthFormat::Float32);

    dof::EnvironmentMap& env = a.env;
    env = dof::EnvironmentMap{};
    if (!a.env_map.empty()) {
        raster::Result<ImageData> img = readImage(a.env_map);
        if (!img.ok())
            return raster::Status::error("--env-map: " + img.status().message());
        env.width = img->width;
        env.height = img->height;
        env.intensity = a.env_intensity;
        env.rgb.resize(size_t(env.width) * env.height * 3);
        for (size_t i = 0; i < size_t(env.width) * env.height; ++i)
            for (uint32_t c = 0; c < 3; ++c)
                env.rgb[i * 3 + c] =
                    img->pixels[i * img->channels + std::min(c, img->channels - 1)];
        s.env_map = &env;
    }
    // --multiview-debug-out: record the rays of one pixel.
    a.debug_rays.clear();
    if (!a.debug_out.empty()) {
        s.debug_x = in.view.width / 2;
        s.debug_y = in.view.height / 2;
        if (!a.debug_pixel.empty()) {
            unsigned dx = 0, dy = 0;
            char tail = 0;
            if (std::sscanf(a.debug_pixel.c_str(), "%u,%u%c", &dx, &dy, &tail) != 2 ||
                dx >= in.view.width || dy >= in.view.height)
                return raster::Status::error("--multiview-debug-pixel: expected X,Y inside the "
                                             "image, got '" +
                                             a.debug_pixel + "'");
            s.debug_x = dx;
            s.debug_y = dy;
        }
        s.debug_rays = &a.debug_rays;
        s.skip_unblurred = false; // the pictures show every stage, even for a sharp image
    }
    // dof::FrameRenderer takes the seed and §4.5's Halton sequence from the lens samples.
    return dof::MethodSettings(dof::MultiviewMethod{s, &in.lens_samples});
}

raster::Status finishMultiview(MultiviewArgs& a, const MethodContext& in,
                               const dof::MethodSettings& method, const dof::FrameRenderer& frames,
                               const dof::FrameReport& report, const std::vector<float>& rgba,
                               MethodOutput& out) {
    const dof::MultiviewSettings& s = std::get<dof::MultiviewMethod>(method).settings;
    const dof::MultiviewStats& st = std::get<dof::MultiviewStats>(report.method_stats);
    const raster::LayeredTarget& layers = frames.multiviewLayers();
    if (!a.debug_out.empty() && layers.layer_count > 0) {
        if (raster::Status ds = writeDebugPictures(a.debug_out, in.view, layers, rgba, a.debug_rays,
                                                   s.debug_x, s.debug_y, st.d_near, st.d_far);
            !ds.ok())
            return raster::Status::error("--multiview-debug-out: " + ds.message());
    }
    out.params = settingsJson(dof::multiviewParams(), s);
    out.params["samples"] = in.lens_samples.size();
    out.params["layer_spacing_used_px"] = st.delta_px;
    out.params["env_map"] = a.env_map;
    out.params["env_intensity"] = a.env_intensity;
    out.params["layer_color"] = s.color_format == raster::ColorFormat::Half ? "half" : "float32";
    out.params["layer_depth"] =
        s.depth_format == raster::DepthFormat::Unorm16 ? "unorm16" : "float32";
    if (st.skipped)
        std::fprintf(stderr, "focal: note: multiview rendered the pinhole only: %s\n",
                     st.skip_reason.c_str());
    out.counts = {{"skipped", st.skipped},
                  {"skip_reason", st.skip_reason},
                  {"layers", st.layers},
                  {"layers_empty", st.layers_empty},
                  {"guard_band_px", st.guard_band_px},
                  {"budget_limited", st.budget_limited},
                  {"d_near", st.d_near},
                  {"d_far", st.d_far},
                  {"lambda", st.lambda},
                  {"cone_centre", st.cones_on_cells ? "cell" : "sample"},
                  {"nbuffer_levels", st.nbuffer_levels},
                  {"mip_levels", st.mip_levels},
                  {"rays", st.rays},
                  {"pixels_in_focus", st.pixels_in_focus},
                  {"rays_discarded", st.rays_discarded},
                  {"rays_background", st.rays_background},
                  {"layer_steps", st.layer_steps},
                  {"layer_tests", st.layer_tests},
                  {"layers_culled_pixel", st.layer_culled_pixel},
                  {"layers_culled_tile", st.layer_culled_tile},
                  {"layers_culled_ray", st.layer_culled_ray},
                  {"cone_partial", st.cone_partial},
                  {"cone_missed", st.cone_missed},
                  {"texel_fetches", st.texel_fetches},
                  {"transparent_hits", st.transparent_hits},
                  {"path_cells", st.path_cells},
                  {"layered_bytes", st.layered_bytes},
                  {"scratch_bytes", st.scratch_bytes}};
    return {};
}

} // namespace

MethodEntry makeMultiviewMethod() {
    auto args = std::make_shared<MultiviewArgs>();
    MethodEntry e;
    e.name = "multiview";
    e.summary = "Lee, Eisemann & Seidel 2009: lens rays traced through depth layers";
    e.add_options = [args](CLI::App& cmd) {
        addSettingsOptions(cmd, "multiview", dof::multiviewParams(), args->settings);
        cmd.add_option("--env-map", args->env_map,
                       "multiview: equirectangular environment map for reflections (Sec. 5)");
        cmd.add_option("--env-intensity", args->env_intensity, "multiview: environment map scale")
            ->capture_default_str();
        cmd.add_option(
            "--multiview-debug-out", args->debug_out,
            "multiview: write debug pictures PREFIX_{layers,depths,nbuffer,rays,lens}.png "
            "(layer colours and depths, N-buffer levels, one pixel's traced rays)");
        cmd.add_option("--multiview-debug-pixel", args->debug_pixel,
                       "multiview: X,Y of the pixel whose rays --multiview-debug-out draws "
                       "[default: the centre]");
    };
    e.settings = [args](const MethodContext& in) { return multiviewSettings(*args, in); };
    e.finish = [args](const MethodContext& in, const dof::MethodSettings& method,
                      const dof::FrameRenderer& frames, const dof::FrameReport& report,
                      const std::vector<float>& rgba, MethodOutput& out) {
        return finishMultiview(*args, in, method, frames, report, rgba, out);
    };
    e.minimum_bytes = [args](const raster::View& view, uint32_t samples, uint32_t workers) {
        dof::MultiviewSettings s;
        s.layers = args->settings.layers;
        s.view_dependent = args->settings.view_dependent;
        s.color_format = raster::ColorFormat::Half; // the smallest storage: a lower bound
        s.depth_format = raster::DepthFormat::Unorm16;
        return dof::multiviewMinimumBytes(s, view.width, view.height, samples, workers);
    };
    return e;
}

} // namespace focal
