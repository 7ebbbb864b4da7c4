// raster/camera.h: firstDepthAtDistance turns a test on distances into a compare of stored
// depths with the same outcome for every stored depth below the cleared value.
#include <raster/camera.h>

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace {

raster::View viewWithPlanes(float znear, float zfar) {
    raster::View v;
    v.znear = znear;
    v.zfar = zfar;
    return v;
}

// Every stored depth near each threshold (the floats on both sides of it) and a sweep of
// [-1, 1): where a wrong threshold would show, one float off.
std::vector<float> storedDepthsAround(const std::vector<float>& thresholds) {
    std::vector<float> out;
    for (int i = 0; i <= 4000; ++i)
        out.push_back(-1.0f + float(i) / 2000.0f);
    for (float t : thresholds) {
        float v = t;
        for (int i = 0; i < 8; ++i)
            v = std::nextafter(v, -INFINITY);
        for (int i = 0; i < 16; ++i, v = std::nextafter(v, INFINITY))
            if (v < 1.0f)
                out.push_back(v);
    }
    return out;
}

TEST(Camera, FirstDepthAtDistanceDecidesLikeTheDistance) {
    for (const raster::View& view :
         {viewWithPlanes(0.1f, 100.0f), viewWithPlanes(0.05f, 0.0f), viewWithPlanes(1.0f, 7.0f)}) {
        std::vector<float> distances = {0.0f, view.znear, 0.3f,  1.0f,    1.2920817f,
                                        3.7f, 25.125696f, 99.9f, 1000.0f, INFINITY};
        std::vector<float> thresholds;
        for (float d : distances)
            thresholds.push_back(raster::firstDepthAtDistance(view, d));
        for (size_t i = 0; i < distances.size(); ++i)
            for (float stored : storedDepthsAround(thresholds)) {
                const bool by_distance = raster::distanceFromDepth(view, stored) >= distances[i];
                ASSERT_EQ(by_distance, stored >= thresholds[i])
                    << "zfar " << view.zfar << ", d " << distances[i] << ", stored " << stored;
            }
    }
}

TEST(Camera, FirstDepthAtDistanceIsTheFirstFloatThatReachesIt) {
    const raster::View view = viewWithPlanes(0.1f, 100.0f);
    const float d = 3.7f;
    const float t = raster::firstDepthAtDistance(view, d);
    EXPECT_GE(raster::distanceFromDepth(view, t), d);
    EXPECT_LT(raster::distanceFromDepth(view, std::nextafter(t, -INFINITY)), d);
    // Near the depth the projection stores for d.
    EXPECT_NEAR(t, raster::depthFromDistance(view, d), 1e-6f);
}

} // namespace
