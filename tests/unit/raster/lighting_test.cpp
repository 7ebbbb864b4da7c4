// The lighting kernel computes the documented model (docs/raster.md §5) to float accuracy,
// with focal's own exp2/log2 standing in for std::pow.
#include "raster/src/light_kernel.h"

#include <raster/scene.h>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <cmath>

namespace focal::test {
namespace {

// The model in double precision with std::pow (directional lights only).
glm::dvec3 reference(const std::vector<raster::Light>& lights, glm::dvec3 albedo, double metallic,
                     double roughness, glm::dvec3 n, glm::dvec3 world, glm::dvec3 eye) {
    const double pi = 3.14159265358979323846;
    n = glm::normalize(n);
    const glm::dvec3 v = glm::normalize(eye - world);
    const double alpha = std::max(roughness * roughness, 0.02);
    const double s = 2.0 / (alpha * alpha) - 2.0;
    const glm::dvec3 diffuse = albedo * (1.0 - metallic) / pi;
    const glm::dvec3 f0 = 0.04 + (albedo - 0.04) * metallic;
    glm::dvec3 rgb = 0.12 * albedo;
    for (const raster::Light& light : lights) {
        const glm::dvec3 l = -glm::normalize(glm::dvec3(light.direction));
        const double ndl = glm::dot(n, l);
        if (ndl <= 0.0)
            continue;
        const glm::dvec3 h = glm::normalize(l + v);
        const double ndh = std::clamp(glm::dot(n, h), 0.0, 1.0);
        rgb += (diffuse + f0 * ((s + 8.0) / (8.0 * pi) * std::pow(ndh, s))) *
               (double(light.intensity) * ndl);
    }
    return rgb;
}

TEST(Lighting, KernelMatchesTheModel) {
    raster::Scene scene;
    raster::Light a, b;
    a.direction = {0.2f, -1.0f, -0.4f};
    a.intensity = 2.5f;
    b.direction = {-0.7f, -0.2f, -0.6f};
    b.intensity = 0.8f;
    scene.lights = {a, b};
    std::vector<raster::PreparedLight> lights;
    raster::prepareLights(scene, glm::vec3(0, -1, 0), lights);
    uint32_t state = 7u;
    auto unit = [&state] {
        state = state * 1664525u + 1013904223u;
        return float(state >> 8) / 16777216.0f;
    };
    const float eye[3] = {0.0f, 0.5f, 4.0f};
    for (int i = 0; i < 2000; ++i) {
        raster::LightLanes io{};
        const raster::LightMaterial m{unit(), 0.1f + 0.9f * unit()};
        for (int c = 0; c < 3; ++c) {
            io.albedo[c][0] = unit();
            io.world[c][0] = unit() - 0.5f;
            io.normal[c][0] = 2.0f * unit() - 1.0f;
        }
        raster::lightKernelScalar(lights.data(), uint32_t(lights.size()), m, eye, &io, 1, 1);
        const glm::dvec3 e =
            reference(scene.lights, {io.albedo[0][0], io.albedo[1][0], io.albedo[2][0]}, m.metallic,
                      m.roughness, {io.normal[0][0], io.normal[1][0], io.normal[2][0]},
                      {io.world[0][0], io.world[1][0], io.world[2][0]}, {eye[0], eye[1], eye[2]});
        for (int c = 0; c < 3; ++c)
            ASSERT_NEAR(io.rgb[c][0], e[c], 2e-4 * std::abs(e[c]) + 1e-5)
                << i << " c " << c << " m " << m.metallic << "," << m.roughness << " n "
                << io.normal[0][0] << "," << io.normal[1][0] << "," << io.normal[2][0] << " w "
                << io.world[0][0] << "," << io.world[1][0] << "," << io.world[2][0] << " a "
                << io.albedo[0][0] << "," << io.albedo[1][0] << "," << io.albedo[2][0];
    }
}

} // namespace
} // namespace focal::test
