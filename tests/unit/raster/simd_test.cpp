// The SIMD quad kernel gives the same bits as the scalar reference (issue 3, SIMD).
#include "support/test_util.h"

#include <raster/task_pool.h>
#include <scenes/builtin.h>

#include <cstring>

#include <gtest/gtest.h>

// The kernel is internal to raster; its header has no dependencies.
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
        if (a.mask != 0)
            ASSERT_EQ(std::memcmp(&a, &b, sizeof(a)), 0) << i;
    }
}

TEST(Simd, RendersMatchTheScalarPathOnBuiltinScenes) {
    for (const char* name : {"demo", "foliage", "glass"}) {
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

}  // namespace
}  // namespace focal::test
