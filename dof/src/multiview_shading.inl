// Multiview's shading (§5): colours of hits and cone footprints shaded per ray from the
// G-buffer, with the environment reflection. Consumes the Tracer, the layers' G-buffers and
// stored depths; produces linear RGB; owns nothing. Included only by multiview_tracer.cpp (via
// multiview_cones.inl), so both traceTile copies inline it.
#pragma once

#include "multiview_tracer.h"

#include <glm/geometric.hpp>

namespace dof::multiview_detail {
namespace {

constexpr float kPi = 3.14159265358979f;

float distanceFromD(const raster::View& view, float d_stored) {
    return raster::distanceFromDepth(view, d_stored);
}

glm::vec3 envLookup(const EnvironmentMap& env, glm::vec3 dir) {
    const float u = 0.5f + std::atan2(dir.x, -dir.z) / (2.0f * kPi);
    const float v = std::acos(std::clamp(dir.y, -1.0f, 1.0f)) / kPi;
    const uint32_t x = std::min(uint32_t(std::max(u, 0.0f) * float(env.width)), env.width - 1);
    const uint32_t y = std::min(uint32_t(std::max(v, 0.0f) * float(env.height)), env.height - 1);
    const float* p = env.rgb.data() + (size_t(y) * env.width + x) * 3;
    return glm::vec3(p[0], p[1], p[2]) * env.intensity;
}

// World position of texel `texel` at stored depth t (pinhole through the lens centre).
glm::vec3 texelWorld(const Tracer& tr, uint32_t texel, float t) {
    const raster::View& view = *tr.view;
    const float d = distanceFromD(view, t);
    const uint32_t ix = texel % tr.width, iy = texel / tr.width;
    const float f_px = tr.lens->focal_length_px;
    const float sx = (float(ix) + 0.5f - 0.5f * float(tr.width)) / f_px;
    const float sy = (float(iy) + 0.5f - 0.5f * float(tr.height)) / f_px;
    return view.eye + d * (view.forward + sx * view.right - sy * view.up);
}

// With an environment map: a Schlick-Fresnel mirror reflection attenuated by roughness.
glm::vec3 envReflection(const Tracer& tr, const raster::GSample& g, glm::vec3 world,
                        glm::vec3 eye) {
    const EnvironmentMap* env = tr.settings->env_map;
    if (!env || g.unlit != 0.0f)
        return glm::vec3(0.0f);
    const glm::vec3 vdir = glm::normalize(eye - world);
    const float n_dot_v = std::max(glm::dot(g.normal, vdir), 0.0f);
    const glm::vec3 r = glm::reflect(-vdir, g.normal);
    const glm::vec3 f0 = glm::mix(glm::vec3(0.04f), g.base_color, g.metallic);
    const float m = 1.0f - n_dot_v;
    const glm::vec3 fresnel = f0 + (glm::vec3(1.0f) - f0) * (m * m * m * m * m);
    const float gloss = (1.0f - g.roughness) * (1.0f - g.roughness);
    return fresnel * gloss * envLookup(*env, r);
}

// §5: shade G-buffer sample g at `world` from lens point `eye`: the rasterizer's Phong model
// (raster::SurfaceShader) plus the environment reflection.
glm::vec3 shadeSample(const Tracer& tr, const raster::GSample& g, glm::vec3 world, glm::vec3 eye) {
    return tr.shader->shade(g, world, eye) + envReflection(tr, g, world, eye);
}

glm::vec3 shadeHit(const Tracer& tr, uint32_t l, uint32_t texel, float t, glm::vec3 eye) {
    const raster::LayeredTarget& lt = *tr.layers;
    return shadeSample(tr, lt.gbuffer[lt.index(l, texel)], texelWorld(tr, texel, t), eye);
}

// §4.4 + §5: the mean shaded colour of the covered texels among five taps of a cone of radius
// `radius` px around image position (px, py) in layer l (the centre and +-radius/2 along x and
// y), each shaded at its own stored depth; none when no tap is covered.
std::optional<glm::vec3> shadeTaps(const Tracer& tr, uint32_t l, float px, float py, float radius,
                                   glm::vec3 eye) {
    const raster::LayeredTarget& lt = *tr.layers;
    const std::vector<float>& depth = tr.scratch->depth[l];
    const float hr = 0.5f * radius;
    const std::array<glm::vec2, 5> taps = {
        {{0.0f, 0.0f}, {-hr, 0.0f}, {hr, 0.0f}, {0.0f, -hr}, {0.0f, hr}}};
    glm::vec3 sum(0.0f);
    uint32_t count = 0;
    for (const glm::vec2& o : taps) {
        const float x = std::floor(px + o.x), y = std::floor(py + o.y);
        if (x < 0.0f || y < 0.0f || x >= float(tr.width) || y >= float(tr.height))
            continue;
        const uint32_t ti = uint32_t(y) * tr.width + uint32_t(x);
        if (!(lt.color.load(lt.index(l, ti)).a > 0.0f))
            continue;
        sum += shadeHit(tr, l, ti, depth[ti], eye);
        ++count;
    }
    if (count == 0)
        return std::nullopt;
    return sum / float(count);
}

// The shaded colour of a cone hit on texel `texel` at depth t: ConeShading::Footprint uses the
// taps (the hit texel when none is covered), Centre shades the hit texel.
glm::vec3 shadeFootprint(const Tracer& tr, uint32_t l, uint32_t texel, float t, float px, float py,
                         float radius, glm::vec3 eye) {
    if (tr.settings->cone_shading == ConeShading::Footprint && radius > 0.5f)
        if (const std::optional<glm::vec3> c = shadeTaps(tr, l, px, py, radius, eye))
            return *c;
    return shadeHit(tr, l, texel, t, eye);
}

} // namespace
} // namespace dof::multiview_detail
