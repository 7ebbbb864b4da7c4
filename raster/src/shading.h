// Shading: turns an interpolated fragment into linear RGBA. Unlit (base colour x texture x
// vertex colour + emissive, KHR_materials_unlit) or lit (Lambert + energy-normalised
// Blinn-Phong over the scene's punctual lights, or a default light, plus a constant ambient).
// Consumes the Scene's materials and images (read-only); stateless.
#pragma once

#include <raster/layered_target.h>
#include <raster/renderer.h>
#include <raster/scene.h>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace raster {

// Per-frame constants shading needs.
struct ShadeContext {
    const Scene* scene = nullptr;
    glm::vec3 eye{0.0f};
    glm::vec3 default_light_dir{0.0f, -1.0f, 0.0f};  // used when the scene has no lights
    ShadingMode mode = ShadingMode::Material;
    FilterOverride filter = FilterOverride::Sampler;
};

// Texture coordinates and their screen derivatives (from the 2x2 quad) at one fragment.
struct UvFootprint {
    glm::vec2 uv{0.0f};
    glm::vec2 duv_dx{0.0f};
    glm::vec2 duv_dy{0.0f};
};

// Base colour and alpha: factor x vertex colour x base colour texture.
glm::vec4 baseColor(const ShadeContext& ctx, const Material& m, const UvFootprint& uv,
                    glm::vec4 vertex_color);

// Final linear RGB for a fragment with base colour `base`; `normal` faces the viewer side the
// fragment is seen from (unnormalised is fine).
glm::vec3 shadeColor(const ShadeContext& ctx, const Material& m, const UvFootprint& uv,
                     glm::vec4 base, glm::vec3 world, glm::vec3 normal);

// The surface parameters a G-buffer keeps so a hit can be re-shaded from another view
// direction (Lee et al. 2009 §5): unit normal, albedo, metallic, roughness, emissive.
GSample surfaceSample(const ShadeContext& ctx, const Material& m, const UvFootprint& uv,
                      glm::vec4 base, glm::vec3 normal);

// Shades a G-buffer sample at `world` as seen from `eye` (same model as shadeColor).
glm::vec3 shadeSample(const ShadeContext& ctx, const GSample& g, glm::vec3 world, glm::vec3 eye);

}  // namespace raster
