#include "apps/render_request.h"

#include "apps/image_io.h"
#include "apps/memory_option.h"
#include "apps/settings_options.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <sstream>
#include <utility>

namespace focal {

using raster::Result;
using raster::Status;

namespace {

constexpr float kPi = 3.14159265358979f;

Result<glm::vec3> parseVec3(const std::string& option, const std::string& text) {
    glm::vec3 v(0.0f);
    std::istringstream in(text);
    char comma1 = 0, comma2 = 0;
    in >> v.x >> comma1 >> v.y >> comma2 >> v.z;
    if (!in || comma1 != ',' || comma2 != ',' || !(in >> std::ws).eof() ||
        !std::isfinite(v.x + v.y + v.z))
        return Status::error(option + " expects three finite numbers X,Y,Z, got '" + text + "'");
    return v;
}

// --eye/--target/--up: a look-at camera whose default clip planes enclose the scene's bounds as
// seen from the eye; its focus distance is the distance to the target.
Result<raster::View> lookAtView(const raster::Scene& scene, const RenderArgs& args) {
    if (!args.eye || !args.target)
        return Status::error("--eye and --target go together");
    if (args.camera)
        return Status::error("--camera cannot be combined with --eye/--target");
    auto eye = parseVec3("--eye", *args.eye);
    auto target = parseVec3("--target", *args.target);
    auto up = parseVec3("--up", args.up.value_or("0,1,0"));
    for (const Status* s : {&eye.status(), &target.status(), &up.status()})
        if (!s->ok())
            return *s;
    if (glm::length(*target - *eye) <= 0.0f)
        return Status::error("--eye and --target must be different points");
    const raster::Bounds bounds = raster::worldBounds(scene);
    float far_dist = 1.0f;
    if (!bounds.empty)
        for (int i = 0; i < 8; ++i) {
            const glm::vec3 corner((i & 1) ? bounds.max.x : bounds.min.x,
                                   (i & 2) ? bounds.max.y : bounds.min.y,
                                   (i & 4) ? bounds.max.z : bounds.min.z);
            far_dist = std::max(far_dist, 1.01f * glm::length(corner - *eye));
        }
    return raster::viewLookAt(*eye, *target, *up, args.yfov_deg.value_or(45.0f) * kPi / 180.0f,
                              args.width, args.height, args.znear.value_or(1e-3f * far_dist),
                              args.zfar.value_or(far_dist));
}

} // namespace

Result<glm::uvec2> parsePixel(const std::string& option, const std::string& text) {
    long long x = -1, y = -1;
    char comma = 0;
    std::istringstream in(text);
    in >> x >> comma >> y;
    if (!in || comma != ',' || !(in >> std::ws).eof() || x < 0 || y < 0 || x > 1000000 ||
        y > 1000000)
        return Status::error(option + " expects a pixel X,Y (integers >= 0), got '" + text + "'");
    return glm::uvec2(uint32_t(x), uint32_t(y));
}

Status checkRenderArgs(const RenderArgs& args) {
    if (args.tile % 8 != 0)
        return Status::error("--tile " + std::to_string(args.tile) + " must be a multiple of 8");
    if (!args.depth_out.empty() && !isLinearFormat(args.depth_out))
        return Status::error(args.depth_out + ": --depth-out must be an .exr file");
    Result<dof::LensRequest> lens = lensRequestOf(args);
    if (!lens.ok())
        return lens.status();
    if (Status s = dof::validate(*lens); !s.ok())
        return Status::error(withOptionNames(s.message()));
    if (!std::isfinite(args.aperture_rotation_deg))
        return Status::error("--aperture-rotation must be a finite angle in degrees");
    return {};
}

bool hasLensOptions(const RenderArgs& args) {
    return args.aperture_radius || args.fstop || args.focus_distance || args.focus_pixel ||
           args.aperture_shape || args.aperture_blades || !args.aperture_image.empty() ||
           args.accum.pixel_jitter;
}

raster::RenderOptions renderOptionsOf(const RenderArgs& args) {
    raster::RenderOptions options;
    options.tile_size = args.tile;
    options.depth_format = args.depth_format == "unorm16" ? raster::DepthFormat::Unorm16
                                                          : raster::DepthFormat::Float32;
    options.shading = args.shading == "unlit" ? raster::ShadingMode::Unlit
                      : args.shading == "lit" ? raster::ShadingMode::Lit
                                              : raster::ShadingMode::Material;
    options.texture_filter = args.texture_filter == "nearest"    ? raster::FilterOverride::Nearest
                             : args.texture_filter == "bilinear" ? raster::FilterOverride::Bilinear
                             : args.texture_filter == "trilinear"
                                 ? raster::FilterOverride::Trilinear
                                 : raster::FilterOverride::Sampler;
    options.simd = !args.no_simd;
    options.memory_budget = parseMemoryBudget(args.memory_budget).value(); // checked by CLI11
    return options;
}

TargetStorage targetStorageOf(const RenderArgs& args) {
    TargetStorage t;
    if (args.precision) {
        t.color = *args.precision == 16 ? raster::ColorFormat::Half : raster::ColorFormat::Float32;
        t.depth =
            *args.precision == 16 ? raster::DepthFormat::Unorm16 : raster::DepthFormat::Float32;
    }
    if (args.target_color)
        t.color =
            *args.target_color == "half" ? raster::ColorFormat::Half : raster::ColorFormat::Float32;
    if (args.target_depth)
        t.depth = *args.target_depth == "unorm16" ? raster::DepthFormat::Unorm16
                                                  : raster::DepthFormat::Float32;
    return t;
}

Result<raster::View> resolveView(const raster::Scene& scene, const RenderArgs& args) {
    if (args.eye || args.target)
        return lookAtView(scene, args);
    raster::View view;
    if (!scene.cameras.empty() || args.camera) {
        const int index = args.camera.value_or(0);
        if (index < 0 || size_t(index) >= scene.cameras.size())
            return Status::error(scene.source + ": has no camera " + std::to_string(index) +
                                 " (it has " + std::to_string(scene.cameras.size()) + ")");
        view = raster::viewFromCamera(scene.cameras[size_t(index)], args.width, args.height);
    } else {
        view = raster::viewFramingBounds(raster::worldBounds(scene), args.width, args.height);
    }
    if (args.yfov_deg)
        view.yfov = *args.yfov_deg * kPi / 180.0f;
    if (args.znear)
        view.znear = *args.znear;
    if (args.zfar)
        view.zfar = *args.zfar;
    return view;
}

Result<dof::LensRequest> lensRequestOf(const RenderArgs& args) {
    dof::LensRequest r;
    r.aperture_radius = args.aperture_radius;
    r.fstop = args.fstop;
    r.focal_length_mm = args.focal_length_mm;
    r.sensor_height_mm = args.sensor_height_mm;
    r.focus_distance = args.focus_distance;
    if (args.focus_pixel) {
        Result<glm::uvec2> pixel = parsePixel("--focus-pixel", *args.focus_pixel);
        if (!pixel.ok())
            return pixel.status();
        r.focus_pixel = *pixel;
    }
    r.view_focus = args.eye.has_value();
    r.pinhole_image = args.method == "pinhole";
    return r;
}

Result<dof::ApertureShape> resolveAperture(const RenderArgs& args) {
    dof::ApertureShape shape;
    std::string kind = args.aperture_shape.value_or(
        !args.aperture_image.empty() ? "image" : (args.aperture_blades ? "polygon" : "circle"));
    if (kind == "polygon") {
        shape.kind = dof::ApertureKind::Polygon;
        shape.blades = args.aperture_blades.value_or(6);
        shape.rotation_deg = args.aperture_rotation_deg;
    } else if (kind == "image") {
        if (args.aperture_image.empty())
            return Status::error("--aperture-shape image needs --aperture-image FILE");
        Result<ImageData> img = readImage(args.aperture_image);
        if (!img.ok())
            return img.status();
        // Transmission: mean of RGB (or grey) in linear light, times alpha when present.
        shape.kind = dof::ApertureKind::Image;
        shape.mask.width = img->width;
        shape.mask.height = img->height;
        const uint32_t ch = img->channels;
        shape.mask.transmission.resize(size_t(img->width) * img->height);
        for (size_t i = 0; i < shape.mask.transmission.size(); ++i) {
            const float* p = &img->pixels[i * ch];
            float t = ch >= 3 ? (p[0] + p[1] + p[2]) / 3.0f : p[0];
            if (ch == 2 || ch == 4)
                t *= p[ch - 1];
            shape.mask.transmission[i] = std::max(t, 0.0f);
        }
    } else if (kind != "circle") {
        return Status::error("unknown --aperture-shape " + kind);
    }
    if (kind != "polygon" && args.aperture_blades)
        return Status::error("--aperture-blades needs --aperture-shape polygon");
    if (kind != "image" && !args.aperture_image.empty())
        return Status::error("--aperture-image needs --aperture-shape image");
    return shape;
}

dof::LensPattern lensPatternOf(const std::string& name) {
    return name == "halton"    ? dof::LensPattern::Halton
           : name == "poisson" ? dof::LensPattern::Poisson
                               : dof::LensPattern::Hammersley;
}

} // namespace focal
