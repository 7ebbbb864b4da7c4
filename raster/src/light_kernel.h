// The lighting kernel: Lambert + energy-normalised Blinn-Phong over the scene's punctual lights,
// plus ambient and emissive, for up to two blocks of kLightLanes fragments at once. Like the quad
// kernel it is written once (light_kernel.inl) as branch-free lane loops and compiled twice — the
// scalar reference and an AVX2 build — with the same bits; powers use focal's own exp2/log2 so the
// lane loops need no library calls. Consumes prepared lights (per frame); writes the lanes' colour.
#pragma once

#include <raster/scene.h>

#include <glm/vec3.hpp>

#include <cstdint>
#include <vector>

namespace raster {

constexpr int kLightLanes = 8;

// A light as the kernel uses it: radiance, unit direction of travel, cone and range constants.
struct PreparedLight {
    Light::Type type = Light::Type::Directional;
    float radiance[3] = {0, 0, 0};   // colour x intensity
    float direction[3] = {0, 0, -1}; // unit, direction the light travels
    float position[3] = {0, 0, 0};
    float inv_range2 = 0.0f; // 1/range^2, 0 = infinite range
    // Spot cone: smooth step from cos_outer to cos_inner, 1/max(cos_inner - cos_outer, 1e-4).
    // The defaults make the factor exactly 1 for any direction (point lights).
    float cos_outer = -2.0f;
    float inv_cone_width = 1.0f;
};

// The scene's lights, or one default directional light of intensity pi travelling along
// `default_direction` when it has none.
void prepareLights(const Scene& scene, glm::vec3 default_direction,
                   std::vector<PreparedLight>& out);

// Surface material constants shared by the lanes (one material per triangle).
struct LightMaterial {
    float metallic = 0.0f;
    float roughness = 1.0f;
};

// Structure-of-arrays inputs and the output colour of the lanes.
struct LightLanes {
    float albedo[3][kLightLanes];
    float emissive[3][kLightLanes];
    float world[3][kLightLanes];
    float normal[3][kLightLanes]; // any length; (0,0,0) means "use +z"
    float rgb[3][kLightLanes];    // output
};

// Shades `blocks` (1 or 2) blocks of lanes, io[0 .. blocks): every lane of a block before the
// last and lanes [0, lanes) of the last. The SIMD build computes every lane of every block in
// one vector pass per block (the lanes are independent, so the bits of the lanes asked for are
// the same): every lane of io's inputs must be initialised, and the rgb of the lanes past
// `lanes` is overwritten with any value. Two blocks cost it about 1.4 times one, not twice: their
// dependency chains are interleaved (light_kernel.inl).
using LightKernel = void (*)(const PreparedLight* lights, uint32_t light_count,
                             const LightMaterial& material, const float eye[3], LightLanes* io,
                             int blocks, int lanes);

void lightKernelScalar(const PreparedLight* lights, uint32_t light_count,
                       const LightMaterial& material, const float eye[3], LightLanes* io,
                       int blocks, int lanes);
LightKernel lightKernelAvx2(); // nullptr when not compiled in
LightKernel selectLightKernel(bool simd);

} // namespace raster
