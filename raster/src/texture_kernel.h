// The texture kernel: filtered lookups of one texture at 8 fragments at once (the quad kernel's
// lanes). Consumes mip levels of an Image (read-only, owned by the Scene) and per-lane uv; writes
// linear RGBA per lane. Like the quad and lighting kernels it is written once
// (texture_kernel.inl) as lane loops and compiled twice, the scalar reference and an AVX2 build;
// both give, lane by lane, the bits of raster::sampleImage (texture.h), which stays the
// one-fragment reference (tests/unit/raster/simd_test.cpp).
#pragma once

#include <raster/texture.h>

#include <cstdint>

namespace raster {

constexpr int kTextureLanes = 8;

// Limits of the kernel's integer arithmetic: texel coordinates are wrapped with a double
// division that is exact for sizes below 2^22, and texel indices y * width + x are int32.
constexpr uint32_t kTextureKernelMaxSide = (1u << 22) - 1;
constexpr uint64_t kTextureKernelMaxTexels = (uint64_t{1} << 31) - 1;

// The texels of a level read as 32-bit words (RGBA8, R in the low byte: little-endian only).
// may_alias: the words are read out of Image's byte vectors.
typedef uint32_t TexelWord __attribute__((may_alias));
static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "TexelWord assumes RGBA in memory order");

struct TextureLevel {
    const TexelWord* texels = nullptr; // width * height words, row 0 first
    int32_t width = 1, height = 1;     // within the kernel limits above
    // The texels decoded (MipLevel::linear: 4 floats each, as the query's decoding gives them),
    // or nullptr. The AVX2 build loads them when present; the scalar reference always decodes
    // the words, which is how the tests hold the two to the same bits.
    const float* linear = nullptr;
};

// What the lanes share: one filter inside the level(s), the wrap modes and the decoding.
struct TextureQuery {
    TextureLevel level[2];           // level[1] is read only when mix_levels
    const float* srgb_lut = nullptr; // 256-entry sRGB decoding table; nullptr: linear texels
    Wrap wrap_s = Wrap::Repeat, wrap_t = Wrap::Repeat;
    bool nearest = false;    // nearest texel instead of bilinear
    bool mix_levels = false; // trilinear: mix level[0] and level[1] by the lane's weight
};

struct TextureLanes {
    float u[kTextureLanes], v[kTextureLanes]; // texture coordinates (any value, NaN included)
    float weight[kTextureLanes];              // of level[1], when mix_levels
    float rgba[4][kTextureLanes];             // output: linear RGBA
};

using TextureKernel = void (*)(const TextureQuery& query, TextureLanes& io);

void textureKernelScalar(const TextureQuery& query, TextureLanes& io);
TextureKernel textureKernelAvx2(); // nullptr when not compiled in (FOCAL_NO_SIMD)
TextureKernel selectTextureKernel(bool simd);

} // namespace raster
