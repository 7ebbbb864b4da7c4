// Depth test precision, perspective-correct interpolation, alpha modes and determinism (issue 3).
#include "support/test_util.h"

#include <raster/camera.h>

#include <gtest/gtest.h>

#include <cmath>

namespace focal::test {
namespace {

using raster::AlphaMode;
using raster::DepthFormat;

constexpr uint32_t kSize = 64;
constexpr float kDist = 64.0f;

std::vector<glm::vec3> quadAt(float depth, float half) {
    return {
        {-half, -half, -depth}, {half, -half, -depth}, {half, half, -depth}, {-half, half, -depth}};
}
const std::vector<uint32_t> kQuad = {0, 1, 2, 0, 2, 3};

// A red plane at first_depth drawn before a green one at second_depth, both covering the
// centre pixel.
raster::Frame renderTwoPlanes(float first_depth, float second_depth, DepthFormat format,
                              float znear = 0.5f, float zfar = 256.0f) {
    raster::Scene s;
    const int32_t red = addMaterial(s, flatMaterial({1, 0, 0, 1}));
    const int32_t green = addMaterial(s, flatMaterial({0, 1, 0, 1}));
    addMesh(s, quadAt(first_depth, 40.0f), kQuad, red);
    addMesh(s, quadAt(second_depth, 40.0f), kQuad, green);
    raster::View v = pixelView(kSize, kSize, kDist);
    v.znear = znear;
    v.zfar = zfar;
    raster::RenderOptions o;
    o.depth_format = format;
    return render(s, v, o);
}

TEST(Depth, NearerSurfaceWinsInEitherOrder) {
    for (DepthFormat format : {DepthFormat::Float32, DepthFormat::Unorm16}) {
        EXPECT_EQ(pixel(renderTwoPlanes(100.0f, 90.0f, format), 32, 32).g, 1.0f);
        EXPECT_EQ(pixel(renderTwoPlanes(90.0f, 100.0f, format), 32, 32).r, 1.0f);
    }
}

TEST(Depth, SixteenBitStorageCannotSeparateCloseSurfaces) {
    // At d = 100 with n = 0.5 one unorm16 step is ~0.3 world units; 0.01 apart is the same
    // stored value, so the LESS test keeps the first surface. Float32 resolves it.
    EXPECT_EQ(pixel(renderTwoPlanes(100.0f, 99.99f, DepthFormat::Float32), 32, 32).g, 1.0f);
    EXPECT_EQ(pixel(renderTwoPlanes(100.0f, 99.99f, DepthFormat::Unorm16), 32, 32).r, 1.0f);
}

TEST(Depth, FloatDepthKeepsFarSurfacesApartWithATinyNearPlane) {
    // Near 1e-5 and no far plane: D = -n/d is about -1e-8 at d = 1000, where float still has 24
    // bits. The classic D = 1 - n/d rounded both planes onto the far value 1 and drew nothing.
    for (const float gap : {1.0f, 0.01f}) {
        const raster::Frame a =
            renderTwoPlanes(1000.0f, 1000.0f - gap, DepthFormat::Float32, 1e-5f, 0.0f);
        const raster::Frame b =
            renderTwoPlanes(1000.0f - gap, 1000.0f, DepthFormat::Float32, 1e-5f, 0.0f);
        EXPECT_EQ(pixel(a, 32, 32), glm::vec4(0, 1, 0, 1)) << "gap " << gap;
        EXPECT_EQ(pixel(b, 32, 32), glm::vec4(1, 0, 0, 1)) << "gap " << gap;
    }
    // Far beyond any scene, surfaces still store below the far value.
    raster::View v = pixelView(kSize, kSize, kDist);
    v.znear = 1e-5f;
    v.zfar = 0.0f;
    EXPECT_LT(raster::depthFromDistance(v, 1e30f), raster::kFarDepth);
    EXPECT_NEAR(raster::distanceFromDepth(v, raster::depthFromDistance(v, 1e6f)), 1e6f, 1.0f);
}

// The tile raster queues the lit lanes of small triangles and shades them eight at a time
// (tile_raster.cpp, LightBatch): a pixel queued twice must still end with the nearer
// triangle's colour in either drawing order, the same colour that triangle gives alone (the
// later one's queued colour lands last; the earlier one's queued depth rejects a farther one).
TEST(Depth, QueuedLitLanesKeepPrimitiveOrder) {
    raster::Material red = flatMaterial({1, 0, 0, 1}), green = flatMaterial({0, 1, 0, 1});
    red.unlit = green.unlit = false; // the same lighting constants: one queue
    const std::vector<uint32_t> tri = {0, 1, 2};
    // About two pixels around the centre pixel (32, 32) at depth d (1 unit = 1 pixel at kDist).
    auto tinyAt = [](float d) {
        const float k = d / kDist;
        return std::vector<glm::vec3>{
            {-0.2f * k, -1.2f * k, -d}, {1.8f * k, -1.2f * k, -d}, {0.8f * k, 0.9f * k, -d}};
    };
    auto centre = [&](std::vector<std::pair<raster::Material, float>> drawn) {
        raster::Scene s;
        for (const auto& [m, d] : drawn)
            addMesh(s, tinyAt(d), tri, addMaterial(s, m));
        raster::FrameStats stats;
        const raster::Frame f = render(s, pixelView(kSize, kSize, kDist), {}, 0, &stats);
        EXPECT_LE(stats.fragments_passed, 2u * 4u * drawn.size()); // small: queued lanes
        return pixel(f, 32, 32);
    };
    const glm::vec4 alone = centre({{green, 60.0f}});
    EXPECT_GT(alone.g, 0.0f);
    EXPECT_EQ(alone.r, 0.0f);
    EXPECT_EQ(centre({{red, 64.0f}, {green, 60.0f}}), alone);
    EXPECT_EQ(centre({{green, 60.0f}, {red, 64.0f}}), alone);
}

// The same with pairs of five or more lit lanes, which the fragment kernel writes into whole
// blocks of the queue, mixed with packed lanes of small triangles: a pixel queued twice ends with
// its later triangle's colour whichever way each was queued.
TEST(Depth, QueuedWholeBlocksKeepPrimitiveOrder) {
    raster::Material red = flatMaterial({1, 0, 0, 1}), green = flatMaterial({0, 1, 0, 1});
    red.unlit = green.unlit = false; // the same lighting constants: one queue
    const std::vector<uint32_t> tri = {0, 1, 2};
    // At depth d: about two pixels around the centre pixel (32, 32), or five of the eight
    // pixels of its quad pair (x 32-35, y 32-33) and no other pixel, so that two of them queued
    // one after the other share a batch.
    auto triangleAt = [](float d, bool pair) {
        const float k = d / kDist;
        if (pair)
            return std::vector<glm::vec3>{
                {0.02f * k, 0.02f * k, -d}, {4.4f * k, 0.02f * k, -d}, {0.02f * k, -2.3f * k, -d}};
        return std::vector<glm::vec3>{
            {-0.2f * k, -1.2f * k, -d}, {1.8f * k, -1.2f * k, -d}, {0.8f * k, 0.9f * k, -d}};
    };
    struct Drawn {
        raster::Material m;
        float d;
        bool pair;
    };
    auto centre = [&](std::vector<Drawn> drawn) {
        raster::Scene s;
        for (const Drawn& t : drawn)
            addMesh(s, triangleAt(t.d, t.pair), tri, addMaterial(s, t.m));
        raster::FrameStats stats;
        const raster::Frame f = render(s, pixelView(kSize, kSize, kDist), {}, 0, &stats);
        if (drawn.size() == 1 && drawn[0].pair) {
            EXPECT_EQ(stats.fragments_passed, 5u); // a whole block of the queue
        }
        return pixel(f, 32, 32);
    };
    for (const bool pair_green : {false, true}) {
        const glm::vec4 alone = centre({{green, 60.0f, pair_green}});
        EXPECT_GT(alone.g, 0.0f);
        EXPECT_EQ(alone.r, 0.0f);
        for (const bool pair_red : {false, true}) {
            if (!pair_red && !pair_green)
                continue; // Depth.QueuedLitLanesKeepPrimitiveOrder
            EXPECT_EQ(centre({{red, 64.0f, pair_red}, {green, 60.0f, pair_green}}), alone)
                << pair_red << pair_green;
            EXPECT_EQ(centre({{green, 60.0f, pair_green}, {red, 64.0f, pair_red}}), alone)
                << pair_red << pair_green;
            // A red one behind, then green in front, then red again behind: still green.
            EXPECT_EQ(
                centre(
                    {{red, 64.0f, pair_red}, {green, 60.0f, pair_green}, {red, 62.0f, pair_red}}),
                alone)
                << pair_red << pair_green;
        }
    }
}

TEST(Depth, StoredValuesMatchTheProjection) {
    for (DepthFormat format : {DepthFormat::Float32, DepthFormat::Unorm16}) {
        const raster::Frame f = renderTwoPlanes(100.0f, 200.0f, format);
        raster::View v = pixelView(kSize, kSize, kDist);
        v.znear = 0.5f;
        v.zfar = 256.0f;
        const float expected = raster::depthFromDistance(v, 100.0f);
        const float stored = f.depth.load(32 * kSize + 32);
        const float tolerance = format == DepthFormat::Float32 ? 1e-6f : 0.5f / 65535.0f;
        EXPECT_NEAR(stored, expected, tolerance);
        EXPECT_NEAR(raster::distanceFromDepth(v, stored), 100.0f,
                    format == DepthFormat::Float32 ? 1e-3f : 0.2f);
        EXPECT_EQ(f.depth.load(0), raster::kFarDepth); // background keeps the clear value
    }
}

TEST(Interpolation, IsPerspectiveCorrect) {
    // A floor y = -1 from d = 2 to d = 20 whose red channel ramps 0 -> 1 with distance. Each
    // pixel must show the value at the point its centre ray hits (affine would be far off).
    raster::Scene s;
    raster::Material m = flatMaterial({1, 1, 1, 1});
    const int32_t mat = addMaterial(s, m);
    raster::Primitive& p =
        addMesh(s, {{-8, -1, -2}, {8, -1, -2}, {8, -1, -20}, {-8, -1, -20}}, kQuad, mat);
    p.colors = {{0, 0, 0, 1}, {0, 0, 0, 1}, {1, 0, 0, 1}, {1, 0, 0, 1}};
    const raster::View v = pixelView(kSize, kSize, kDist);
    const raster::Frame f = render(s, v);
    const float fpx = raster::focalLengthPx(v);
    int checked = 0;
    for (uint32_t y = 33; y < kSize; ++y) {
        const float ray_y = (32.0f - (float(y) + 0.5f)) / fpx; // y/d along the centre ray
        const float d = -1.0f / ray_y;
        if (d < 2.05f || d > 19.95f)
            continue;
        // 1e-3: snapping the far vertices to 1/256 px moves the ramp slightly near the horizon;
        // affine (non-perspective) interpolation is off by up to ~0.4 here.
        EXPECT_NEAR(pixel(f, 32, y).r, (d - 2.0f) / 18.0f, 1e-3f) << "row " << y;
        ++checked;
    }
    EXPECT_GT(checked, 10);
}

TEST(Alpha, MaskDiscardsBelowTheCutoffAndIsOpaqueAbove) {
    raster::Scene s;
    raster::Material m = flatMaterial({0, 0, 1, 1}, AlphaMode::Mask);
    m.alpha_cutoff = 0.5f;
    const int32_t mat = addMaterial(s, m);
    // Alpha ramps 0 (left) -> 1 (right) across the quad.
    raster::Primitive& p = addMesh(s, quadAt(kDist, 32.0f), kQuad, mat);
    p.colors = {{1, 1, 1, 0}, {1, 1, 1, 1}, {1, 1, 1, 1}, {1, 1, 1, 0}};
    const raster::Frame f = render(s, pixelView(kSize, kSize, kDist));
    EXPECT_EQ(pixel(f, 10, 32), glm::vec4(0, 0, 0, 1)); // alpha ~0.16: discarded
    EXPECT_EQ(pixel(f, 50, 32), glm::vec4(0, 0, 1, 1)); // alpha ~0.79: opaque, full alpha
    EXPECT_EQ(f.depth.load(32 * kSize + 10), raster::kFarDepth);
    EXPECT_LT(f.depth.load(32 * kSize + 50), raster::kFarDepth);
}

TEST(Alpha, BlendIsOverInPrimitiveOrderAfterOpaqueWithoutDepthWrite) {
    raster::Scene s;
    s.background = glm::vec3(0.0f);
    const int32_t a = addMaterial(s, flatMaterial({1, 0, 0, 0.5f}, AlphaMode::Blend));
    const int32_t b = addMaterial(s, flatMaterial({0, 1, 0, 0.25f}, AlphaMode::Blend));
    const int32_t opaque = addMaterial(s, flatMaterial({0, 0, 1, 1}));
    addMesh(s, quadAt(50.0f, 20.0f), kQuad, a);
    addMesh(s, quadAt(40.0f, 20.0f), kQuad, b);
    // An opaque surface behind both, submitted last: BLEND triangles are drawn after every
    // opaque one (they write no depth, so the wall would otherwise cover the panes), then over
    // each other in primitive order.
    addMesh(s, {{0, -20, -60}, {20, -20, -60}, {20, 20, -60}, {0, 20, -60}}, kQuad, opaque);
    const raster::Frame f = render(s, pixelView(kSize, kSize, kDist));
    const glm::vec4 left = pixel(f, 20, 32); // no wall: a over black, then b over that
    EXPECT_FLOAT_EQ(left.r, 0.5f * 0.75f);
    EXPECT_FLOAT_EQ(left.g, 0.25f);
    EXPECT_FLOAT_EQ(left.b, 0.0f);
    const glm::vec4 right = pixel(f, 40, 32); // a over the blue wall, then b
    EXPECT_FLOAT_EQ(right.r, 0.5f * 0.75f);
    EXPECT_FLOAT_EQ(right.g, 0.25f);
    EXPECT_FLOAT_EQ(right.b, 0.5f * 0.75f);
}

// A busy synthetic scene: overlapping opaque, masked and blended triangles of many sizes.
raster::Scene busyScene() {
    raster::Scene s;
    s.background = {0.1f, 0.2f, 0.3f};
    const int32_t mats[3] = {
        addMaterial(s, flatMaterial({0.8f, 0.3f, 0.2f, 1.0f})),
        addMaterial(s, flatMaterial({0.2f, 0.8f, 0.3f, 0.6f}, AlphaMode::Blend)),
        addMaterial(s, flatMaterial({0.3f, 0.2f, 0.9f, 0.7f}, AlphaMode::Mask))};
    std::vector<glm::vec3> pos;
    std::vector<uint32_t> idx;
    for (uint32_t i = 0; i < 600; ++i) {
        auto h = [i](uint32_t k) {
            uint32_t x = i * 2654435761u + k * 40503u;
            x ^= x >> 13;
            x *= 0x5bd1e995u;
            x ^= x >> 15;
            return float(x & 0xffffu) / 65536.0f;
        };
        const glm::vec3 c(200.0f * h(1) - 100.0f, 150.0f * h(2) - 75.0f, -60.0f - 200.0f * h(3));
        const float r = 2.0f + 60.0f * h(4) * h(4);
        const uint32_t base = uint32_t(pos.size());
        pos.push_back(c + glm::vec3(-r, -r, 30.0f * h(5)));
        pos.push_back(c + glm::vec3(r, -r * h(6), -30.0f * h(7)));
        pos.push_back(c + glm::vec3(r * h(8), r, 0.0f));
        idx.insert(idx.end(), {base, base + 1, base + 2});
    }
    for (int m = 0; m < 3; ++m) {
        raster::Primitive& p = addMesh(s, pos, {}, mats[m]);
        for (size_t t = size_t(m); t < pos.size() / 3; t += 3)
            p.indices.insert(p.indices.end(),
                             {uint32_t(3 * t), uint32_t(3 * t + 1), uint32_t(3 * t + 2)});
    }
    return s;
}

TEST(Determinism, SameBitsForEveryThreadCountAndTileSize) {
    const raster::Scene s = busyScene();
    raster::View v = pixelView(203, 157, 120.0f); // odd sizes: partial tiles and quads
    raster::RenderOptions o;
    for (DepthFormat format : {DepthFormat::Float32, DepthFormat::Unorm16}) {
        o.depth_format = format;
        o.tile_size = 64;
        const uint64_t reference = hashFrame(render(s, v, o, 0));
        for (uint32_t threads : {1u, 2u, 3u, 8u})
            for (uint32_t tile : {16u, 32u, 64u, 128u}) {
                o.tile_size = tile;
                EXPECT_EQ(hashFrame(render(s, v, o, threads)), reference)
                    << "threads " << threads << " tile " << tile;
            }
    }
}

} // namespace
} // namespace focal::test
