#include "apps/scene_info.h"

#include <algorithm>
#include <cstdarg>
#include <cstdio>
#include <string>
#include <vector>

namespace focal {
namespace {

constexpr double kPi = 3.14159265358979323846;

// printf-style append (snprintf keeps number formatting identical on every platform's C locale).
[[gnu::format(printf, 2, 3)]] void add(std::string& out, const char* format, ...) {
    va_list args;
    va_start(args, format);
    va_list copy;
    va_copy(copy, args);
    const int n = std::vsnprintf(nullptr, 0, format, copy);
    va_end(copy);
    if (n > 0) {
        const size_t old = out.size();
        out.resize(old + static_cast<size_t>(n) + 1);
        std::vsnprintf(out.data() + old, static_cast<size_t>(n) + 1, format, args);
        out.resize(old + static_cast<size_t>(n));
    }
    va_end(args);
}

std::string quoted(const std::string& name) {
    return name.empty() ? "" : " \"" + name + "\"";
}

const char* alphaModeName(raster::AlphaMode mode) {
    switch (mode) {
    case raster::AlphaMode::Opaque:
        return "OPAQUE";
    case raster::AlphaMode::Mask:
        return "MASK";
    case raster::AlphaMode::Blend:
        return "BLEND";
    }
    return "?";
}

const char* wrapName(raster::Wrap wrap) {
    switch (wrap) {
    case raster::Wrap::Repeat:
        return "repeat";
    case raster::Wrap::ClampToEdge:
        return "clamp-to-edge";
    case raster::Wrap::MirroredRepeat:
        return "mirrored-repeat";
    }
    return "?";
}

const char* filterName(raster::Filter filter) {
    return filter == raster::Filter::Nearest ? "nearest" : "linear";
}

const char* mipName(raster::MipFilter mip) {
    switch (mip) {
    case raster::MipFilter::None:
        return "none";
    case raster::MipFilter::Nearest:
        return "nearest";
    case raster::MipFilter::Linear:
        return "linear";
    }
    return "?";
}

const char* lightTypeName(raster::Light::Type type) {
    switch (type) {
    case raster::Light::Type::Directional:
        return "directional";
    case raster::Light::Type::Point:
        return "point";
    case raster::Light::Type::Spot:
        return "spot";
    }
    return "?";
}

std::string textureText(const char* what, const raster::TextureRef& ref) {
    if (ref.image < 0)
        return {};
    std::string out;
    add(out, ", %s texture: image %d", what, ref.image);
    if (ref.sampler >= 0)
        add(out, " sampler %d", ref.sampler);
    if (ref.texcoord != 0)
        add(out, " TEXCOORD_%u", ref.texcoord);
    if (ref.transform != glm::mat3(1.0f))
        out += " (transformed)";
    return out;
}

// ", used as base colour, emissive" (nothing for an image no material role uses).
std::string rolesText(raster::TextureRoles roles) {
    std::string out;
    for (uint32_t r = 0; r < raster::kTextureRoleCount; ++r) {
        const auto role = static_cast<raster::TextureRole>(r);
        if (roles.has(role))
            out += (out.empty() ? ", used as " : ", ") + std::string(raster::textureRoleName(role));
    }
    return out;
}

std::string joined(const std::vector<std::string>& items) {
    if (items.empty())
        return "none";
    std::string out;
    for (size_t i = 0; i < items.size(); ++i)
        out += (i ? ", " : "") + items[i];
    return out;
}

} // namespace

std::string describeLoad(const raster::ImportStats& stats) {
    std::string out;
    add(out, "load: %.1f ms (parse %.1f, images %.1f, scene %.1f); %u images decoded, %u skipped",
        stats.ms_total, stats.ms_parse, stats.ms_images, stats.ms_scene, stats.images_decoded,
        stats.images_skipped);
    if (stats.images_decoded > 0)
        add(out, "; per image, summed over threads: decode %.1f ms, mipmaps %.1f ms",
            stats.ms_decode, stats.ms_mipmaps);
    out += "\n";
    return out;
}

std::string describeScene(const raster::Scene& scene) {
    std::string out;
    add(out, "scene: %s\n", scene.source.empty() ? "(unnamed)" : scene.source.c_str());
    add(out, "triangles: %llu\n", static_cast<unsigned long long>(raster::triangleCount(scene)));
    add(out, "instances: %zu\n", scene.instances.size());

    size_t primitives = 0;
    for (const raster::Mesh& mesh : scene.meshes)
        primitives += mesh.primitives.size();
    add(out, "meshes: %zu (%zu primitives)\n", scene.meshes.size(), primitives);
    for (size_t i = 0; i < scene.meshes.size(); ++i) {
        const raster::Mesh& mesh = scene.meshes[i];
        size_t triangles = 0, vertices = 0;
        for (const raster::Primitive& prim : mesh.primitives) {
            triangles += prim.indices.size() / 3;
            vertices += prim.positions.size();
        }
        add(out, "  mesh %zu%s: %zu primitives, %zu triangles, %zu vertices\n", i,
            quoted(mesh.name).c_str(), mesh.primitives.size(), triangles, vertices);
    }

    add(out, "materials: %zu\n", scene.materials.size());
    for (size_t i = 0; i < scene.materials.size(); ++i) {
        const raster::Material& m = scene.materials[i];
        add(out, "  material %zu%s: %s", i, quoted(m.name).c_str(), alphaModeName(m.alpha_mode));
        if (m.alpha_mode == raster::AlphaMode::Mask)
            add(out, " (cutoff %g)", static_cast<double>(m.alpha_cutoff));
        if (m.double_sided)
            out += ", double-sided";
        if (m.unlit)
            out += ", unlit";
        add(out, ", base colour (%g, %g, %g, %g)", static_cast<double>(m.base_color_factor.x),
            static_cast<double>(m.base_color_factor.y), static_cast<double>(m.base_color_factor.z),
            static_cast<double>(m.base_color_factor.w));
        out += textureText("base colour", m.base_color_texture);
        if (m.emissive_factor != glm::vec3(0.0f))
            add(out, ", emissive (%g, %g, %g)", static_cast<double>(m.emissive_factor.x),
                static_cast<double>(m.emissive_factor.y), static_cast<double>(m.emissive_factor.z));
        out += textureText("emissive", m.emissive_texture);
        out += "\n";
    }

    const size_t skipped = static_cast<size_t>(
        std::count_if(scene.images.begin(), scene.images.end(),
                      [](const raster::Image& image) { return !image.decoded; }));
    add(out, "images: %zu", scene.images.size());
    if (skipped > 0)
        add(out, " (%zu not decoded: no shading mode samples them)", skipped);
    out += "\n";
    for (size_t i = 0; i < scene.images.size(); ++i) {
        const raster::Image& image = scene.images[i];
        add(out, "  image %zu%s: ", i, quoted(image.name).c_str());
        if (!image.decoded)
            out += "not decoded";
        else if (image.levels.empty())
            out += "no pixels";
        else
            add(out, "%ux%u, %zu mip levels, %s", image.levels[0].width, image.levels[0].height,
                image.levels.size(), image.srgb ? "sRGB" : "linear");
        out += rolesText(image.roles);
        out += "\n";
    }

    add(out, "samplers: %zu\n", scene.samplers.size());
    for (size_t i = 0; i < scene.samplers.size(); ++i) {
        const raster::Sampler& s = scene.samplers[i];
        add(out, "  sampler %zu: wrap %s/%s, mag %s, min %s, mip %s\n", i, wrapName(s.wrap_s),
            wrapName(s.wrap_t), filterName(s.mag), filterName(s.min), mipName(s.mip));
    }

    add(out, "cameras: %zu\n", scene.cameras.size());
    for (size_t i = 0; i < scene.cameras.size(); ++i) {
        const raster::Camera& c = scene.cameras[i];
        const glm::vec4 eye = c.world[3];
        add(out, "  camera %zu%s: yfov %.2f deg, near %g, far ", i, quoted(c.name).c_str(),
            static_cast<double>(c.yfov) * 180.0 / kPi, static_cast<double>(c.znear));
        if (c.zfar > 0.0f)
            add(out, "%g", static_cast<double>(c.zfar));
        else
            out += "infinite";
        if (c.aspect_ratio > 0.0f)
            add(out, ", aspect %g", static_cast<double>(c.aspect_ratio));
        add(out, ", at (%g, %g, %g)\n", static_cast<double>(eye.x), static_cast<double>(eye.y),
            static_cast<double>(eye.z));
    }

    add(out, "lights: %zu\n", scene.lights.size());
    for (size_t i = 0; i < scene.lights.size(); ++i) {
        const raster::Light& l = scene.lights[i];
        add(out, "  light %zu%s: %s, colour (%g, %g, %g), intensity %g", i, quoted(l.name).c_str(),
            lightTypeName(l.type), static_cast<double>(l.color.x), static_cast<double>(l.color.y),
            static_cast<double>(l.color.z), static_cast<double>(l.intensity));
        if (l.type != raster::Light::Type::Directional)
            add(out, ", at (%g, %g, %g)", static_cast<double>(l.position.x),
                static_cast<double>(l.position.y), static_cast<double>(l.position.z));
        if (l.type != raster::Light::Type::Point)
            add(out, ", direction (%g, %g, %g)", static_cast<double>(l.direction.x),
                static_cast<double>(l.direction.y), static_cast<double>(l.direction.z));
        out += "\n";
    }

    const raster::Bounds b = raster::worldBounds(scene);
    if (b.empty)
        out += "bounds: empty\n";
    else
        add(out, "bounds: min (%g, %g, %g) max (%g, %g, %g)\n", static_cast<double>(b.min.x),
            static_cast<double>(b.min.y), static_cast<double>(b.min.z),
            static_cast<double>(b.max.x), static_cast<double>(b.max.y),
            static_cast<double>(b.max.z));
    if (scene.lens)
        add(out, "lens hint: aperture radius %g, focus distance %g\n",
            static_cast<double>(scene.lens->aperture_radius),
            static_cast<double>(scene.lens->focus_distance));

    add(out, "extensions used: %s\n", joined(scene.extensions_used).c_str());
    add(out, "extensions required: %s\n", joined(scene.extensions_required).c_str());
    add(out, "warnings: %zu\n", scene.warnings.size());
    for (const std::string& w : scene.warnings)
        add(out, "  %s\n", w.c_str());
    return out;
}

} // namespace focal
