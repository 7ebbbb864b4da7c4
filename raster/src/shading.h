// Shading: turns an interpolated fragment into linear RGBA. Unlit (base colour x texture x
// vertex colour + emissive, KHR_materials_unlit) or lit (Lambert + energy-normalised
// Blinn-Phong over the scene's punctual lights, or a default light, plus a constant ambient).
// Consumes the Scene's materials and images (read-only); stateless.
#pragma once

#include "light_kernel.h"
#include "texture_kernel.h"

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
    ShadingMode mode = ShadingMode::Material;
    FilterOverride filter = FilterOverride::Sampler;
    const PreparedLight* lights = nullptr; // prepareLights(): the scene's or the default light
    uint32_t light_count = 0;
    LightKernel light_kernel = &lightKernelScalar;
    TextureKernel texture_kernel = &textureKernelScalar;
};

// Texture coordinates of the 8 lanes of two 2x2 quads (quad_kernel.h's lane order: lanes
// 4q..4q+3 are quad q, in the order (0, 0), (1, 0), (0, 1), (1, 1)), helper pixels included,
// one array per component so the lane loops over them vectorize. Each quad's screen
// derivatives are its lane 1 and lane 2 minus its lane 0 (coarse ddx, ddy).
struct QuadPairUv {
    alignas(32) float u[kTextureLanes];
    alignas(32) float v[kTextureLanes];
};

// `ref`'s texture at a quad pair, the part that needs the pair's helper pixels: one level of
// detail per quad, as GPUs compute it from the quad's derivatives, and the levels it selects
// (sel[q] for lanes 4q..4q+3), and every lane's coordinates after the texture transform and mip
// weight, ready for sampleLanes.
struct QuadPairLookup {
    LevelSelection sel[2];
    TextureLanes lanes;
};
void prepareQuadPair(const ShadeContext& ctx, const TextureRef& ref, const QuadPairUv& uv,
                     QuadPairLookup& out);

// Whether lookups of `a` and `b` at the same fragments read the same coordinates and select the
// same levels: the same texture coordinates, transform and sampler, and images of the same size
// and number of levels (what prepareQuadPair depends on besides the pair's coordinates).
bool sameFootprint(const Scene& scene, const TextureRef& a, const TextureRef& b);

// Whether two selections read the same levels the same way (their weights aside): lanes of both
// can share one texture kernel call.
bool sameLevels(const LevelSelection& a, const LevelSelection& b);

// `ref`'s texture at the lanes set in `lane_mask`, each at (lanes.u, lanes.v) on the levels `sel`
// selects with its own lanes.weight: linear RGBA per lane in lanes.rgba, the same bits as a
// lookup of that one fragment. Every lane of lanes.rgba is written (those not asked for with
// unspecified values: the fragment kernel reads them), and every lane's u, v and weight must be
// initialised. The lanes are filtered together by the texture kernel, or one by one when only a
// few are asked for (the kernel's cost does not depend on how many lanes are used).
// `colour_only`: the caller reads only the colour channels (emissive), so lookups that read only
// texels of zero colour are skipped whatever their alpha; otherwise only those whose texels are
// all zero. `lane_mask` is not empty.
void sampleLanes(const ShadeContext& ctx, const TextureRef& ref, const LevelSelection& sel,
                 uint32_t lane_mask, bool colour_only, TextureLanes& lanes);

// Whether fragments of `m` skip lighting (KHR_materials_unlit or --shading unlit).
bool isUnlit(const ShadeContext& ctx, const Material& m);

// The surface parameters a G-buffer keeps so a hit can be re-shaded from another view
// direction (Lee et al. 2009 §5): unit normal, albedo, metallic, roughness, emissive. `base` and
// `emissive` are the fragment's, as the tile raster computed them for its shading.
GSample surfaceSample(const ShadeContext& ctx, const Material& m, glm::vec3 base,
                      glm::vec3 emissive, glm::vec3 normal);

// Shades a G-buffer sample at `world` as seen from `eye` (the same lighting kernel as fragments).
glm::vec3 shadeSample(const ShadeContext& ctx, const GSample& g, glm::vec3 world, glm::vec3 eye);

} // namespace raster
