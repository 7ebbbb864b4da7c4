// The fragment kernel: a triangle's vertex attributes at the 8 lanes of a quad pair. Consumes the
// quad kernel's perspective-correct barycentrics, the triangle's vertex colours, positions and
// normals, its material's factors and alpha mode, and the texels the texture kernel fetched;
// writes each lane's base colour, emissive, world position and normal in the lighting kernel's
// layout (LightLanes), its opacity, and which lanes survive the alpha test. Like the quad,
// lighting and texture kernels it is written once (fragment_kernel.inl) as lane loops and
// compiled twice, the scalar reference and an AVX2 build; every lane does the same IEEE
// operations in the same order in both (tests/unit/raster/simd_test.cpp, the goldens).
#pragma once

#include "light_kernel.h"
#include "quad_kernel.h"

#include <cstdint>

namespace raster {

static_assert(kLightLanes == kQuadLanes, "the fragment kernel fills a quad pair's light lanes");

// What the lanes of one triangle share, set up once per triangle. Vertex arrays are
// [component][vertex].
struct FragmentTriangle {
    float color[4][3] = {};    // vertex colours; read only when has_colors
    float world[3][3] = {};    // world positions
    float normal[3][3] = {};   // world normals; read only when has_normals
    float face_normal[3] = {}; // facing the eye: the normal of a primitive without normals
    float base_factor[4] = {}; // the material's base colour factor
    float emissive_factor[3] = {};
    float alpha_cutoff = 0.5f;
    bool has_colors = false;  // false: the vertex colour is exactly white
    bool has_normals = false; // false: every lane takes face_normal
    bool flip_normal = false; // glTF: back faces of double-sided materials flip the normal
    bool mask = false;        // alphaMode MASK: drop lanes whose alpha is below the cutoff
    bool blend = false;       // alphaMode BLEND: drop lanes of opacity 0; alpha is clamped
};

// For the lanes set in `lanes`: interpolates with the barycentrics `persp`, multiplies in the
// texels (`base_texel`, `emissive_texel`; nullptr: not textured) and returns the lanes that pass
// the alpha test, with their albedo, emissive, world and normal in `out` and their opacity in
// `alpha` (1 unless BLEND). The texel arrays and `persp` must be initialised in every lane: the
// SIMD build computes all kQuadLanes lanes (the others' outputs are then unspecified); the
// scalar one computes lanes up to the highest set in `lanes`.
using FragmentKernel = uint32_t (*)(const FragmentTriangle& tri, const float persp[3][kQuadLanes],
                                    const float (*base_texel)[kQuadLanes],
                                    const float (*emissive_texel)[kQuadLanes], uint32_t lanes,
                                    LightLanes& out, float alpha[kQuadLanes]);

uint32_t fragmentKernelScalar(const FragmentTriangle& tri, const float persp[3][kQuadLanes],
                              const float (*base_texel)[kQuadLanes],
                              const float (*emissive_texel)[kQuadLanes], uint32_t lanes,
                              LightLanes& out, float alpha[kQuadLanes]);
FragmentKernel fragmentKernelAvx2(); // nullptr when not compiled in (FOCAL_NO_SIMD)
FragmentKernel selectFragmentKernel(bool simd);

} // namespace raster
