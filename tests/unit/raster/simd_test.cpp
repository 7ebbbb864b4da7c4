// The SIMD quad kernel gives the same bits as the scalar reference (issue 3, SIMD).
#include "support/test_util.h"

#include <raster/task_pool.h>
#include <scenes/builtin.h>

#include <gtest/gtest.h>

#include <cstring>

// The kernels are internal to raster.
#include "raster/src/light_kernel.h"
#include "raster/src/quad_kernel.h"

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
    const std::vector<raster::PreparedLight> lights =
        raster::prepareLights(scene, glm::vec3(0.0f, -1.0f, 0.0f));
    const float eye[3] = {0.0f, 1.0f, 5.0f};
    for (int i = 0; i < 5000; ++i) {
        raster::LightLanes a;
        for (int c = 0; c < 3; ++c)
            for (int l = 0; l < raster::kLightLanes; ++l) {
                a.albedo[c][l] = unit();
                a.emissive[c][l] = unit() < 0.2f ? 4.0f * unit() : 0.0f;
                a.world[c][l] = 4.0f * unit() - 2.0f;
                a.normal[c][l] = 2.0f * unit() - 1.0f;
            }
        raster::LightLanes b = a;
        const raster::LightMaterial m{unit(), unit()};
        const int lanes = 1 + i % raster::kLightLanes;
        raster::lightKernelScalar(lights.data(), uint32_t(lights.size()), m, eye, a, lanes);
        wide(lights.data(), uint32_t(lights.size()), m, eye, b, lanes);
        for (int c = 0; c < 3; ++c)
            for (int l = 0; l < lanes; ++l)
                ASSERT_EQ(std::memcmp(&a.rgb[c][l], &b.rgb[c][l], sizeof(float)), 0)
                    << i << " lane " << l << ": " << a.rgb[c][l] << " vs " << b.rgb[c][l];
    }
}

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
