// Tests of the Zhou, Chen & Pullen 2007 gather filter (dof/gather.h): depth from the stored
// depth buffer (§4.1), the analytic cases, the Fig. 7 leakage case against accum, the scalar
// reference and determinism across threads and tile sizes.
#include "dof_test_util.h"

#include <dof/gather.h>
#include <dof/lens.h>
#include <raster/camera.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

namespace focal::test {
namespace {

using dof::GatherSettings;

uint64_t hashFloats(const std::vector<float>& v) {
    uint64_t h = 1469598103934665603ull;
    for (float f : v) {
        uint32_t bits = 0;
        std::memcpy(&bits, &f, 4);
        for (int i = 0; i < 4; ++i) {
            h ^= (bits >> (8 * i)) & 0xffu;
            h *= 1099511628211ull;
        }
    }
    return h;
}

dof::GatherImage imageOf(const raster::Frame& f) {
    dof::GatherImage img;
    img.rgba = f.color.data();
    img.depth = dof::depthRefOf(f.depth);
    img.width = f.width;
    img.height = f.height;
    return img;
}

// A synthetic frame: pseudo-random colours and depths (integer hash, no RNG state), with the
// stored depth of distances in [d_lo, d_hi], in the requested format.
raster::Frame noiseFrame(const raster::View& view, raster::DepthFormat format, float d_lo,
                         float d_hi, uint32_t salt = 0) {
    raster::Frame f;
    f.width = view.width;
    f.height = view.height;
    f.color.resize(size_t(f.width) * f.height * 4);
    f.depth.resize(format, f.width, f.height);
    for (uint32_t i = 0; i < f.width * f.height; ++i) {
        for (uint32_t c = 0; c < 4; ++c)
            f.color[4 * i + c] = dof::hashToUnit(dof::hashWords(i, c, salt));
        // Piecewise-constant depth in 5x3 blocks, so there are edges and flat regions.
        const uint32_t bx = (i % f.width) / 5, by = (i / f.width) / 3;
        const float u = dof::hashToUnit(dof::hashWords(bx, by, salt, 99));
        f.depth.store(i, raster::depthFromDistance(view, d_lo + u * (d_hi - d_lo)));
    }
    return f;
}

constexpr float kFocus = 100.0f; // pixelView: f_px = d_f = 100

TEST(Gather, CocIsAffineInTheStoredDepth) {
    for (float zfar : {400.0f, 0.0f}) {
        raster::View view = pixelView(64, 48, kFocus);
        view.zfar = zfar;
        const dof::ThinLens lens = dof::makeThinLens(view, 8.0f, kFocus);
        const dof::CocAffine ca = dof::cocAffine(lens, view);
        for (float d : {0.5f, 0.7f, 3.0f, 50.0f, 99.0f, 100.0f, 101.0f, 250.0f, 399.0f}) {
            const float stored = raster::depthFromDistance(view, d);
            const double c = ca.a * double(stored) + ca.b;
            // Through the slow way: Eq. 7 (distance from the stored value) then Eq. 2.
            const float slow = dof::cocRadiusPx(lens, raster::distanceFromDepth(view, stored));
            EXPECT_NEAR(c, double(slow), 1e-3 * std::max(1.0, std::fabs(double(slow))))
                << "d = " << d << " far = " << zfar;
        }
        // D = -1 is the near plane, D = 0 the far plane (or infinity).
        EXPECT_NEAR(ca.b - ca.a, double(dof::cocRadiusPx(lens, view.znear)), 1e-3);
        const float far_c = dof::cocRadiusPx(lens, zfar > 0.0f ? zfar : INFINITY);
        EXPECT_NEAR(ca.b, double(far_c), 1e-3);
    }
}

TEST(Gather, SixteenBitDepthCocErrorIsBoundedByTheQuantisationStep) {
    const raster::View view = pixelView(80, 60, kFocus);
    const dof::ThinLens lens = dof::makeThinLens(view, 8.0f, kFocus);
    const raster::Frame f32 = noiseFrame(view, raster::DepthFormat::Float32, 20.0f, 390.0f);
    const raster::Frame f16 = noiseFrame(view, raster::DepthFormat::Unorm16, 20.0f, 390.0f);
    std::vector<float> out, coc32, coc16;
    ASSERT_TRUE(dof::gather(imageOf(f32), lens, view, {}, out, &coc32).ok());
    ASSERT_TRUE(dof::gather(imageOf(f16), lens, view, {}, out, &coc16).ok());
    const dof::CocAffine ca = dof::cocAffine(lens, view);
    const double step = ca.a / 65535.0; // pixels of CoC per unorm16 code
    double max_err = 0.0;
    for (size_t i = 0; i < coc32.size(); ++i)
        max_err = std::max(max_err, std::fabs(double(coc16[i]) - double(coc32[i])));
    EXPECT_LE(max_err, 0.51 * step + 1e-4);
    EXPECT_GT(max_err, 0.0);
}

TEST(Gather, AllInFocusImageIsUnchanged) {
    // A textured wall at the focus distance: every CoC is ~0, so every tile is copied.
    const raster::View view = pixelView(96, 72, kFocus);
    raster::Scene scene;
    const int32_t a = addMaterial(scene, flatMaterial({1.0f, 0.5f, 0.25f, 1.0f}));
    const int32_t b = addMaterial(scene, flatMaterial({0.1f, 0.2f, 0.9f, 1.0f}));
    for (int j = -10; j < 10; ++j)
        for (int i = -14; i < 14; ++i)
            addQuad(scene, float(4 * i), float(4 * j), float(4 * i + 4), float(4 * j + 4), kFocus,
                    ((i + j) & 1) ? a : b);
    for (raster::DepthFormat fmt : {raster::DepthFormat::Float32, raster::DepthFormat::Unorm16}) {
        raster::RenderOptions opt;
        opt.depth_format = fmt;
        const raster::Frame frame = render(scene, view, opt);
        const dof::ThinLens lens = dof::makeThinLens(view, 8.0f, kFocus);
        for (bool skip : {true, false}) {
            GatherSettings s;
            s.skip_tiles = skip;
            s.max_radius_px = 24.0f;
            std::vector<float> out;
            raster::Result<dof::GatherStats> r = dof::gather(imageOf(frame), lens, view, s, out);
            ASSERT_TRUE(r.ok()) << r.status().message();
            EXPECT_EQ(hashFloats(out), hashFloats(frame.color));
            EXPECT_LT(std::fabs(r->max_coc_px), 0.5f);
            if (skip) {
                EXPECT_EQ(r->tiles_copied, r->tiles);
                EXPECT_EQ(r->samples, 0u);
            }
        }
    }
    // The synthetic frame, all depths at d_f, at any aperture: unchanged too.
    const raster::Frame flat = noiseFrame(view, raster::DepthFormat::Float32, kFocus, kFocus);
    std::vector<float> out;
    ASSERT_TRUE(
        dof::gather(imageOf(flat), dof::makeThinLens(view, 50.0f, kFocus), view, {}, out).ok());
    EXPECT_EQ(hashFloats(out), hashFloats(flat.color));
}

TEST(Gather, PinholeLensIsTheIdentity) {
    const raster::View view = pixelView(70, 50, kFocus);
    const raster::Frame f = noiseFrame(view, raster::DepthFormat::Float32, 1.0f, 399.0f);
    std::vector<float> out;
    ASSERT_TRUE(dof::gather(imageOf(f), dof::makeThinLens(view, 0.0f, kFocus), view, {}, out).ok());
    EXPECT_EQ(hashFloats(out), hashFloats(f.color));
}

TEST(Gather, ConstantImageStaysConstant) {
    const raster::View view = pixelView(90, 70, kFocus);
    raster::Frame f = noiseFrame(view, raster::DepthFormat::Float32, 10.0f, 399.0f);
    const float colour[4] = {0.3f, 0.6f, 0.9f, 1.0f};
    for (size_t i = 0; i < f.color.size(); ++i)
        f.color[i] = colour[i % 4];
    GatherSettings s;
    s.max_radius_px = 20.0f;
    std::vector<float> out;
    raster::Result<dof::GatherStats> r =
        dof::gather(imageOf(f), dof::makeThinLens(view, 10.0f, kFocus), view, s, out);
    ASSERT_TRUE(r.ok());
    EXPECT_GT(r->samples, 0u);
    for (size_t i = 0; i < out.size(); ++i)
        ASSERT_NEAR(out[i], colour[i % 4], 4e-6f * colour[i % 4]) << "value " << i;
}

TEST(Gather, BlurredWallSpreadsAStepOverTheCoc) {
    // A wall at d = 400 with CoC r = 6 px: a vertical colour step becomes a ramp as wide as the
    // 1-D filter's support, 2r - 1 ... 2r + 1 pixels, centred on the step; far from it nothing
    // changes.
    const raster::View view = pixelView(64, 32, kFocus);
    const dof::ThinLens lens = dof::makeThinLens(view, 8.0f, kFocus); // C(400) = +6 px
    raster::Frame f;
    f.width = view.width, f.height = view.height;
    f.color.assign(size_t(f.width) * f.height * 4, 1.0f);
    f.depth.resize(raster::DepthFormat::Float32, f.width, f.height);
    for (uint32_t i = 0; i < f.width * f.height; ++i) {
        f.depth.store(i, raster::depthFromDistance(view, 400.0f));
        if (i % f.width < 32)
            f.color[4 * i] = f.color[4 * i + 1] = f.color[4 * i + 2] = 0.0f;
    }
    std::vector<float> out;
    ASSERT_TRUE(dof::gather(imageOf(f), lens, view, {}, out).ok());
    const uint32_t y = 16;
    auto at = [&](uint32_t x) { return out[(size_t(y) * f.width + x) * 4]; };
    EXPECT_EQ(at(25), 0.0f); // 7 px from the step: out of reach
    EXPECT_EQ(at(38), 1.0f);
    EXPECT_NEAR(at(31) + at(32), 1.0f, 1e-6f); // symmetric about the step
    for (uint32_t x = 26; x < 37; ++x)
        EXPECT_LT(at(x), at(x + 1)) << x;
}

// Fig. 7: an in-focus foreground object over a blurred background. The object stays sharp and
// does not leak onto the background around it; the background does not leak onto the object.
TEST(Gather, InFocusObjectDoesNotLeakOntoTheBlurredBackground) {
    constexpr uint32_t kW = 96, kH = 96;
    raster::View view = pixelView(kW, kH, kFocus);
    view.zfar = 1000.0f;
    const dof::ThinLens lens = dof::makeThinLens(view, 8.0f, kFocus); // background: +6 px
    raster::Scene scene;
    const int32_t red = addMaterial(scene, flatMaterial({1.0f, 0.0f, 0.0f, 1.0f}));
    const int32_t g = addMaterial(scene, flatMaterial({0.0f, 0.8f, 0.2f, 1.0f}));
    const int32_t b = addMaterial(scene, flatMaterial({0.0f, 0.1f, 0.7f, 1.0f}));
    constexpr float kBack = 400.0f;
    for (int j = -10; j < 10; ++j)
        for (int i = -10; i < 10; ++i)
            addQuad(scene, float(8 * i) * 4.0f, float(8 * j) * 4.0f, float(8 * i + 8) * 4.0f,
                    float(8 * j + 8) * 4.0f, kBack, ((i + j) & 1) ? g : b);
    // The object: pixels [36, 60) x [36, 60), in focus.
    addQuad(scene, -12.0f, -12.0f, 12.0f, 12.0f, kFocus, red);

    const raster::Frame pinhole = render(scene, view);
    dof::AccumStats accum_stats;
    const raster::Frame accum =
        renderAccum(scene, view, lens, makeSamples(256), {}, 0, {}, &accum_stats);
    ASSERT_FALSE(accum_stats.skipped);
    GatherSettings s;
    s.max_radius_px = 16.0f;
    std::vector<float> out;
    ASSERT_TRUE(dof::gather(imageOf(pinhole), lens, view, s, out).ok());

    auto inside = [](int x, int y, int margin) {
        return x >= 36 - margin && x < 60 + margin && y >= 36 - margin && y < 60 + margin;
    };
    double ring_err = 0.0, max_red = 0.0, obj_err = 0.0;
    uint32_t ring = 0;
    for (int y = 0; y < int(kH); ++y)
        for (int x = 0; x < int(kW); ++x) {
            const size_t i = (size_t(y) * kW + size_t(x)) * 4;
            if (inside(x, y, 0)) {
                // The object: unchanged (background samples get L = min(1, r_c) ~ 0).
                for (int c = 0; c < 3; ++c)
                    obj_err =
                        std::max(obj_err, double(std::fabs(out[i + c] - pinhole.color[i + c])));
                continue;
            }
            if (!inside(x, y, 8))
                continue;
            // The background ring up to 8 px around the object (more than its 6 px CoC).
            ++ring;
            max_red = std::max(max_red, double(out[i]));
            for (int c = 0; c < 3; ++c)
                ring_err += std::fabs(double(out[i + c]) - double(accum.color[i + c]));
        }
    ring_err /= 3.0 * ring;
    EXPECT_LT(max_red, 1e-6); // no object colour outside the object
    // The in-focus object stays sharp: its CoC is ~1e-5 px (float depth), so L ~ 1e-5.
    EXPECT_LT(obj_err, 1e-4);
    // The background there matches accum (measured 0.0082; accum with 256 samples).
    EXPECT_LT(ring_err, 0.02);
    // accum itself shows no red there either: the error is blur shape, not leakage.
    double accum_red = 0.0;
    for (int y = 0; y < int(kH); ++y)
        for (int x = 0; x < int(kW); ++x)
            if (!inside(x, y, 0) && inside(x, y, 8))
                accum_red = std::max(accum_red, double(accum.color[(size_t(y) * kW + x) * 4]));
    EXPECT_LT(accum_red, 1e-6);
    RecordProperty("ring_mean_abs_error", std::to_string(ring_err));
    std::printf("ring mean abs error %.5f over %u px\n", ring_err, ring);
}

TEST(Gather, FastPathEqualsTheScalarReference) {
    const raster::View view = pixelView(83, 61, kFocus); // not a multiple of 8 or the tile
    for (raster::DepthFormat fmt : {raster::DepthFormat::Float32, raster::DepthFormat::Unorm16}) {
        const raster::Frame f = noiseFrame(view, fmt, 30.0f, 399.0f, 7);
        for (float radius : {1.0f, 3.5f, 9.0f, 17.0f}) {
            GatherSettings s;
            s.max_radius_px = radius;
            s.tile_size = 16;
            std::vector<float> fast, scalar, ref;
            const dof::ThinLens lens = dof::makeThinLens(view, 6.0f, kFocus);
            ASSERT_TRUE(dof::gather(imageOf(f), lens, view, s, fast).ok());
            s.simd = false; // the tiled path without its SSE2 lanes
            ASSERT_TRUE(dof::gather(imageOf(f), lens, view, s, scalar).ok());
            ASSERT_TRUE(dof::gatherReference(imageOf(f), lens, view, s, ref).ok());
            EXPECT_EQ(hashFloats(fast), hashFloats(ref)) << "R = " << radius;
            EXPECT_EQ(hashFloats(scalar), hashFloats(ref)) << "R = " << radius;
        }
    }
}

TEST(Gather, SameBitsForEveryThreadCountAndTileSize) {
    const raster::View view = pixelView(150, 110, kFocus);
    const raster::Frame f = noiseFrame(view, raster::DepthFormat::Unorm16, 20.0f, 399.0f, 3);
    const dof::ThinLens lens = dof::makeThinLens(view, 10.0f, kFocus);
    GatherSettings s;
    s.max_radius_px = 12.0f;
    std::vector<float> first;
    std::vector<float> first_coc;
    ASSERT_TRUE(dof::gather(imageOf(f), lens, view, s, first, &first_coc).ok());
    for (uint32_t threads : {0u, 1u, 2u, 3u, 8u})
        for (uint32_t tile : {8u, 24u, 64u, 256u})
            for (bool skip : {true, false}) {
                raster::TaskPool pool(threads);
                dof::GatherScratch scratch;
                s.tile_size = tile;
                s.skip_tiles = skip;
                std::vector<float> out, coc;
                for (int run = 0; run < 2; ++run) { // the second run reuses the scratch
                    ASSERT_TRUE(
                        dof::gather(imageOf(f), lens, view, s, out, &coc, &pool, &scratch).ok());
                    EXPECT_EQ(hashFloats(out), hashFloats(first))
                        << "threads " << threads << " tile " << tile << " skip " << skip;
                    EXPECT_EQ(hashFloats(coc), hashFloats(first_coc));
                }
            }
}

TEST(Gather, RejectsBadInputWithTheSettingName) {
    const raster::View view = pixelView(32, 32, kFocus);
    raster::Frame f = noiseFrame(view, raster::DepthFormat::Float32, 20.0f, 300.0f);
    const dof::ThinLens lens = dof::makeThinLens(view, 4.0f, kFocus);
    std::vector<float> out;
    auto message = [&](GatherSettings s) {
        raster::Result<dof::GatherStats> r = dof::gather(imageOf(f), lens, view, s, out);
        return r.ok() ? std::string() : r.status().message();
    };
    GatherSettings s;
    s.max_radius_px = 0.5f;
    EXPECT_NE(message(s).find("gather settings: max_radius_px"), std::string::npos);
    s.max_radius_px = NAN;
    EXPECT_NE(message(s).find("gather settings: max_radius_px"), std::string::npos);
    s = {};
    s.leak_scale = -1.0f;
    EXPECT_NE(message(s).find("gather settings: leak_scale"), std::string::npos);
    s = {};
    s.min_radius_px = 0.0f;
    EXPECT_NE(message(s).find("gather settings: min_radius_px"), std::string::npos);
    s = {};
    s.tile_size = 12;
    EXPECT_NE(message(s).find("tile"), std::string::npos);
    EXPECT_TRUE(message({}).empty());

    raster::Result<dof::GatherStats> bad_lens =
        dof::gather(imageOf(f), dof::makeThinLens(view, -1.0f, kFocus), view, {}, out);
    ASSERT_FALSE(bad_lens.ok());
    EXPECT_NE(bad_lens.status().message().find("aperture_radius"), std::string::npos);

    f.depth.float32[5 * 32 + 7] = 1.5f;
    f.depth.float32[9 * 32 + 1] = NAN;
    std::string m = message({});
    EXPECT_NE(m.find("(7, 5)"), std::string::npos) << m;
    f.depth.float32[5 * 32 + 7] = -0.5f;
    m = message({});
    EXPECT_NE(m.find("(1, 9)"), std::string::npos) << m;
    f.depth.float32[9 * 32 + 1] = -0.5f;
    f.color[4 * 33 + 2] = INFINITY;
    m = message({});
    EXPECT_NE(m.find("colour"), std::string::npos) << m;

    dof::GatherImage empty;
    raster::Result<dof::GatherStats> r = dof::gather(empty, lens, view, {}, out);
    EXPECT_FALSE(r.ok());
}

} // namespace
} // namespace focal::test
