// Coverage: fill rule, watertightness, clipping, guard band and culling (issue 3).
#include "support/test_util.h"

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include <cmath>

namespace focal::test {
namespace {

using raster::AlphaMode;

constexpr uint32_t kSize = 64;
constexpr float kDist = 64.0f; // the plane where one world unit is one pixel

// World point on the pixel-exact plane for pixel coordinates (px, py).
glm::vec3 at(float px, float py) {
    return {px - 32.0f, 32.0f - py, -kDist};
}

// Every triangle is drawn with 50% white over black: a pixel covered once reads 0.5, twice 0.75.
raster::Scene blendScene() {
    raster::Scene s;
    s.background = glm::vec3(0.0f);
    addMaterial(s, flatMaterial(glm::vec4(1.0f, 1.0f, 1.0f, 0.5f), AlphaMode::Blend));
    return s;
}

// Deterministic jitter in [-0.5, 0.5) from an integer (a small integer hash).
float jitter(uint32_t i) {
    i = (i ^ 61u) ^ (i >> 16);
    i *= 9u;
    i ^= i >> 4;
    i *= 0x27d4eb2du;
    i ^= i >> 15;
    return float(i & 0xffffu) / 65536.0f - 0.5f;
}

TEST(Coverage, TopLeftRuleOnPixelCentres) {
    // A square whose corners are pixel centres (2.5,2.5)-(6.5,6.5): the top and left edges own
    // the centres on them, the bottom and right edges do not, so exactly 4x4 pixels are covered.
    raster::Scene s = blendScene();
    addMesh(s, {at(2.5f, 2.5f), at(6.5f, 2.5f), at(6.5f, 6.5f), at(2.5f, 6.5f)}, {0, 3, 2, 0, 2, 1},
            0);
    const raster::Frame f = render(s, pixelView(kSize, kSize, kDist));
    for (uint32_t y = 0; y < 10; ++y)
        for (uint32_t x = 0; x < 10; ++x) {
            const bool inside = x >= 2 && x <= 5 && y >= 2 && y <= 5;
            EXPECT_EQ(pixel(f, x, y).r, inside ? 0.5f : 0.0f) << x << "," << y;
        }
}

TEST(Coverage, JitteredMeshIsWatertight) {
    // A 12x12 grid of sub-pixel-jittered vertices plus a 16-triangle fan around a pixel centre:
    // every pixel inside is covered exactly once.
    raster::Scene s = blendScene();
    std::vector<glm::vec3> pos;
    std::vector<uint32_t> idx;
    const int n = 12;
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) {
            const bool border = i == 0 || j == 0 || i == n || j == n;
            const uint32_t k = uint32_t(j * (n + 1) + i);
            const float jx = border ? 0.0f : 2.5f * jitter(2 * k);
            const float jy = border ? 0.0f : 2.5f * jitter(2 * k + 1);
            pos.push_back(at(4.0f + 4.5f * float(i) + jx, 4.0f + 4.5f * float(j) + jy));
        }
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const uint32_t a = uint32_t(j * (n + 1) + i), b = a + 1, c = a + uint32_t(n + 1),
                           d = c + 1;
            if ((i + j) % 2)
                idx.insert(idx.end(), {a, c, b, b, c, d});
            else
                idx.insert(idx.end(), {a, c, d, a, d, b});
        }
    addMesh(s, pos, idx, 0);
    const raster::Frame f = render(s, pixelView(kSize, kSize, kDist));
    // Pixels whose centre is well inside [4, 58] are covered exactly once; none twice.
    for (uint32_t y = 0; y < kSize; ++y)
        for (uint32_t x = 0; x < kSize; ++x) {
            const float v = pixel(f, x, y).r;
            EXPECT_TRUE(v == 0.0f || v == 0.5f) << x << "," << y << " = " << v;
            if (x >= 5 && x < 57 && y >= 5 && y < 57) {
                EXPECT_EQ(v, 0.5f) << x << "," << y;
            }
        }
}

TEST(Coverage, FanAroundPixelCentreCoversItOnce) {
    raster::Scene s = blendScene();
    std::vector<glm::vec3> pos = {at(20.5f, 20.5f)};
    std::vector<uint32_t> idx;
    const int n = 16;
    for (int i = 0; i < n; ++i) {
        const float a = float(i) * 6.2831853f / float(n);
        pos.push_back(at(20.5f + 9.0f * std::cos(a), 20.5f + 9.0f * std::sin(a)));
    }
    for (int i = 0; i < n; ++i)
        idx.insert(idx.end(), {0u, uint32_t(1 + (i + 1) % n), uint32_t(1 + i)});
    addMesh(s, pos, idx, 0);
    const raster::Frame f = render(s, pixelView(kSize, kSize, kDist));
    EXPECT_EQ(pixel(f, 20, 20).r, 0.5f);
    for (uint32_t y = 12; y < 30; ++y)
        for (uint32_t x = 12; x < 30; ++x) {
            const float v = pixel(f, x, y).r;
            EXPECT_TRUE(v == 0.0f || v == 0.5f) << x << "," << y << " = " << v;
        }
    for (uint32_t y = 15; y < 26; ++y)
        for (uint32_t x = 15; x < 26; ++x)
            EXPECT_EQ(pixel(f, x, y).r, 0.5f) << x << "," << y;
}

TEST(Coverage, GroundPlaneCrossingTheNearPlaneIsClipped) {
    // A ground quad from 1000 behind the eye to 1000 in front: after near-plane clipping it
    // covers exactly the rows below the horizon (row centres below H/2 + f/1000).
    raster::Scene s = blendScene();
    addMesh(s, {{-1000, -1, 1000}, {1000, -1, 1000}, {1000, -1, -1000}, {-1000, -1, -1000}},
            {0, 1, 2, 0, 2, 3}, 0);
    raster::View v = pixelView(kSize, kSize, kDist);
    v.zfar = 0.0f;
    raster::FrameStats stats;
    const raster::Frame f = render(s, v, {}, 0, &stats);
    EXPECT_GT(stats.triangles_clipped, 0u);
    for (uint32_t y = 0; y < kSize; ++y)
        for (uint32_t x = 0; x < kSize; ++x)
            EXPECT_EQ(pixel(f, x, y).r, y >= 32 ? 0.5f : 0.0f) << x << "," << y;
}

TEST(Coverage, HugeTriangleBeyondTheGuardBandCoversEveryPixelOnce) {
    raster::Scene s = blendScene();
    addMesh(s, {at(-1e6f, -1e6f), at(-1e6f, 3e6f), at(3e6f, -1e6f)}, {0, 1, 2}, 0);
    raster::FrameStats stats;
    const raster::Frame f = render(s, pixelView(kSize, kSize, kDist), {}, 0, &stats);
    EXPECT_EQ(stats.triangles_clipped, 1u);
    for (uint32_t y = 0; y < kSize; ++y)
        for (uint32_t x = 0; x < kSize; ++x)
            ASSERT_EQ(pixel(f, x, y).r, 0.5f) << x << "," << y;
}

TEST(Coverage, SmallTriangleCoveringNoPixelCentreIsCulledAtSetup) {
    // Two one-pixel triangles whose bounding boxes both hold the centre (10.5, 10.5): A's
    // hypotenuse (x + y = 20.8) passes before it, B's (x + y = 21.2) beyond it. Set-up tests the
    // few centres of a small box with the raster's edge functions: A is culled there and never
    // reaches binning, B covers the pixel once.
    raster::Scene s = blendScene();
    addMesh(s, {at(9.9f, 9.9f), at(10.9f, 9.9f), at(9.9f, 10.9f)}, {0, 2, 1}, 0);
    addMesh(s, {at(10.1f, 10.1f), at(11.1f, 10.1f), at(10.1f, 11.1f)}, {0, 2, 1}, 0);
    raster::FrameStats stats;
    const raster::Frame f = render(s, pixelView(kSize, kSize, kDist), {}, 0, &stats);
    EXPECT_EQ(stats.triangles_in, 2u);
    EXPECT_EQ(stats.triangles_culled, 1u);
    EXPECT_EQ(stats.triangles_setup, 1u);
    for (uint32_t y = 0; y < 16; ++y)
        for (uint32_t x = 0; x < 16; ++x)
            EXPECT_EQ(pixel(f, x, y).r, x == 10 && y == 10 ? 0.5f : 0.0f) << x << "," << y;
}

TEST(Coverage, ZeroAreaAndSliverTriangles) {
    raster::Scene s = blendScene();
    // Degenerate (collinear) and a sliver thinner than the snapping grid: nothing is drawn, no
    // crash; a long thin sliver covers at most one pixel per row.
    addMesh(s, {at(10, 10), at(20, 20), at(30, 30)}, {0, 1, 2}, 0);
    addMesh(s, {at(10, 40), at(50, 40.001f), at(30, 40)}, {0, 2, 1}, 0);
    addMesh(s, {at(5.5f, 2), at(5.6f, 2), at(5.55f, 60)}, {0, 2, 1}, 0);
    raster::FrameStats stats;
    const raster::Frame f = render(s, pixelView(kSize, kSize, kDist), {}, 0, &stats);
    EXPECT_GE(stats.triangles_culled, 2u);
    for (uint32_t y = 0; y < kSize; ++y) {
        int covered = 0;
        for (uint32_t x = 0; x < kSize; ++x) {
            const float v = pixel(f, x, y).r;
            EXPECT_TRUE(v == 0.0f || v == 0.5f);
            covered += v > 0.0f;
        }
        EXPECT_LE(covered, 1) << "row " << y;
    }
}

struct CullCase {
    const char* name;
    bool clockwise; // as seen from the camera
    bool double_sided;
    bool mirrored;
    bool visible;
};

class Culling : public ::testing::TestWithParam<CullCase> {};

TEST_P(Culling, HonoursWindingDoubleSidedAndMirroring) {
    const CullCase c = GetParam();
    raster::Scene s;
    addMaterial(s, flatMaterial(glm::vec4(1.0f), AlphaMode::Opaque, c.double_sided));
    // Counter-clockwise as seen from the camera is glTF's front face.
    std::vector<uint32_t> idx =
        c.clockwise ? std::vector<uint32_t>{0, 2, 1} : std::vector<uint32_t>{0, 1, 2};
    const glm::mat4 world =
        c.mirrored ? glm::scale(glm::mat4(1.0f), glm::vec3(-1.0f, 1.0f, 1.0f)) : glm::mat4(1.0f);
    addMesh(s, {at(10, 50), at(50, 50), at(30, 10)}, idx, 0, world);
    const raster::Frame f = render(s, pixelView(kSize, kSize, kDist));
    EXPECT_EQ(pixel(f, 32, 40).r, c.visible ? 1.0f : 0.0f);
}

INSTANTIATE_TEST_SUITE_P(
    Raster, Culling,
    ::testing::Values(CullCase{"front", false, false, false, true},
                      CullCase{"back", true, false, false, false},
                      CullCase{"back_double_sided", true, true, false, true},
                      // A mirroring transform flips the winding, so the authored front face
                      // (now clockwise on screen) stays visible and the back one is culled.
                      CullCase{"front_mirrored", false, false, true, true},
                      CullCase{"back_mirrored", true, false, true, false}),
    [](const auto& test) { return std::string(test.param.name); });

} // namespace
} // namespace focal::test
