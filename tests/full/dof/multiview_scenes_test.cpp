// Multiview synthesis (Lee et al. 2009) against the accum reference on built-in scenes at a
// reduced size: the background behind the railing's thin near bars shows through (§4.1 hidden
// layers, Fig. 8 first row), the crossing branches of Fig. 8 (second row) come out as accum
// renders them, alpha-blended panes stay visible (transparent planes), and per-ray shading (§5)
// beats view-independent shading on shiny spheres; cell-centred cones keep the bokeh's rims; the
// defaults that differ from the paper are the closer ones.
#include "../../unit/dof/dof_test_util.h"
#include "method_runs.h"
#include "support/builtin_case.h"

#include <dof/metrics.h>
#include <dof/multiview.h>
#include <scenes/builtin.h>

#include <gtest/gtest.h>

#include <cmath>

namespace focal::test {
namespace {

// The multiview image and, when asked, the pinhole image to compare it with (rendered apart:
// multiview's own pinhole frame holds its depth only).
std::vector<float> multiview(const BuiltinCase& c, const dof::LensSampleSet& samples,
                             const dof::MultiviewSettings& s, raster::Frame* pinhole = nullptr) {
    std::vector<float> out = runMultiview(c, samples, s);
    if (pinhole)
        *pinhole = render(c.scene, c.view);
    return out;
}

dof::ErrorMetrics compare(const std::vector<float>& a, const raster::Frame& ref,
                          const std::vector<uint8_t>* mask = nullptr) {
    raster::Result<dof::ErrorMetrics> e = dof::compareImages(
        {a.data(), ref.width, ref.height, 4}, {ref.color.data(), ref.width, ref.height, 4}, mask);
    FOCAL_CHECK(e.ok());
    return *e;
}

TEST(MultiviewScenes, RailingBackgroundShowsThroughNearBars) {
    const BuiltinCase c = loadBuiltinCase("railing", 320, 240);
    const raster::Frame ref = renderAccum(c.scene, c.view, c.lens, makeSamples(256), {}, 2);
    raster::Frame pinhole;
    const std::vector<float> mv = multiview(c, makeSamples(64), {}, &pinhole);
    // The region the near bars cover in the pinhole view (well in front of the focus).
    std::vector<uint8_t> bars(size_t(320) * 240, 0);
    size_t count = 0;
    for (size_t i = 0; i < bars.size(); ++i) {
        const float d = pinhole.depth.load(i);
        if (d < raster::kFarDepth &&
            raster::distanceFromDepth(c.view, d) < 0.6f * c.lens.focus_distance)
            bars[i] = 1, ++count;
    }
    ASSERT_GT(count, 500u);
    // Measured with the session-4 defaults (cones of missed rays, 0.5 px texels): 44.2 dB in the
    // bars' region (pinhole 13.4 dB), SSIM 0.9990 over the frame.
    const dof::ErrorMetrics in_bars = compare(mv, ref, &bars);
    const dof::ErrorMetrics pin_bars = compare(pinhole.color, ref, &bars);
    EXPECT_GT(in_bars.psnr_linear_db, 40.0);
    EXPECT_GT(in_bars.psnr_linear_db, pin_bars.psnr_linear_db + 8.0);
    EXPECT_GT(compare(mv, ref).ssim, 0.995);
}

TEST(MultiviewScenes, BranchesMatchTheReference) {
    const BuiltinCase c = loadBuiltinCase("branches", 320, 240);
    const raster::Frame ref = renderAccum(c.scene, c.view, c.lens, makeSamples(256), {}, 2);
    raster::Frame pinhole;
    // Eq. 4 spaces layers by delta pixels of CoC, so at 320x240 (f_px 0.4x that of 800x600) a
    // delta = 2 px layer is 2.5x deeper than at the benchmark's 800x600; delta = 1 px here slices
    // depth like delta = 2.5 px there. Measured against accum 256 at this size with the
    // defaults of session 3 (shared samples, clamped off-screen rays): SSIM 0.973 / 32.3 dB with
    // delta = 2, 0.990 / 38.5 dB with delta = 1 (the session-2 defaults gave 0.980 / 34.3 dB;
    // docs/benchmarks.md, "Multiview synthesis"); with session 4's cones of missed rays and
    // 0.5 px texels, 0.992 / 40.9 dB with delta = 1.
    dof::MultiviewSettings s;
    s.layer_spacing_px = 1.0f;
    const std::vector<float> mv = multiview(c, makeSamples(64), s, &pinhole);
    const dof::ErrorMetrics e = compare(mv, ref);
    const dof::ErrorMetrics p = compare(pinhole.color, ref);
    EXPECT_GT(e.psnr_linear_db, 39.0);
    EXPECT_GT(e.ssim, 0.99);
    EXPECT_GT(e.ssim, p.ssim);
}

TEST(MultiviewScenes, GlassPanesShowThroughTransparentPlanes) {
    // BLEND panes at 1-3 m in front of the focused objects: the layers' transparent planes keep
    // them (measured 36.8 dB / SSIM 0.989 against accum 256 with the session-4 defaults; 36.4 /
    // 0.988 with session 3's, 32.1 / 0.977 with session 2's; 18.5 dB when the panes were lost).
    const BuiltinCase c = loadBuiltinCase("glass", 320, 240);
    const raster::Frame ref = renderAccum(c.scene, c.view, c.lens, makeSamples(256), {}, 2);
    raster::Frame pinhole;
    const std::vector<float> mv = multiview(c, makeSamples(64), {}, &pinhole);
    const dof::ErrorMetrics e = compare(mv, ref);
    EXPECT_GT(e.psnr_linear_db, 33.0);
    EXPECT_GT(e.ssim, 0.98);
    EXPECT_GT(e.psnr_linear_db, compare(pinhole.color, ref).psnr_linear_db + 4.0);
}

TEST(MultiviewScenes, CellCentredConesKeepTheBokehRims) {
    // builtin:bokeh at 400x300 with the aperture doubled, so that its discs are as many pixels
    // wide as at 800x600 (at the scene's own aperture the cones are under a pixel wide here and
    // not used): cones centred on their samples' cells keep the highlights' rims where cones on
    // the rays (the paper) soften and widen them. Measured against accum 256: 24.54 dB / 0.9327
    // with cell centres, 23.85 / 0.9220 on the rays (at 800x600 against accum 1024: 33.28 /
    // 0.9884 against 31.21 / 0.9828).
    BuiltinCase c = loadBuiltinCase("bokeh", 400, 300);
    c.lens = dof::makeThinLens(c.view, 2.0f * c.lens.aperture_radius, c.lens.focus_distance);
    const raster::Frame ref = renderAccum(c.scene, c.view, c.lens, makeSamples(256), {}, 2);
    dof::MultiviewSettings on_ray;
    on_ray.cone_centre = dof::ConeCentre::Sample;
    const dof::ErrorMetrics cell = compare(multiview(c, makeSamples(64), {}), ref);
    const dof::ErrorMetrics ray = compare(multiview(c, makeSamples(64), on_ray), ref);
    EXPECT_GT(cell.psnr_linear_db, ray.psnr_linear_db + 0.4);
    EXPECT_GT(cell.ssim, ray.ssim + 0.005);
}

TEST(MultiviewScenes, DefaultsAreCloserToTheReferenceThanThePapersChoices) {
    // Six defaults differ from the paper, because against accum they are better in both
    // metrics on (nearly) all eight scenes at 800x600 (docs/benchmarks.md): the shared sample
    // set instead of §4.5's noise jitter (the cones already smooth the pattern's copies), layers
    // over a guard band around the image (§4.3's "viewport that encompasses all lens rays")
    // instead of the image alone, rays that still leave it clamped to its border instead of
    // discarded (§4.3; discarding biases the periphery), cones for the rays that miss a layer as
    // well as for those that hit it (§4.4), 0.5 px texels instead of the height field (§4.3),
    // and cones centred on their samples' cells instead of the rays (§4.4; jittered samples, as
    // in the noise variant, keep theirs on the rays). Measured here (linear PSNR dB / SSIM):
    // defaults 37.23 / 0.9750; noise 36.48 / 0.9621; discard without the band 34.22 / 0.9718;
    // clamp without the band (the defaults before session 28) 36.04 / 0.9746; cones at hits only
    // 36.35 / 0.9635; height field 35.28 / 0.9742; cones on the rays 37.20 / 0.9741.
    const BuiltinCase c = loadBuiltinCase("foliage", 320, 240);
    const raster::Frame ref = renderAccum(c.scene, c.view, c.lens, makeSamples(256), {}, 2);
    const dof::MultiviewSettings defaults;
    ASSERT_EQ(defaults.jitter, dof::JitterMode::None);
    ASSERT_EQ(defaults.offscreen, dof::OffscreenPolicy::Clamp);
    ASSERT_TRUE(defaults.cone_misses);
    ASSERT_EQ(defaults.thickness_px, 0.5f);
    ASSERT_EQ(defaults.cone_centre, dof::ConeCentre::Cell);
    dof::MultiviewSettings noise;
    noise.jitter = dof::JitterMode::Noise;
    dof::MultiviewSettings discard; // the paper's layers cover the image alone
    discard.offscreen = dof::OffscreenPolicy::Discard;
    discard.guard_band_px = 0.0f;
    dof::MultiviewSettings image_only;
    image_only.guard_band_px = 0.0f;
    dof::MultiviewSettings hits_only;
    hits_only.cone_misses = false;
    dof::MultiviewSettings height_field;
    height_field.thickness_px = INFINITY;
    dof::MultiviewSettings on_ray;
    on_ray.cone_centre = dof::ConeCentre::Sample;
    const dof::ErrorMetrics d = compare(multiview(c, makeSamples(32), defaults), ref);
    for (const dof::MultiviewSettings& paper :
         {noise, discard, image_only, hits_only, height_field, on_ray}) {
        const dof::ErrorMetrics p = compare(multiview(c, makeSamples(32), paper), ref);
        EXPECT_GT(d.psnr_linear_db, p.psnr_linear_db);
        EXPECT_GT(d.ssim, p.ssim);
    }
}

TEST(MultiviewScenes, ViewDependentShadingBeatsViewIndependent) {
    const BuiltinCase c = loadBuiltinCase("reflective", 320, 240);
    raster::RenderOptions lit;
    const raster::Frame ref = renderAccum(c.scene, c.view, c.lens, makeSamples(256), {}, 2);
    dof::MultiviewSettings vd;
    vd.view_dependent = true;
    const dof::ErrorMetrics dep = compare(multiview(c, makeSamples(64), vd), ref);
    const dof::ErrorMetrics indep = compare(multiview(c, makeSamples(64), {}), ref);
    EXPECT_GT(dep.psnr_linear_db, indep.psnr_linear_db);
    EXPECT_GE(dep.ssim, indep.ssim);
}

} // namespace
} // namespace focal::test
