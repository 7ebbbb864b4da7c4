// dof/lens.h: the thin-lens CoC, its signs, the photographic mapping and validation.
#include "dof_test_util.h"

#include <dof/layer_spacing.h>
#include <dof/lens.h>
#include <raster/frame.h>
#include <scenes/builtin.h>

#include <gtest/gtest.h>

#include <cmath>
#include <string_view>

namespace focal::test {
namespace {

TEST(Lens, CocIsSignedAndZeroAtTheFocusDistance) {
    const raster::View view = pixelView(64, 64, 100.0f);
    const dof::ThinLens lens = dof::makeThinLens(view, 2.0f, 100.0f);
    EXPECT_FLOAT_EQ(lens.focal_length_px, 100.0f);
    EXPECT_EQ(dof::cocRadiusPx(lens, 100.0f), 0.0f);
    EXPECT_LT(dof::cocRadiusPx(lens, 50.0f), 0.0f);  // in front: negative
    EXPECT_GT(dof::cocRadiusPx(lens, 200.0f), 0.0f); // behind: positive
    // E f (1/d_f - 1/d): 2 * 100 * (0.01 - 0.02) = -2; 2 * 100 * (0.01 - 0.005) = 1.
    EXPECT_FLOAT_EQ(dof::cocRadiusPx(lens, 50.0f), -2.0f);
    EXPECT_FLOAT_EQ(dof::cocRadiusPx(lens, 200.0f), 1.0f);
    EXPECT_FLOAT_EQ(dof::cocRadiusPx(lens, INFINITY), 2.0f);
    // Affine in 1/d (Lee et al. 2009, Sec. 4.1: layers uniform in C).
    const float c1 = dof::cocRadiusPx(lens, 1.0f / 0.004f),
                c2 = dof::cocRadiusPx(lens, 1.0f / 0.006f),
                c3 = dof::cocRadiusPx(lens, 1.0f / 0.008f);
    EXPECT_NEAR(c2 - c1, c3 - c2, 1e-5f);
}

TEST(Lens, LensRayOffsetFlipsY) {
    const glm::vec2 o = dof::lensRayImageOffset(4.0f, {0.5f, 0.25f});
    EXPECT_FLOAT_EQ(o.x, -2.0f);
    EXPECT_FLOAT_EQ(o.y, 1.0f);
}

TEST(Lens, BlenderFStopMapping) {
    // 50 mm at f/2: E = 0.05 / 4 = 12.5 mm; 24 mm sensor: yfov = 2 atan(12/50) = 26.99 degrees.
    EXPECT_FLOAT_EQ(dof::apertureRadiusFromFStop(50.0f, 2.0f), 0.0125f);
    EXPECT_NEAR(dof::yfovFromFocalLength(50.0f, 24.0f) * 180.0f / 3.14159265f, 26.9915f, 1e-3f);
}

TEST(Lens, ValidateRejectsNonsense) {
    raster::View view = pixelView(64, 64, 100.0f); // far = 400
    EXPECT_TRUE(dof::validate(dof::makeThinLens(view, 0.0f, 100.0f), view).ok());
    EXPECT_FALSE(dof::validate(dof::makeThinLens(view, -0.1f, 100.0f), view).ok());
    EXPECT_FALSE(dof::validate(dof::makeThinLens(view, NAN, 100.0f), view).ok());
    EXPECT_FALSE(dof::validate(dof::makeThinLens(view, INFINITY, 100.0f), view).ok());
    EXPECT_FALSE(dof::validate(dof::makeThinLens(view, 1.0f, 0.0f), view).ok());
    EXPECT_FALSE(dof::validate(dof::makeThinLens(view, 1.0f, -5.0f), view).ok());
    EXPECT_FALSE(dof::validate(dof::makeThinLens(view, 1.0f, NAN), view).ok());
    const raster::Status behind = dof::validate(dof::makeThinLens(view, 1.0f, 401.0f), view);
    EXPECT_FALSE(behind.ok());
    EXPECT_NE(behind.message().find("far plane"), std::string::npos);
    view.zfar = 0.0f; // infinite far plane: any positive focus distance
    EXPECT_TRUE(dof::validate(dof::makeThinLens(view, 1.0f, 1e6f), view).ok());
}

TEST(Lens, FocusDistanceAtPixel) {
    const raster::View view = pixelView(64, 64, 100.0f);
    raster::Scene scene;
    const int32_t white = addMaterial(scene, flatMaterial({1.0f, 1.0f, 1.0f, 1.0f}));
    addQuad(scene, -10.0f, -10.0f, 10.0f, 10.0f, 150.0f, white); // pixels ~[25,39)
    const raster::Frame f = render(scene, view);
    raster::Result<float> d = dof::focusDistanceAtPixel(f, view, 32, 32);
    ASSERT_TRUE(d.ok());
    EXPECT_NEAR(*d, 150.0f, 1e-2f);
    EXPECT_FALSE(dof::focusDistanceAtPixel(f, view, 2, 2).ok());   // background
    EXPECT_FALSE(dof::focusDistanceAtPixel(f, view, 64, 10).ok()); // outside
    const dof::CocRange range =
        dof::visibleCocRange(dof::makeThinLens(view, 3.0f, 100.0f), f, view);
    EXPECT_TRUE(range.covered);
    EXPECT_NEAR(range.max_px, 1.0f, 1e-3f); // 3 * 100 * (1/100 - 1/150)
    EXPECT_NEAR(range.min_px, 1.0f, 1e-3f);
}

// visibleCocRange and visibleDepthRange take their ends from the extreme stored depths: the same
// bits as folding every visible pixel's value (opaque and BLEND; float and, on dense, unorm16
// depth), for lenses focused in front of, inside and behind the scene.
TEST(Lens, VisibleRangesMatchEveryPixelsExtremes) {
    for (const char* name : {"demo", "glass", "dense"}) {
        raster::Result<raster::Scene> scene = scenes::makeBuiltinScene(name);
        ASSERT_TRUE(scene.ok()) << name;
        const raster::View view = raster::viewFromCamera(scene->cameras[0], 96, 64);
        raster::RenderOptions options;
        options.depth_format = std::string_view(name) == "dense" ? raster::DepthFormat::Unorm16
                                                                 : raster::DepthFormat::Float32;
        const raster::Frame f = render(*scene, view, options);
        if (std::string_view(name) == "glass") { // BLEND surfaces are visible depths too
            ASSERT_GT(f.transparent_depth.bytes(), 0u);
        }
        float d_lo = INFINITY, d_hi = 0.0f;
        raster::forEachVisibleDepth(f, [&](float stored) {
            const float d = raster::distanceFromDepth(view, stored);
            d_lo = std::min(d_lo, d);
            d_hi = std::max(d_hi, d);
        });
        const dof::DepthRange depths = dof::visibleDepthRange(f, view);
        ASSERT_TRUE(depths.covered) << name;
        EXPECT_EQ(depths.near_d, d_lo) << name;
        EXPECT_EQ(depths.far_d, d_hi) << name;
        for (float focus : {0.5f * d_lo, 0.5f * (d_lo + d_hi), 2.0f * d_hi}) {
            const dof::ThinLens lens = dof::makeThinLens(view, 0.05f, focus);
            float c_lo = INFINITY, c_hi = -INFINITY;
            raster::forEachVisibleDepth(f, [&](float stored) {
                const float c = dof::cocRadiusPx(lens, raster::distanceFromDepth(view, stored));
                c_lo = std::fmin(c_lo, c);
                c_hi = std::fmax(c_hi, c);
            });
            const dof::CocRange coc = dof::visibleCocRange(lens, f, view);
            ASSERT_TRUE(coc.covered) << name;
            EXPECT_EQ(coc.min_px, c_lo) << name << " focus " << focus;
            EXPECT_EQ(coc.max_px, c_hi) << name << " focus " << focus;
            EXPECT_LT(c_lo, c_hi) << name; // a range of depths, not one
        }
    }
}

} // namespace
} // namespace focal::test
