#include "shading.h"

#include <algorithm>
#include <cmath>

#include <glm/exponential.hpp>
#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>

namespace raster {

namespace {

constexpr float kPi = 3.14159265358979f;
// Constant ambient light (fraction of the base colour) so surfaces facing away stay visible.
constexpr float kAmbient = 0.12f;
// The default light: a directional light whose irradiance makes a facing surface show its albedo.
constexpr float kDefaultLightIntensity = kPi;

glm::vec4 sampleRef(const ShadeContext& ctx, const TextureRef& ref, const UvFootprint& fp) {
    const Scene& scene = *ctx.scene;
    const Image& image = scene.images[size_t(ref.image)];
    static const Sampler kDefaultSampler{};
    const Sampler& sampler =
        ref.sampler >= 0 ? scene.samplers[size_t(ref.sampler)] : kDefaultSampler;
    // KHR_texture_transform: uv' = M (u, v, 1); derivatives transform by the linear part.
    const glm::vec2 uv = glm::vec2(ref.transform * glm::vec3(fp.uv, 1.0f));
    const glm::mat2 lin(glm::vec2(ref.transform[0]), glm::vec2(ref.transform[1]));
    const glm::vec2 size(float(image.levels[0].width), float(image.levels[0].height));
    const glm::vec2 dx = lin * fp.duv_dx * size, dy = lin * fp.duv_dy * size;
    // glTF/OpenGL LOD: log2 of the longer footprint axis in texels (OpenGL 4.6 §8.14.1).
    const float rho2 = std::max(glm::dot(dx, dx), glm::dot(dy, dy));
    const float lod = rho2 > 0.0f ? 0.5f * std::log2(rho2) : -1.0f;
    return sampleImage(image, sampler, ctx.filter, uv, lod);
}

}  // namespace

glm::vec4 baseColor(const ShadeContext& ctx, const Material& m, const UvFootprint& uv,
                    glm::vec4 vertex_color) {
    glm::vec4 c = m.base_color_factor * vertex_color;
    if (m.base_color_texture.image >= 0)
        c *= sampleRef(ctx, m.base_color_texture, uv);
    return c;
}

namespace {

// Lambert + energy-normalised Blinn-Phong over the scene's lights, plus ambient and emissive.
glm::vec3 lightSurface(const ShadeContext& ctx, glm::vec3 albedo, float metallic_factor,
                       float roughness_factor, glm::vec3 emissive, glm::vec3 world,
                       glm::vec3 normal, glm::vec3 eye) {
    const float len = glm::length(normal);
    const glm::vec3 n = len > 0.0f ? normal / len : glm::vec3(0.0f, 0.0f, 1.0f);
    const glm::vec3 v = glm::normalize(eye - world);
    const float metallic = std::clamp(metallic_factor, 0.0f, 1.0f);
    const float alpha = std::max(roughness_factor * roughness_factor, 0.02f);
    // Blinn-Phong exponent matching a GGX-like lobe of roughness alpha (Walter et al. 2007).
    const float shininess = 2.0f / (alpha * alpha) - 2.0f;
    const glm::vec3 diffuse = albedo * (1.0f - metallic) * (1.0f / kPi);
    const glm::vec3 f0 = glm::mix(glm::vec3(0.04f), albedo, metallic);
    const float spec_norm = (shininess + 8.0f) / (8.0f * kPi);

    glm::vec3 result = emissive + kAmbient * albedo;
    auto addLight = [&](glm::vec3 l, glm::vec3 radiance) {
        const float n_dot_l = glm::dot(n, l);
        if (!(n_dot_l > 0.0f))
            return;
        const glm::vec3 h = glm::normalize(l + v);
        const float n_dot_h = std::max(glm::dot(n, h), 0.0f);
        const glm::vec3 brdf = diffuse + f0 * (spec_norm * std::pow(n_dot_h, shininess));
        result += brdf * radiance * n_dot_l;
    };
    if (ctx.scene->lights.empty()) {
        addLight(-ctx.default_light_dir, glm::vec3(kDefaultLightIntensity));
        return result;
    }
    for (const Light& light : ctx.scene->lights) {
        const glm::vec3 radiance = light.color * light.intensity;
        if (light.type == Light::Type::Directional) {
            addLight(-glm::normalize(light.direction), radiance);
            continue;
        }
        const glm::vec3 to_light = light.position - world;
        const float dist2 = std::max(glm::dot(to_light, to_light), 1e-8f);
        const glm::vec3 l = to_light / std::sqrt(dist2);
        // KHR_lights_punctual: inverse square with a smooth window at `range`.
        float attenuation = 1.0f / dist2;
        if (light.range > 0.0f) {
            const float r = dist2 / (light.range * light.range);
            attenuation *= std::clamp(1.0f - r * r, 0.0f, 1.0f);
        }
        if (light.type == Light::Type::Spot) {
            const float cos_outer = std::cos(light.outer_cone_angle);
            const float cos_inner = std::cos(light.inner_cone_angle);
            const float cd = glm::dot(glm::normalize(light.direction), -l);
            const float t = std::clamp((cd - cos_outer) / std::max(cos_inner - cos_outer, 1e-4f),
                                       0.0f, 1.0f);
            attenuation *= t * t;
        }
        addLight(l, radiance * attenuation);
    }
    return result;
}

bool isUnlit(const ShadeContext& ctx, const Material& m) {
    return ctx.mode == ShadingMode::Unlit || (ctx.mode == ShadingMode::Material && m.unlit);
}

glm::vec3 emissiveOf(const ShadeContext& ctx, const Material& m, const UvFootprint& uv) {
    glm::vec3 emissive = m.emissive_factor;
    if (m.emissive_texture.image >= 0 && emissive != glm::vec3(0.0f))
        emissive *= glm::vec3(sampleRef(ctx, m.emissive_texture, uv));
    return emissive;
}

}  // namespace

glm::vec3 shadeColor(const ShadeContext& ctx, const Material& m, const UvFootprint& uv,
                     glm::vec4 base, glm::vec3 world, glm::vec3 normal) {
    const glm::vec3 emissive = emissiveOf(ctx, m, uv);
    if (isUnlit(ctx, m))
        return glm::vec3(base) + emissive;
    return lightSurface(ctx, glm::vec3(base), m.metallic_factor, m.roughness_factor, emissive,
                        world, normal, ctx.eye);
}

GSample surfaceSample(const ShadeContext& ctx, const Material& m, const UvFootprint& uv,
                      glm::vec4 base, glm::vec3 normal) {
    GSample g;
    const float len = glm::length(normal);
    g.normal = len > 0.0f ? normal / len : glm::vec3(0.0f, 0.0f, 1.0f);
    g.base_color = glm::vec3(base);
    g.metallic = m.metallic_factor;
    g.roughness = m.roughness_factor;
    g.emissive = emissiveOf(ctx, m, uv);
    g.unlit = isUnlit(ctx, m) ? 1.0f : 0.0f;
    return g;
}

glm::vec3 shadeSample(const ShadeContext& ctx, const GSample& g, glm::vec3 world, glm::vec3 eye) {
    if (g.unlit != 0.0f)
        return g.base_color + g.emissive;
    return lightSurface(ctx, g.base_color, g.metallic, g.roughness, g.emissive, world, g.normal,
                        eye);
}

}  // namespace raster
