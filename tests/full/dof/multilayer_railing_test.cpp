// Selgrad et al. 2015 Fig. 1 / Fig. 11 against the accumulation reference: the blurred near
// railing of builtin:railing must reveal the in-focus text behind it. Error is measured where
// the pinhole image shows the bars (what a single-layer method cannot know) and over the whole
// image, for the multi-layer method and, as the baseline that must lose, the pinhole image.
#include "unit/dof/dof_test_util.h"

#include <dof/metrics.h>
#include <dof/multilayer.h>
#include <raster/fragment_lists.h>
#include <raster/renderer.h>
#include <scenes/builtin.h>

#include <gtest/gtest.h>

namespace focal::test {
namespace {

constexpr uint32_t kW = 320, kH = 180;

TEST(MultilayerRailing, BlurredBarsRevealTheTextBehindThem) {
    raster::Result<raster::Scene> scene = scenes::makeBuiltinScene("railing");
    ASSERT_TRUE(scene.ok());
    const raster::View view = raster::viewFromCamera(scene->cameras[0], kW, kH);
    const dof::ThinLens lens =
        dof::makeThinLens(view, scene->lens->aperture_radius, scene->lens->focus_distance);

    raster::TaskPool pool(2);
    raster::Renderer renderer(pool);
    const raster::Frame pinhole = render(*scene, view, {}, 2);
    const raster::Frame accum = renderAccum(*scene, view, lens, makeSamples(256), {}, 2);

    dof::Multilayer ml;
    dof::MultilayerImage image;
    const dof::CollectFn collect = [&](const raster::FragmentListDesc& desc,
                                       raster::FragmentLists& lists) {
        return renderer.renderFragmentLists(*scene, view, {}, desc, lists);
    };
    const raster::Status s = ml.render(view, lens, scene->background, {}, collect, pool, image);
    ASSERT_TRUE(s.ok()) << s.message();

    // The bars: pinhole pixels closer than 1 m (the railing stands 0.7 m from the eye).
    std::vector<uint8_t> bars(size_t(kW) * kH, 0);
    uint64_t bar_pixels = 0;
    for (size_t i = 0; i < bars.size(); ++i)
        if (raster::distanceFromDepth(view, pinhole.depth.load(i)) < 1.0f)
            bars[i] = 1, ++bar_pixels;
    ASSERT_GT(bar_pixels, kW * kH / 20);

    const dof::ImageRef ref{accum.color.data(), kW, kH, 4};
    const dof::ImageRef ours{image.rgba.data(), kW, kH, 4};
    const dof::ImageRef pin{pinhole.color.data(), kW, kH, 4};
    const raster::Result<dof::ErrorMetrics> ml_bars = dof::compareImages(ref, ours, &bars);
    const raster::Result<dof::ErrorMetrics> pin_bars = dof::compareImages(ref, pin, &bars);
    const raster::Result<dof::ErrorMetrics> ml_all = dof::compareImages(ref, ours);
    ASSERT_TRUE(ml_bars.ok() && pin_bars.ok() && ml_all.ok());
    // The pinhole shows dark bars where accum shows the wall and the text through the blur.
    EXPECT_LT(pin_bars->psnr_srgb_db, 20.0);
    EXPECT_GT(ml_bars->psnr_srgb_db, 32.0);
    EXPECT_GT(ml_bars->psnr_srgb_db, pin_bars->psnr_srgb_db + 12.0);
    EXPECT_GT(ml_all->psnr_srgb_db, 33.0);
    EXPECT_GT(ml_all->ssim, 0.97);
    RecordProperty("psnr_bars_db", std::to_string(ml_bars->psnr_srgb_db));
    RecordProperty("psnr_all_db", std::to_string(ml_all->psnr_srgb_db));
    RecordProperty("ssim_all", std::to_string(ml_all->ssim));
}

} // namespace
} // namespace focal::test
