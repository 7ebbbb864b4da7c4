// raster/depth_precision.h: the numbers behind the "no silent wrong image" warnings (issue 23).
#include <raster/camera.h>
#include <raster/depth_precision.h>
#include <raster/storage.h>

#include <gtest/gtest.h>

#include <cmath>

namespace {

using raster::DepthFormat;

raster::View viewWithNear(float znear, float zfar = 0.0f) {
    raster::View v;
    v.znear = znear;
    v.zfar = zfar;
    return v;
}

TEST(DepthPrecision, FarthestStorableDistanceIsWhereTheFarValueTakesOver) {
    const raster::View v = viewWithNear(1e-5f);
    const float unorm = raster::farthestStorableDistance(v, DepthFormat::Unorm16);
    EXPECT_NEAR(unorm, 1e-5f * 131070.0f, 1e-4f); // 1.31
    // Just inside it still stores below 65535, just beyond it stores the far value.
    EXPECT_LT(raster::encodeUnorm16(raster::depthFromDistance(v, 0.99f * unorm)), 65535);
    EXPECT_EQ(raster::encodeUnorm16(raster::depthFromDistance(v, 1.01f * unorm)), 65535);
    // Float D = -n/d reaches the far value 0 only by underflow: never, for a float distance.
    EXPECT_TRUE(std::isinf(raster::farthestStorableDistance(v, DepthFormat::Float32)));
    EXPECT_LT(raster::depthFromDistance(v, 3e38f), raster::kFarDepth);
    // With a finite far plane, only the last half step before it is lost (0.76% of 100 here);
    // float loses next to nothing.
    EXPECT_NEAR(raster::farthestStorableDistance(viewWithNear(0.1f, 100.0f), DepthFormat::Unorm16),
                99.24f, 0.01f);
    EXPECT_NEAR(raster::farthestStorableDistance(viewWithNear(0.1f, 100.0f), DepthFormat::Float32),
                100.0f, 1e-4f);
}

TEST(DepthPrecision, ResolutionGrowsWithTheSquareOfDistance) {
    const raster::View v = viewWithNear(0.1f);
    const float at10 = raster::depthResolution(v, DepthFormat::Unorm16, 10.0f);
    EXPECT_NEAR(at10, 10.0f * 10.0f / (0.1f * 65535.0f), 1e-5f);
    EXPECT_NEAR(raster::depthResolution(v, DepthFormat::Unorm16, 20.0f), 4.0f * at10, 1e-4f);
    // float D = -n/d keeps 24 bits at every distance: d 2^-24 up to d 2^-23, whatever n.
    for (const float near : {1e-6f, 0.1f})
        for (const float d : {10.0f, 1e4f, 1e7f}) {
            const float step = raster::depthResolution(viewWithNear(near), DepthFormat::Float32, d);
            EXPECT_GE(step, std::ldexp(d, -24) * 0.999f) << near << " " << d;
            EXPECT_LE(step, std::ldexp(d, -23) * 1.001f) << near << " " << d;
        }
}

TEST(DepthPrecision, ProblemNamesTheNumbers) {
    // The case: --near 1e-5 --depth-format unorm16 drew an empty sky without a word.
    const auto problem = raster::depthPrecisionProblem(viewWithNear(1e-5f), DepthFormat::Unorm16,
                                                       2.0f, 25.0f, "depth");
    ASSERT_TRUE(problem.has_value());
    EXPECT_EQ(*problem, "unorm16 depth with near 1e-05 stores every distance beyond 1.31 as the "
                        "far plane, but the scene reaches 25: surfaces beyond 1.31 are not drawn "
                        "(raise the view's znear or use float32 depth)");
    // Float depth (D = -n/d, reversed-Z) keeps them, 24 bits apart at any distance.
    EXPECT_FALSE(raster::depthPrecisionProblem(viewWithNear(1e-5f), DepthFormat::Float32, 2.0f,
                                               25.0f, "depth"));
    EXPECT_FALSE(raster::depthPrecisionProblem(viewWithNear(1e-6f), DepthFormat::Float32, 1e-6f,
                                               1e8f, "depth"));
    // The usual near planes are fine with either format.
    EXPECT_FALSE(raster::depthPrecisionProblem(viewWithNear(1e-3f), DepthFormat::Float32, 2.0f,
                                               25.0f, "depth"));
    EXPECT_FALSE(raster::depthPrecisionProblem(viewWithNear(0.05f), DepthFormat::Unorm16, 2.0f,
                                               25.0f, "depth"));
    // Coarse but not lost: near 0.001, unorm16 at 1000 steps 15 units.
    const auto coarse = raster::depthPrecisionProblem(viewWithNear(1e-3f), DepthFormat::Unorm16,
                                                      1.0f, 100.0f, "layer depth");
    ASSERT_TRUE(coarse.has_value());
    EXPECT_NE(coarse->find("resolves distances near 100 only to 153"), std::string::npos)
        << *coarse;
}

} // namespace
