// Layer spacing of Lee et al. 2009 §4.1 (Eq. 4): uniform in the signed CoC from d_near.
#include "dof_test_util.h"

#include <dof/layer_spacing.h>

#include <gtest/gtest.h>

namespace focal::test {
namespace {

TEST(LayerSpacing, BoundsAreUniformInSignedCoc) {
    const raster::View view = pixelView(64, 48, 100.0f);
    const dof::ThinLens lens = dof::makeThinLens(view, 10.0f, 100.0f);
    const dof::DepthRange range{40.0f, 400.0f, true};
    raster::Result<dof::LayerSpacing> s = dof::layerSpacingFromDelta(lens, range, 2.0f, 64);
    ASSERT_TRUE(s.ok()) << s.status().message();
    // C(40) = -15, C(400) = 7.5: 22.5 px / 2 px -> 12 layers.
    EXPECT_EQ(s->layers, 12u);
    EXPECT_FALSE(s->budget_limited);
    ASSERT_EQ(s->bounds.size(), 13u);
    EXPECT_LE(s->bounds.front(), 40.0f);
    EXPECT_GE(s->bounds.back(), 400.0f);
    for (uint32_t l = 1; l < s->layers; ++l) {
        EXPECT_NEAR(dof::cocRadiusPx(lens, s->bounds[l]) - dof::cocRadiusPx(lens, 40.0f),
                    2.0f * float(l), 1e-3f);
        // Eq. 4 puts a depth just past bound l into layer l.
        EXPECT_EQ(dof::layerIndex(lens, *s, s->bounds[l] * 1.0001f), l);
    }
    EXPECT_EQ(dof::layerIndex(lens, *s, 41.0f), 0u);
    EXPECT_EQ(dof::layerIndex(lens, *s, 399.0f), 11u);
}

TEST(LayerSpacing, BudgetSetsDeltaAndCapsTheCount) {
    const raster::View view = pixelView(64, 48, 100.0f);
    const dof::ThinLens lens = dof::makeThinLens(view, 10.0f, 100.0f);
    const dof::DepthRange range{40.0f, 400.0f, true};
    raster::Result<dof::LayerSpacing> b = dof::layerSpacingFromCount(lens, range, 9);
    ASSERT_TRUE(b.ok());
    EXPECT_EQ(b->layers, 9u);
    EXPECT_NEAR(b->delta_px, 2.5f, 1e-4f);
    raster::Result<dof::LayerSpacing> c = dof::layerSpacingFromDelta(lens, range, 0.1f, 16);
    ASSERT_TRUE(c.ok());
    EXPECT_EQ(c->layers, 16u);
    EXPECT_TRUE(c->budget_limited);
    EXPECT_NEAR(c->delta_px, 22.5f / 16.0f, 1e-4f);
}

TEST(LayerSpacing, PinholeAndFlatScenesGetOneLayer) {
    const raster::View view = pixelView(64, 48, 100.0f);
    raster::Result<dof::LayerSpacing> s = dof::layerSpacingFromDelta(
        dof::makeThinLens(view, 0.0f, 100.0f), {40.0f, 400.0f, true}, 2.0f, 64);
    ASSERT_TRUE(s.ok());
    EXPECT_EQ(s->layers, 1u);
    s = dof::layerSpacingFromDelta(dof::makeThinLens(view, 10.0f, 100.0f), {50.0f, 50.0f, true},
                                   2.0f, 64);
    ASSERT_TRUE(s.ok());
    EXPECT_EQ(s->layers, 1u);
    EXPECT_LT(s->bounds[0], s->bounds[1]);
}

TEST(LayerSpacing, BadParametersNameTheSetting) {
    const raster::View view = pixelView(64, 48, 100.0f);
    const dof::ThinLens lens = dof::makeThinLens(view, 10.0f, 100.0f);
    const dof::DepthRange range{40.0f, 400.0f, true};
    raster::Result<dof::LayerSpacing> s = dof::layerSpacingFromDelta(lens, range, 0.0f, 64);
    ASSERT_FALSE(s.ok());
    EXPECT_NE(s.status().message().find("multiview settings: layer_spacing_px"), std::string::npos);
    s = dof::layerSpacingFromDelta(lens, range, NAN, 64);
    EXPECT_FALSE(s.ok());
    s = dof::layerSpacingFromCount(lens, range, 0);
    ASSERT_FALSE(s.ok());
    EXPECT_NE(s.status().message().find("multiview settings: layers"), std::string::npos);
    s = dof::layerSpacingFromCount(lens, dof::DepthRange{}, 4);
    EXPECT_FALSE(s.ok());
}

TEST(LayerSpacing, VisibleRangeSkipsBackgroundNotClipPlanes) {
    raster::Scene scene;
    const int32_t m = addMaterial(scene, flatMaterial({1.0f, 1.0f, 1.0f, 1.0f}));
    addQuad(scene, -10.0f, -10.0f, 10.0f, 10.0f, 80.0f, m);
    addQuad(scene, 5.0f, 5.0f, 30.0f, 20.0f, 150.0f, m);
    const raster::View view = pixelView(64, 48, 100.0f);
    const raster::Frame f = render(scene, view);
    const dof::DepthRange r = dof::visibleDepthRange(f, view);
    ASSERT_TRUE(r.covered);
    EXPECT_NEAR(r.near_d, 80.0f, 0.05f);
    EXPECT_NEAR(r.far_d, 150.0f, 0.1f);
    raster::Scene empty;
    EXPECT_FALSE(dof::visibleDepthRange(render(empty, view), view).covered);
}

} // namespace
} // namespace focal::test
