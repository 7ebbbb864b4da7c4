#include "shading.h"

#include <glm/exponential.hpp>
#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>

#include <algorithm>
#include <cmath>

namespace raster {

namespace {

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

} // namespace

TextureRoles sampledTextureRoles(ShadingMode) {
    // baseColor() and emissiveColor() are the only texture reads, and every mode makes them
    // (lighting takes metallic and roughness from the material's factors alone).
    return TextureRoles{} | TextureRole::BaseColor | TextureRole::Emissive;
}

glm::vec4 baseColor(const ShadeContext& ctx, const Material& m, const UvFootprint& uv,
                    glm::vec4 vertex_color) {
    glm::vec4 c = m.base_color_factor * vertex_color;
    if (m.base_color_texture.image >= 0)
        c *= sampleRef(ctx, m.base_color_texture, uv);
    return c;
}

bool isUnlit(const ShadeContext& ctx, const Material& m) {
    return ctx.mode == ShadingMode::Unlit || (ctx.mode == ShadingMode::Material && m.unlit);
}

glm::vec3 emissiveColor(const ShadeContext& ctx, const Material& m, const UvFootprint& uv) {
    glm::vec3 emissive = m.emissive_factor;
    if (m.emissive_texture.image >= 0 && emissive != glm::vec3(0.0f))
        emissive *= glm::vec3(sampleRef(ctx, m.emissive_texture, uv));
    return emissive;
}

GSample surfaceSample(const ShadeContext& ctx, const Material& m, const UvFootprint& uv,
                      glm::vec4 base, glm::vec3 normal) {
    GSample g;
    const float len = glm::length(normal);
    g.normal = len > 0.0f ? normal / len : glm::vec3(0.0f, 0.0f, 1.0f);
    g.base_color = glm::vec3(base);
    g.metallic = m.metallic_factor;
    g.roughness = m.roughness_factor;
    g.emissive = emissiveColor(ctx, m, uv);
    g.unlit = isUnlit(ctx, m) ? 1.0f : 0.0f;
    return g;
}

glm::vec3 shadeSample(const ShadeContext& ctx, const GSample& g, glm::vec3 world, glm::vec3 eye) {
    if (g.unlit != 0.0f)
        return g.base_color + g.emissive;
    LightLanes lanes;
    for (int c = 0; c < 3; ++c) {
        lanes.albedo[c][0] = g.base_color[c];
        lanes.emissive[c][0] = g.emissive[c];
        lanes.world[c][0] = world[c];
        lanes.normal[c][0] = g.normal[c];
    }
    const float eye3[3] = {eye.x, eye.y, eye.z};
    ctx.light_kernel(ctx.lights, ctx.light_count, {g.metallic, g.roughness}, eye3, lanes, 1);
    return {lanes.rgb[0][0], lanes.rgb[1][0], lanes.rgb[2][0]};
}

} // namespace raster
