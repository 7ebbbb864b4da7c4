#include <raster/texture.h>

#include <glm/common.hpp>

#include <algorithm>
#include <array>
#include <cmath>

namespace raster {

float srgbToLinear(float v) {
    return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}

float linearToSrgb(float v) {
    return v <= 0.0031308f ? v * 12.92f : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
}

const char* textureRoleName(TextureRole role) {
    switch (role) {
    case TextureRole::BaseColor:
        return "base colour";
    case TextureRole::Emissive:
        return "emissive";
    case TextureRole::MetallicRoughness:
        return "metallic-roughness";
    case TextureRole::Normal:
        return "normal";
    case TextureRole::Occlusion:
        return "occlusion";
    }
    return "unknown";
}

namespace {

// Decoding table for 8-bit sRGB, built once (thread-safe static initialisation).
const std::array<float, 256>& srgbTable() {
    static const std::array<float, 256> table = [] {
        std::array<float, 256> t{};
        for (int i = 0; i < 256; ++i)
            t[size_t(i)] = srgbToLinear(float(i) / 255.0f);
        return t;
    }();
    return table;
}

uint8_t encode8(float v, bool srgb) {
    const float c = std::clamp(srgb ? linearToSrgb(v) : v, 0.0f, 1.0f);
    return uint8_t(c * 255.0f + 0.5f);
}

// Linear RGBA of texel (x, y); `lut` decodes sRGB colour channels (nullptr: linear image).
inline glm::vec4 fetch(const MipLevel& level, const float* lut, int x, int y) {
    const uint8_t* t = &level.rgba8[(size_t(y) * level.width + size_t(x)) * 4];
    if (lut)
        return {lut[t[0]], lut[t[1]], lut[t[2]], float(t[3]) * (1.0f / 255.0f)};
    return glm::vec4(t[0], t[1], t[2], t[3]) * (1.0f / 255.0f);
}

glm::vec4 fetch(const MipLevel& level, bool srgb, int x, int y) {
    return fetch(level, srgb ? srgbTable().data() : nullptr, x, y);
}

// fetch's value, read from the level's decoded texels where it keeps them (buildMipChain filled
// them with fetch: the same values, from the array the texture kernel reads too).
inline glm::vec4 texel(const MipLevel& level, const float* lut, int x, int y) {
    if (level.linear.empty())
        return fetch(level, lut, x, y);
    const float* t = &level.linear[(size_t(y) * level.width + size_t(x)) * 4];
    return {t[0], t[1], t[2], t[3]};
}

int wrapIndex(int64_t i, int n, Wrap wrap) {
    if (i >= 0 && i < n) // inside: every mode agrees, and it is by far the common case
        return int(i);
    switch (wrap) {
    case Wrap::Repeat:
        return int(((i % n) + n) % n);
    case Wrap::ClampToEdge:
        return int(std::clamp<int64_t>(i, 0, n - 1));
    case Wrap::MirroredRepeat: {
        const int64_t m = ((i % (2 * n)) + 2 * n) % (2 * n);
        return int(m < n ? m : 2 * n - 1 - m);
    }
    }
    return 0;
}

// Texel coordinate of u, clamped so huge or non-finite values cannot overflow the integer cast.
double texelCoord(float u, uint32_t size) {
    const double x = std::isfinite(u) ? double(u) * size - 0.5 : 0.0;
    return std::clamp(x, -1073741824.0, 1073741824.0);
}

glm::vec4 sampleLevel(const Image& image, const MipLevel& level, const Sampler& s, Filter filter,
                      glm::vec2 uv) {
    const int w = int(level.width), h = int(level.height);
    const float* lut = image.srgb ? srgbTable().data() : nullptr;
    const double x = texelCoord(uv.x, level.width);
    const double y = texelCoord(uv.y, level.height);
    if (filter == Filter::Nearest) {
        const int64_t ix = int64_t(std::floor(x + 0.5)), iy = int64_t(std::floor(y + 0.5));
        return texel(level, lut, wrapIndex(ix, w, s.wrap_s), wrapIndex(iy, h, s.wrap_t));
    }
    const double fx = std::floor(x), fy = std::floor(y);
    const float ax = float(x - fx), ay = float(y - fy);
    const int x0 = wrapIndex(int64_t(fx), w, s.wrap_s),
              x1 = wrapIndex(int64_t(fx) + 1, w, s.wrap_s);
    const int y0 = wrapIndex(int64_t(fy), h, s.wrap_t),
              y1 = wrapIndex(int64_t(fy) + 1, h, s.wrap_t);
    const glm::vec4 top = glm::mix(texel(level, lut, x0, y0), texel(level, lut, x1, y0), ax);
    const glm::vec4 bottom = glm::mix(texel(level, lut, x0, y1), texel(level, lut, x1, y1), ax);
    return glm::mix(top, bottom, ay);
}

// MipLevel::nonzero from the level's bytes: a byte 0 decodes to exactly 0 (sRGB or linear).
void markNonzeroBlocks(MipLevel& level) {
    const uint32_t bx = level.blocksX();
    const uint32_t by = (level.height + kTexelBlockSide - 1) / kTexelBlockSide;
    level.nonzero.assign(size_t(bx) * by, 0);
    for (uint32_t y = 0; y < level.height; ++y) {
        uint8_t* row = &level.nonzero[size_t(y / kTexelBlockSide) * bx];
        const uint8_t* t = &level.rgba8[size_t(y) * level.width * 4];
        for (uint32_t x = 0; x < level.width; ++x, t += 4)
            row[x / kTexelBlockSide] |= uint8_t((t[0] | t[1] | t[2]) != 0) | uint8_t(t[3] != 0)
                                                                                 << 1;
    }
}

} // namespace

uint32_t MipLevel::blocksX() const {
    return (width + kTexelBlockSide - 1) / kTexelBlockSide;
}

bool zeroTexels(const MipLevel& level, int64_t x0, int64_t x1, int64_t y0, int64_t y1, bool alpha) {
    if (level.nonzero.empty())
        return false;
    const uint8_t bits = alpha ? 3 : 1;
    const int64_t bx = level.blocksX(), side = kTexelBlockSide;
    for (int64_t y = y0 / side; y <= y1 / side; ++y)
        for (int64_t x = x0 / side; x <= x1 / side; ++x)
            if (level.nonzero[size_t(y * bx + x)] & bits)
                return false;
    return true;
}

void buildMipChain(Image& image) {
    if (image.levels.empty())
        return;
    image.levels.resize(1);
    while (image.levels.back().width > 1 || image.levels.back().height > 1) {
        const MipLevel& src = image.levels.back();
        MipLevel dst;
        dst.width = std::max(1u, src.width / 2);
        dst.height = std::max(1u, src.height / 2);
        dst.rgba8.resize(size_t(dst.width) * dst.height * 4);
        for (uint32_t y = 0; y < dst.height; ++y) {
            for (uint32_t x = 0; x < dst.width; ++x) {
                glm::vec4 sum(0.0f);
                int n = 0;
                for (uint32_t dy = 0; dy < 2; ++dy) {
                    for (uint32_t dx = 0; dx < 2; ++dx) {
                        const uint32_t sx = std::min(2 * x + dx, src.width - 1);
                        const uint32_t sy = std::min(2 * y + dy, src.height - 1);
                        sum += fetch(src, image.srgb, int(sx), int(sy));
                        ++n;
                    }
                }
                sum /= float(n);
                uint8_t* t = &dst.rgba8[(size_t(y) * dst.width + x) * 4];
                t[0] = encode8(sum.r, image.srgb);
                t[1] = encode8(sum.g, image.srgb);
                t[2] = encode8(sum.b, image.srgb);
                t[3] = encode8(sum.a, false);
            }
        }
        image.levels.push_back(std::move(dst));
    }
    // Asking the blocks costs a lookup about as much as it saves when one is skipped, so only
    // images whose blocks are mostly zero are asked (ToyCar's emissive map, 87 % zero: raster
    // 1.07x; StainedGlassLamp's, 3-45 % of 16x16 blocks zero, lost 4 % when always asked).
    size_t blocks = 0, zero_colour = 0, zero = 0;
    for (MipLevel& level : image.levels) {
        markNonzeroBlocks(level);
        blocks += level.nonzero.size();
        for (const uint8_t b : level.nonzero)
            zero_colour += (b & 1) == 0, zero += b == 0;
    }
    image.zero_colour_blocks = 2 * zero_colour > blocks;
    image.zero_blocks = 2 * zero > blocks;
    for (MipLevel& level : image.levels) {
        const size_t texels = size_t(level.width) * level.height;
        if (texels > kLinearLevelMaxTexels) {
            level.linear.clear();
            continue;
        }
        level.linear.resize(texels * 4);
        float* out = level.linear.data();
        for (uint32_t y = 0; y < level.height; ++y)
            for (uint32_t x = 0; x < level.width; ++x, out += 4) {
                const glm::vec4 c = fetch(level, image.srgb, int(x), int(y));
                out[0] = c.r, out[1] = c.g, out[2] = c.b, out[3] = c.a;
            }
    }
}

LevelSelection selectLevels(const Image& image, const Sampler& sampler, FilterOverride filter,
                            float lod) {
    Filter mag = sampler.mag, min = sampler.min;
    MipFilter mip = sampler.mip;
    switch (filter) {
    case FilterOverride::Sampler:
        break;
    case FilterOverride::Nearest:
        mag = min = Filter::Nearest, mip = MipFilter::None;
        break;
    case FilterOverride::Bilinear:
        mag = min = Filter::Linear, mip = MipFilter::None;
        break;
    case FilterOverride::Trilinear:
        mag = min = Filter::Linear, mip = MipFilter::Linear;
        break;
    }
    LevelSelection s;
    if (!(lod > 0.0f) || mip == MipFilter::None) {
        s.filter = lod > 0.0f ? min : mag;
        return s;
    }
    s.filter = min;
    const float max_level = float(image.levels.size() - 1);
    const float l = std::min(lod, max_level);
    if (mip == MipFilter::Nearest) {
        s.level0 = uint32_t(std::floor(l + 0.5f));
        return s;
    }
    s.level0 = uint32_t(std::floor(l));
    s.level1 = std::min(s.level0 + 1, uint32_t(image.levels.size() - 1));
    s.mix_levels = true;
    s.weight = l - float(s.level0);
    return s;
}

const float* srgbDecodeTable() {
    return srgbTable().data();
}

glm::vec4 sampleImage(const Image& image, const Sampler& sampler, FilterOverride filter,
                      glm::vec2 uv, float lod) {
    if (image.levels.empty())
        return glm::vec4(1.0f);
    return sampleLevels(image, sampler, selectLevels(image, sampler, filter, lod), uv);
}

glm::vec4 sampleLevels(const Image& image, const Sampler& sampler, const LevelSelection& s,
                       glm::vec2 uv) {
    const glm::vec4 a = sampleLevel(image, image.levels[s.level0], sampler, s.filter, uv);
    if (!s.mix_levels)
        return a;
    const glm::vec4 b = sampleLevel(image, image.levels[s.level1], sampler, s.filter, uv);
    return glm::mix(a, b, s.weight);
}

} // namespace raster
