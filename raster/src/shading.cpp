#include "shading.h"

#include "quad_kernel.h"

#include <glm/exponential.hpp>
#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>

#include <algorithm>
#include <cmath>

namespace raster {

namespace {

const Sampler& samplerOf(const Scene& scene, const TextureRef& ref) {
    static const Sampler kDefaultSampler{};
    return ref.sampler >= 0 ? scene.samplers[size_t(ref.sampler)] : kDefaultSampler;
}

// glTF/OpenGL LOD: log2 of the longer footprint axis in texels (OpenGL 4.6 §8.14.1). The
// derivatives transform by the linear part of the texture transform. A footprint of at most one
// texel is magnification, where only the sign of the LOD counts (selectLevels): -1 without the
// logarithm (log2 of rho2 <= 1 is <= 0, of NaN not > 0).
float levelOfDetail(const TextureRef& ref, const Image& image, glm::vec2 duv_dx, glm::vec2 duv_dy) {
    const glm::mat2 lin(glm::vec2(ref.transform[0]), glm::vec2(ref.transform[1]));
    const glm::vec2 size(float(image.levels[0].width), float(image.levels[0].height));
    const glm::vec2 dx = lin * duv_dx * size, dy = lin * duv_dy * size;
    const float rho2 = std::max(glm::dot(dx, dx), glm::dot(dy, dy));
    return rho2 > 1.0f ? 0.5f * std::log2(rho2) : -1.0f;
}

bool fitsTextureKernel(const MipLevel& level) {
    return level.width <= kTextureKernelMaxSide && level.height <= kTextureKernelMaxSide &&
           uint64_t(level.width) * level.height <= kTextureKernelMaxTexels;
}

TextureLevel kernelLevel(const MipLevel& level) {
    return {reinterpret_cast<const TexelWord*>(level.rgba8.data()), int32_t(level.width),
            int32_t(level.height), level.linear.empty() ? nullptr : level.linear.data()};
}

// Whether the lookups of the `mask` lanes on `sel`'s levels read only texels whose colour is
// zero, and alpha too unless `colour_only`: each tap's weight is finite and non-negative, so each
// such lookup returns exactly zero there. The taps of a lane at u on a level of width w lie in
// [floor(u w - 1/2), floor(u w - 1/2) + 1] (sampleLevel's texelCoord, the same double
// arithmetic; nearest picks one of the two). Only windows inside the level, of a few blocks, and
// finite coordinates are looked at; anything else is sampled. `mask` is not empty.
bool zeroFootprint(const Image& image, const LevelSelection& sel, const TextureLanes& lanes,
                   uint32_t mask, bool colour_only) {
    float u0 = INFINITY, u1 = -INFINITY, v0 = INFINITY, v1 = -INFINITY;
    for (int l = 0; l < kTextureLanes; ++l)
        if (mask & (1u << l)) {
            if (!std::isfinite(lanes.u[l]) || !std::isfinite(lanes.v[l]))
                return false;
            u0 = std::min(u0, lanes.u[l]), u1 = std::max(u1, lanes.u[l]);
            v0 = std::min(v0, lanes.v[l]), v1 = std::max(v1, lanes.v[l]);
        }
    constexpr int64_t kMaxBlocks = 16;
    const uint32_t levels[2] = {sel.level0, sel.level1};
    for (int j = 0; j < (sel.mix_levels ? 2 : 1); ++j) {
        const MipLevel& level = image.levels[levels[j]];
        const double w = double(level.width), h = double(level.height);
        const double fx0 = std::floor(double(u0) * w - 0.5), fx1 = std::floor(double(u1) * w - 0.5);
        const double fy0 = std::floor(double(v0) * h - 0.5), fy1 = std::floor(double(v1) * h - 0.5);
        if (!(fx0 >= 0.0 && fy0 >= 0.0 && fx1 + 1.0 < w && fy1 + 1.0 < h))
            return false; // off the level (also huge coordinates: tested before the casts)
        const int64_t x0 = int64_t(fx0), x1 = int64_t(fx1) + 1;
        const int64_t y0 = int64_t(fy0), y1 = int64_t(fy1) + 1;
        const int64_t side = kTexelBlockSide;
        if ((x1 / side - x0 / side + 1) * (y1 / side - y0 / side + 1) > kMaxBlocks ||
            !zeroTexels(level, x0, x1, y0, y1, !colour_only))
            return false;
    }
    return true;
}

} // namespace

TextureRoles sampledTextureRoles(ShadingMode) {
    // The base colour and emissive textures are the only texture reads (sampleLanes in the
    // tile raster), and every mode makes them (lighting takes metallic and roughness from the
    // material's factors alone).
    return TextureRoles{} | TextureRole::BaseColor | TextureRole::Emissive;
}

void prepareQuadPair(const ShadeContext& ctx, const TextureRef& ref, const QuadPairUv& in,
                     QuadPairLookup& out) {
    const Image& image = ctx.scene->images[size_t(ref.image)];
    const Sampler& sampler = samplerOf(*ctx.scene, ref);
    for (int q = 0; q < 2; ++q) {
        const int l0 = 4 * q;
        const float lod =
            levelOfDetail(ref, image, {in.u[l0 + 1] - in.u[l0], in.v[l0 + 1] - in.v[l0]},
                          {in.u[l0 + 2] - in.u[l0], in.v[l0 + 2] - in.v[l0]});
        out.sel[q] = selectLevels(image, sampler, ctx.filter, lod);
    }
    for (int l = 0; l < kTextureLanes; ++l)
        out.lanes.weight[l] = out.sel[l / 4].weight;
    // KHR_texture_transform: uv' = M (u, v, 1), as glm's mat3 * vec3 computes it (the third
    // term is M[2] * 1, which is M[2]), a lane loop the compiler vectorizes.
    const glm::mat3& m = ref.transform;
    for (int l = 0; l < kTextureLanes; ++l) {
        out.lanes.u[l] = m[0][0] * in.u[l] + m[1][0] * in.v[l] + m[2][0];
        out.lanes.v[l] = m[0][1] * in.u[l] + m[1][1] * in.v[l] + m[2][1];
    }
}

bool sameFootprint(const Scene& scene, const TextureRef& a, const TextureRef& b) {
    const Image& ia = scene.images[size_t(a.image)];
    const Image& ib = scene.images[size_t(b.image)];
    return a.texcoord == b.texcoord && a.sampler == b.sampler && a.transform == b.transform &&
           ia.levels.size() == ib.levels.size() && ia.levels[0].width == ib.levels[0].width &&
           ia.levels[0].height == ib.levels[0].height;
}

bool sameLevels(const LevelSelection& a, const LevelSelection& b) {
    return a.level0 == b.level0 && a.level1 == b.level1 && a.filter == b.filter &&
           a.mix_levels == b.mix_levels;
}

void sampleLanes(const ShadeContext& ctx, const TextureRef& ref, const LevelSelection& sel,
                 uint32_t lane_mask, bool colour_only, TextureLanes& lanes) {
    const Image& image = ctx.scene->images[size_t(ref.image)];
    // Where the image has blocks of zero texels, lookups that read only those are zero.
    const bool zeros = colour_only ? image.zero_colour_blocks : image.zero_blocks;
    if (zeros && zeroFootprint(image, sel, lanes, lane_mask, colour_only)) {
        for (int k = 0; k < 4; ++k)
            for (int l = 0; l < kTextureLanes; ++l)
                lanes.rgba[k][l] = 0.0f;
        return;
    }
    const Sampler& sampler = samplerOf(*ctx.scene, ref);
    // One by one when at most kFewLanes lanes are asked for (with gathers, an AVX2 kernel call
    // costs about as much as 1.3 one-fragment lookups; callgrind on ToyCar, docs/raster.md 8.2)
    // or the image is beyond the kernel's integers.
    constexpr int kFewLanes = 1;
    if (laneCount(lane_mask) <= kFewLanes || !fitsTextureKernel(image.levels[0])) {
        for (int l = 0; l < kTextureLanes; ++l) {
            glm::vec4 c(0.0f); // a lane not asked for is still written (shading.h)
            if (lane_mask & (1u << l)) {
                LevelSelection lane_sel = sel;
                lane_sel.weight = lanes.weight[l];
                c = sampleLevels(image, sampler, lane_sel, {lanes.u[l], lanes.v[l]});
            }
            for (int k = 0; k < 4; ++k)
                lanes.rgba[k][l] = c[k];
        }
        return;
    }
    TextureQuery query;
    query.level[0] = kernelLevel(image.levels[sel.level0]);
    query.level[1] = kernelLevel(image.levels[sel.level1]);
    query.srgb_lut = image.srgb ? srgbDecodeTable() : nullptr;
    query.wrap_s = sampler.wrap_s;
    query.wrap_t = sampler.wrap_t;
    query.nearest = sel.filter == Filter::Nearest;
    query.mix_levels = sel.mix_levels;
    ctx.texture_kernel(query, lanes);
}

bool isUnlit(const ShadeContext& ctx, const Material& m) {
    return ctx.mode == ShadingMode::Unlit || (ctx.mode == ShadingMode::Material && m.unlit);
}

GSample surfaceSample(const ShadeContext& ctx, const Material& m, glm::vec3 base,
                      glm::vec3 emissive, glm::vec3 normal) {
    GSample g;
    const float len = glm::length(normal);
    g.normal = len > 0.0f ? normal / len : glm::vec3(0.0f, 0.0f, 1.0f);
    g.base_color = base;
    g.metallic = m.metallic_factor;
    g.roughness = m.roughness_factor;
    g.emissive = emissive;
    g.unlit = isUnlit(ctx, m) ? 1.0f : 0.0f;
    return g;
}

glm::vec3 shadeSample(const ShadeContext& ctx, const GSample& g, glm::vec3 world, glm::vec3 eye) {
    if (g.unlit != 0.0f)
        return g.base_color + g.emissive;
    LightLanes lanes{}; // every lane initialised (light_kernel.h)
    for (int c = 0; c < 3; ++c) {
        lanes.albedo[c][0] = g.base_color[c];
        lanes.emissive[c][0] = g.emissive[c];
        lanes.world[c][0] = world[c];
        lanes.normal[c][0] = g.normal[c];
    }
    const float eye3[3] = {eye.x, eye.y, eye.z};
    ctx.light_kernel(ctx.lights, ctx.light_count, {g.metallic, g.roughness}, eye3, &lanes, 1, 1);
    return {lanes.rgb[0][0], lanes.rgb[1][0], lanes.rgb[2][0]};
}

} // namespace raster
