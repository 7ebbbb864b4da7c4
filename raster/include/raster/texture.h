// Textures: decoded images with their mip chains, samplers, and filtered lookups.
// Produced by glTF import and the built-in scene generators (owned by the Scene); sampled by the
// tile raster. Texels are 8-bit RGBA as on a GPU; sRGB images are decoded to linear light
// *before* filtering (a 256-entry table), and mip levels are box-filtered in linear space.
#pragma once

#include <glm/vec2.hpp>
#include <glm/vec4.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace raster {

enum class Wrap : uint8_t { Repeat, ClampToEdge, MirroredRepeat };
enum class Filter : uint8_t { Nearest, Linear };
enum class MipFilter : uint8_t { None, Nearest, Linear };

// glTF sampler (glTF 2.0 §5.26); minification picks the filter inside and between levels.
struct Sampler {
    Wrap wrap_s = Wrap::Repeat;
    Wrap wrap_t = Wrap::Repeat;
    Filter mag = Filter::Linear;
    Filter min = Filter::Linear;
    MipFilter mip = MipFilter::Linear;
};

struct MipLevel {
    uint32_t width = 0;
    uint32_t height = 0;
    std::vector<uint8_t> rgba8; // width*height*4, row 0 is the top row (glTF uv (0,0))
    // The same texels decoded as a lookup decodes them (linear RGBA floats, sRGB colour through
    // the decoding table), for levels of at most kLinearLevelMaxTexels texels (buildMipChain);
    // empty otherwise. The texture kernel loads a texel's four channels from here in one
    // access instead of gathering its word and then three table entries, and the one-fragment
    // lookup (sampleImage) reads them too.
    std::vector<float> linear;
    // Per block of kTexelBlockSide x kTexelBlockSide texels (row-major, blocksX() per row):
    // bit 0 set when some texel of the block has a non-zero colour channel, bit 1 when some
    // has a non-zero alpha. Filled by buildMipChain; empty (nothing known) otherwise. Lets a
    // lookup whose taps all read zero texels be skipped (zeroTexels): an emissive map is
    // mostly black.
    std::vector<uint8_t> nonzero;

    uint32_t blocksX() const;
};

// The side of the texel blocks MipLevel::nonzero describes.
constexpr uint32_t kTexelBlockSide = 8;

// The largest mip level that also keeps its decoded texels (MipLevel::linear): 1024 x 1024,
// 16 MB next to the level's 4 MB of bytes. A larger level 0 keeps only its bytes; its smaller
// levels, which minified lookups read, are decoded.
constexpr uint64_t kLinearLevelMaxTexels = uint64_t{1} << 20;

// What a material samples a texture for (glTF 2.0 §3.9.2-3.9.5).
enum class TextureRole : uint8_t { BaseColor, Emissive, MetallicRoughness, Normal, Occlusion };
constexpr uint32_t kTextureRoleCount = 5;

// A set of texture roles, one bit per TextureRole.
struct TextureRoles {
    uint8_t bits = 0;

    static constexpr TextureRoles all() { return {uint8_t((1u << kTextureRoleCount) - 1)}; }
    constexpr bool has(TextureRole role) const { return (bits >> uint32_t(role)) & 1u; }
    constexpr bool empty() const { return bits == 0; }
    constexpr TextureRoles operator|(TextureRole role) const {
        return {uint8_t(bits | (1u << uint32_t(role)))};
    }
    constexpr bool intersects(TextureRoles other) const { return (bits & other.bits) != 0; }
    constexpr bool operator==(const TextureRoles&) const = default;
};

// "base colour", "emissive", "metallic-roughness", "normal", "occlusion".
const char* textureRoleName(TextureRole role);

struct Image {
    std::string name;
    bool srgb = true;             // colour channels sRGB-encoded (base colour, emissive)
    std::vector<MipLevel> levels; // levels[0] is the full image; buildMipChain adds the rest
    // What the scene's materials use the image for (glTF import; empty for built-in scenes).
    TextureRoles roles;
    // False when import skipped the image because none of its roles was asked for
    // (ImportOptions::roles): `levels` is then empty and nothing may sample it.
    bool decoded = true;
    // Most of the levels' blocks have texels of zero colour (zero_colour_blocks), or zero colour
    // and alpha (zero_blocks): MipLevel::nonzero is worth asking before a lookup
    // (buildMipChain).
    bool zero_colour_blocks = false, zero_blocks = false;
};

// Replaces image.levels[1..] with the full chain down to 1x1: each texel of level i+1 is the
// average of the (up to) 2x2 texels of level i, computed in linear light and re-encoded. Then
// fills MipLevel::linear of every level of at most kLinearLevelMaxTexels texels, every level's
// MipLevel::nonzero and the image's zero-block flags.
void buildMipChain(Image& image);

// Whether every texel of `level` in [x0, x1] x [y0, y1] (inside the level) has zero colour
// channels, and zero alpha too with `alpha`, as MipLevel::nonzero tells (false when empty).
bool zeroTexels(const MipLevel& level, int64_t x0, int64_t x1, int64_t y0, int64_t y1, bool alpha);

// The filter the CLI may force on every sampler (--texture-filter).
enum class FilterOverride : uint8_t { Sampler, Nearest, Bilinear, Trilinear };

// Linear-light RGBA at uv with the level of detail `lod` (log2 of texels per pixel; <= 0 is
// magnification). Wrapping follows the sampler; filtering follows the sampler unless overridden.
glm::vec4 sampleImage(const Image& image, const Sampler& sampler, FilterOverride filter,
                      glm::vec2 uv, float lod);

// The levels and filter sampleImage uses at `lod` (image.levels must not be empty): level0
// filtered with `filter`, and when mix_levels, mixed with level1 by `weight`.
struct LevelSelection {
    uint32_t level0 = 0, level1 = 0;
    Filter filter = Filter::Linear;
    bool mix_levels = false;
    float weight = 0.0f;
};
LevelSelection selectLevels(const Image& image, const Sampler& sampler, FilterOverride filter,
                            float lod);

// sampleImage's lookup once the levels are selected (image.levels must not be empty).
glm::vec4 sampleLevels(const Image& image, const Sampler& sampler, const LevelSelection& s,
                       glm::vec2 uv);

// The 256-entry table decoding 8-bit sRGB to linear (srgbToLinear(i / 255)).
const float* srgbDecodeTable();

// sRGB transfer function, exact (IEC 61966-2-1).
float srgbToLinear(float v);
float linearToSrgb(float v);

} // namespace raster
