// The SIMD kernels give the same bits as the scalar references (issue 3, SIMD; issue 19, the
// texture and fragment kernels).
#include "support/test_util.h"

#include <raster/task_pool.h>
#include <raster/texture.h>
#include <scenes/builtin.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

// The kernels are internal to raster.
#include "raster/src/fragment_kernel.h"
#include "raster/src/light_kernel.h"
#include "raster/src/quad_kernel.h"
#include "raster/src/texture_kernel.h"

namespace focal::test {
namespace {

TEST(Simd, QuadKernelMatchesScalarBitForBit) {
    const raster::QuadKernel wide = raster::quadKernelAvx2();
    if (!wide || !__builtin_cpu_supports("avx2"))
        GTEST_SKIP() << "no AVX2 kernel on this build or CPU";
    // Pseudo-random triangles within the fixed-point budget (edge values < 2^50).
    uint64_t state = 0x9e3779b97f4a7c15ull;
    auto next = [&state] {
        state ^= state << 13, state ^= state >> 7, state ^= state << 17;
        return state;
    };
    auto integer = [&](int bits) {
        return double(int64_t(next() % (1ull << bits)) - int64_t(1ull << (bits - 1)));
    };
    for (int i = 0; i < 20000; ++i) {
        raster::QuadInput in;
        for (int k = 0; k < 3; ++k) {
            in.edge[k] = integer(i % 2 ? 20 : 48);
            in.step_x[k] = integer(i % 3 ? 12 : 30) * 256.0;
            in.step_y[k] = integer(i % 3 ? 12 : 30) * 256.0;
            in.bias[k] = (next() & 1) ? 0.0 : -1.0;
            in.inv_w[k] = float(next() % 100000 + 1) * 1e-4f;
            in.z[k] = float(next() % 100001) * 1e-5f;
        }
        in.inv_area2 = 1.0 / (double(next() % (1ull << 40)) + 1.0);
        in.valid = uint32_t(next() & 0xff) | (i % 4 ? 0xffu : 0u);
        raster::QuadOutput a, b;
        std::memset(&a, 0, sizeof(a));
        std::memset(&b, 0, sizeof(b));
        raster::quadKernelScalar(in, a);
        wide(in, b);
        ASSERT_EQ(a.mask, b.mask) << i;
        if (a.mask != 0) {
            ASSERT_EQ(std::memcmp(&a, &b, sizeof(a)), 0) << i;
        }
    }
}

TEST(Simd, LightKernelMatchesScalarBitForBit) {
    const raster::LightKernel wide = raster::lightKernelAvx2();
    if (!wide || !__builtin_cpu_supports("avx2"))
        GTEST_SKIP() << "no AVX2 kernel on this build or CPU";
    uint32_t state = 12345u;
    auto unit = [&state] {
        state = state * 1664525u + 1013904223u;
        return float(state >> 8) / 16777216.0f;
    };
    raster::Scene scene; // lights of every type, incl. a ranged spot
    raster::Light sun;
    sun.direction = {0.3f, -1.0f, -0.2f};
    raster::Light bulb;
    bulb.type = raster::Light::Type::Point;
    bulb.position = {0.5f, 2.0f, 1.0f};
    bulb.intensity = 20.0f;
    bulb.range = 6.0f;
    raster::Light spot = bulb;
    spot.type = raster::Light::Type::Spot;
    spot.direction = {0.0f, -1.0f, 0.0f};
    spot.inner_cone_angle = 0.2f;
    spot.outer_cone_angle = 0.6f;
    scene.lights = {sun, bulb, spot};
    std::vector<raster::PreparedLight> lights;
    raster::prepareLights(scene, glm::vec3(0.0f, -1.0f, 0.0f), lights);
    const float eye[3] = {0.0f, 1.0f, 5.0f};
    for (int i = 0; i < 5000; ++i) {
        // One block, or two (whose chains the AVX2 build interleaves), the last one partial.
        raster::LightLanes a[2];
        for (raster::LightLanes& block : a)
            for (int c = 0; c < 3; ++c)
                for (int l = 0; l < raster::kLightLanes; ++l) {
                    block.albedo[c][l] = unit();
                    block.emissive[c][l] = unit() < 0.2f ? 4.0f * unit() : 0.0f;
                    block.world[c][l] = 4.0f * unit() - 2.0f;
                    block.normal[c][l] = 2.0f * unit() - 1.0f;
                }
        raster::LightLanes b[2] = {a[0], a[1]};
        const raster::LightMaterial m{unit(), unit()};
        const int blocks = 1 + i % 2;
        const int lanes = 1 + (i / 2) % raster::kLightLanes;
        // Every light type, and the lights in pairs and alone.
        const uint32_t count = 1 + uint32_t(i / 16) % uint32_t(lights.size());
        const raster::PreparedLight* first = lights.data() + (i / 48) % (lights.size() - count + 1);
        raster::lightKernelScalar(first, count, m, eye, a, blocks, lanes);
        wide(first, count, m, eye, b, blocks, lanes);
        for (int k = 0; k < blocks; ++k)
            for (int c = 0; c < 3; ++c)
                for (int l = 0; l < (k + 1 == blocks ? lanes : raster::kLightLanes); ++l)
                    ASSERT_EQ(std::memcmp(&a[k].rgb[c][l], &b[k].rgb[c][l], sizeof(float)), 0)
                        << i << " block " << k << " lane " << l << ": " << a[k].rgb[c][l] << " vs "
                        << b[k].rgb[c][l];
    }
}

// The fragment kernel's AVX2 build gives the scalar build's bits in every lane asked for: lanes
// passed, base colour, emissive, world position, normal and opacity, for every combination of
// vertex colours, normals, back faces, alpha modes and textures.
TEST(Simd, FragmentKernelMatchesScalarBitForBit) {
    const raster::FragmentKernel wide = raster::fragmentKernelAvx2();
    if (!wide || !__builtin_cpu_supports("avx2"))
        GTEST_SKIP() << "no AVX2 kernel on this build or CPU";
    uint32_t state = 4242u;
    auto unit = [&state] {
        state = state * 1664525u + 1013904223u;
        return float(state >> 8) / 16777216.0f;
    };
    for (int i = 0; i < 20000; ++i) {
        raster::FragmentTriangle tri;
        for (int k = 0; k < 3; ++k) {
            for (int c = 0; c < 4; ++c)
                tri.color[c][k] = unit();
            for (int c = 0; c < 3; ++c) {
                tri.world[c][k] = 20.0f * unit() - 10.0f;
                tri.normal[c][k] = 2.0f * unit() - 1.0f;
            }
        }
        for (int c = 0; c < 4; ++c)
            tri.base_factor[c] = 1.5f * unit() - 0.25f; // alpha below 0 and above 1 too
        for (int c = 0; c < 3; ++c) {
            tri.emissive_factor[c] = i % 3 ? 0.0f : 2.0f * unit();
            tri.face_normal[c] = 2.0f * unit() - 1.0f;
        }
        tri.alpha_cutoff = unit();
        tri.has_colors = i & 1;
        tri.has_normals = i & 2;
        tri.flip_normal = i & 4;
        tri.mask = (i % 5) == 1;
        tri.blend = (i % 5) == 2;
        alignas(32) float persp[3][raster::kQuadLanes];
        alignas(32) float base_texel[4][raster::kQuadLanes], emissive_texel[4][raster::kQuadLanes];
        for (int l = 0; l < raster::kQuadLanes; ++l) {
            const float b0 = unit(), b1 = unit() * (1.0f - b0);
            persp[0][l] = b0, persp[1][l] = b1, persp[2][l] = 1.0f - b0 - b1;
            for (int c = 0; c < 4; ++c)
                base_texel[c][l] = unit(), emissive_texel[c][l] = unit();
        }
        const uint32_t lanes = (state >> 4) & 0xffu;
        const bool base_textured = i & 8, emissive_textured = i & 16;
        raster::LightLanes a{}, b{};
        alignas(32) float alpha_a[raster::kQuadLanes] = {}, alpha_b[raster::kQuadLanes] = {};
        const uint32_t passed_a = raster::fragmentKernelScalar(
            tri, persp, base_textured ? base_texel : nullptr,
            emissive_textured ? emissive_texel : nullptr, lanes, a, alpha_a);
        const uint32_t passed_b =
            wide(tri, persp, base_textured ? base_texel : nullptr,
                 emissive_textured ? emissive_texel : nullptr, lanes, b, alpha_b);
        ASSERT_EQ(passed_a, passed_b) << i;
        ASSERT_EQ(passed_a & ~lanes, 0u) << i;
        for (int l = 0; l < raster::kQuadLanes; ++l) {
            if (!(lanes & (1u << l)))
                continue;
            ASSERT_EQ(std::memcmp(&alpha_a[l], &alpha_b[l], sizeof(float)), 0) << i;
            for (int c = 0; c < 3; ++c) {
                ASSERT_EQ(std::memcmp(&a.albedo[c][l], &b.albedo[c][l], sizeof(float)), 0) << i;
                ASSERT_EQ(std::memcmp(&a.emissive[c][l], &b.emissive[c][l], sizeof(float)), 0) << i;
                ASSERT_EQ(std::memcmp(&a.world[c][l], &b.world[c][l], sizeof(float)), 0) << i;
                ASSERT_EQ(std::memcmp(&a.normal[c][l], &b.normal[c][l], sizeof(float)), 0) << i;
            }
        }
    }
}

// Lane by lane, the texture kernel (scalar build, and the AVX2 build where there is one, from
// the texel words and from the decoded texels) gives the bits of sampleImage, the one-fragment
// reference: every wrap mode and filter, sRGB and linear images, sizes that are not powers of
// two, and coordinates far outside [0, 1], non-finite ones included.
TEST(Simd, TextureKernelMatchesSampleImageBitForBit) {
    const raster::TextureKernel wide = raster::textureKernelAvx2();
    const bool has_wide = wide && __builtin_cpu_supports("avx2");
    uint32_t state = 777u;
    auto next = [&state] {
        state = state * 1664525u + 1013904223u;
        return state >> 8;
    };
    auto unit = [&] { return float(next()) / 16777216.0f; };
    const raster::Wrap wraps[] = {raster::Wrap::Repeat, raster::Wrap::ClampToEdge,
                                  raster::Wrap::MirroredRepeat};
    const raster::FilterOverride overrides[] = {
        raster::FilterOverride::Sampler, raster::FilterOverride::Nearest,
        raster::FilterOverride::Bilinear, raster::FilterOverride::Trilinear};
    const uint32_t sizes[][2] = {{1, 1}, {4, 4}, {7, 3}, {64, 32}, {1, 33}, {100, 1}};
    int checked = 0;
    for (const auto& size : sizes)
        for (const bool srgb : {false, true}) {
            raster::Image img;
            img.srgb = srgb;
            raster::MipLevel& top = img.levels.emplace_back();
            top.width = size[0];
            top.height = size[1];
            top.rgba8.resize(size_t(size[0]) * size[1] * 4);
            for (uint8_t& texel : top.rgba8)
                texel = uint8_t(next() & 0xff);
            raster::buildMipChain(img);
            for (int i = 0; i < 400; ++i) {
                raster::Sampler s;
                s.wrap_s = wraps[i % 3];
                s.wrap_t = wraps[(i / 3) % 3];
                s.mag = next() & 1 ? raster::Filter::Linear : raster::Filter::Nearest;
                s.min = next() & 1 ? raster::Filter::Linear : raster::Filter::Nearest;
                s.mip = raster::MipFilter(next() % 3);
                const raster::FilterOverride filter = overrides[(i / 9) % 4];
                const float lod = 8.0f * unit() - 2.0f;
                const raster::LevelSelection sel = raster::selectLevels(img, s, filter, lod);
                raster::TextureQuery q;
                for (int k = 0; k < 2; ++k) {
                    const raster::MipLevel& level = img.levels[k ? sel.level1 : sel.level0];
                    q.level[k] = {reinterpret_cast<const raster::TexelWord*>(level.rgba8.data()),
                                  int32_t(level.width), int32_t(level.height)};
                }
                q.srgb_lut = srgb ? raster::srgbDecodeTable() : nullptr;
                q.wrap_s = s.wrap_s;
                q.wrap_t = s.wrap_t;
                q.nearest = sel.filter == raster::Filter::Nearest;
                q.mix_levels = sel.mix_levels;
                raster::TextureLanes lanes;
                auto coordinate = [&](uint32_t texels) {
                    switch (next() % 8) {
                    case 0: // exactly on a texel centre or edge
                        return float(int(next() % 64) - 32) / float(2 * texels);
                    case 1:
                        return (unit() - 0.5f) * 1e9f;
                    case 2:
                        return next() & 1 ? NAN : (next() & 1 ? INFINITY : -INFINITY);
                    default:
                        return 8.0f * unit() - 4.0f;
                    }
                };
                for (int l = 0; l < raster::kTextureLanes; ++l) {
                    lanes.u[l] = coordinate(size[0]);
                    lanes.v[l] = coordinate(size[1]);
                    lanes.weight[l] = sel.weight;
                }
                raster::TextureLanes a = lanes, b = lanes;
                raster::textureKernelScalar(q, a);
                for (int l = 0; l < raster::kTextureLanes; ++l) {
                    const glm::vec4 ref =
                        raster::sampleImage(img, s, filter, {lanes.u[l], lanes.v[l]}, lod);
                    for (int c = 0; c < 4; ++c)
                        ASSERT_EQ(std::memcmp(&a.rgba[c][l], &ref[c], sizeof(float)), 0)
                            << "size " << size[0] << "x" << size[1] << " case " << i << " lane "
                            << l << " uv " << lanes.u[l] << "," << lanes.v[l] << ": "
                            << a.rgba[c][l] << " vs " << ref[c];
                }
                if (has_wide) {
                    wide(q, b);
                    ASSERT_EQ(std::memcmp(a.rgba, b.rgba, sizeof(a.rgba)), 0) << i;
                    raster::TextureQuery decoded = q;
                    for (int k = 0; k < 2; ++k) {
                        const raster::MipLevel& level = img.levels[k ? sel.level1 : sel.level0];
                        ASSERT_EQ(level.linear.size(), level.rgba8.size());
                        decoded.level[k].linear = level.linear.data();
                    }
                    raster::TextureLanes c = lanes;
                    wide(decoded, c);
                    ASSERT_EQ(std::memcmp(a.rgba, c.rgba, sizeof(a.rgba)), 0) << i;
                }
                ++checked;
            }
        }
    EXPECT_EQ(checked, 6 * 2 * 400);
}

// Whole renders: every kernel and the tile raster's AVX2 copy (rasterizeTile) against the
// scalar reference path.
TEST(Simd, RendersMatchTheScalarPathOnBuiltinScenes) {
    for (const char* name : {"demo", "foliage", "glass", "reflective"}) {
        raster::Result<raster::Scene> s = scenes::makeBuiltinScene(name);
        ASSERT_TRUE(s.ok());
        const raster::View v = raster::viewFromCamera(s->cameras[0], 200, 150);
        raster::RenderOptions o;
        o.simd = false;
        const uint64_t scalar = hashFrame(render(*s, v, o, 2));
        o.simd = true;
        EXPECT_EQ(hashFrame(render(*s, v, o, 2)), scalar) << name;
    }
}

} // namespace
} // namespace focal::test
