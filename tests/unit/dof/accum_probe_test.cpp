// accum's pixel probes (AccumSettings::probes, accum.h): each lens view's sample of a pixel,
// recorded as the frame adds it, whose weighted mean in view order is the frame's pixel.
#include "dof_test_util.h"

#include <dof/accum.h>
#include <scenes/builtin.h>

#include <gtest/gtest.h>

#include <cstring>
#include <string>

namespace focal::test {
namespace {

bool sameBits(const float* a, const float* b) {
    return std::memcmp(a, b, 4 * sizeof(float)) == 0;
}

struct Scenario {
    raster::Scene scene;
    raster::View view;
    dof::ThinLens lens;
};

Scenario demo(uint32_t width, uint32_t height) {
    raster::Result<raster::Scene> s = scenes::makeBuiltinScene("demo");
    FOCAL_CHECK(s.ok());
    Scenario c{std::move(*s), {}, {}};
    c.view = raster::viewFromCamera(c.scene.cameras[0], width, height);
    c.lens = dof::makeThinLens(c.view, c.scene.lens->aperture_radius, c.scene.lens->focus_distance);
    return c;
}

TEST(AccumProbe, ViewsAverageToThePixelInAccumulationOrder) {
    const Scenario c = demo(80, 60);
    const std::vector<glm::uvec2> pixels = {{0, 0},   {79, 0},  {0, 59},  {79, 59},
                                            {40, 30}, {12, 45}, {65, 20}, {40, 30}};
    for (const bool jitter : {false, true})
        for (const uint32_t n : {16u, 32u}) {
            const std::string what = "N=" + std::to_string(n) + (jitter ? " jitter" : "");
            const dof::LensSampleSet samples = makeSamples(n, {}, dof::LensPattern::Halton);
            std::vector<dof::AccumPixelProbe> probes;
            dof::AccumSettings s;
            s.pixel_jitter = jitter;
            s.probe_pixels = pixels;
            s.probes = &probes;
            const raster::Frame frame = renderAccum(c.scene, c.view, c.lens, samples, s);
            // Probing does not change the image.
            s.probes = nullptr;
            EXPECT_EQ(hashFrame(frame), hashFrame(renderAccum(c.scene, c.view, c.lens, samples, s)))
                << what;
            ASSERT_EQ(probes.size(), pixels.size()) << what;
            for (size_t i = 0; i < probes.size(); ++i) {
                const dof::AccumPixelProbe& p = probes[i];
                const std::string at =
                    what + " pixel " + std::to_string(p.x) + "," + std::to_string(p.y);
                EXPECT_EQ(glm::uvec2(p.x, p.y), pixels[i]) << at;
                EXPECT_TRUE(sameBits(p.rgba, frame.color.data() + (size_t(p.y) * 80 + p.x) * 4))
                    << at;
                ASSERT_EQ(p.views.size(), n) << at;
                double sum[4] = {}, sum_w = 0.0;
                for (uint32_t k = 0; k < n; ++k) {
                    const dof::AccumViewSample& v = p.views[k];
                    EXPECT_EQ(v.lens, samples.sample(k).position) << at;
                    EXPECT_EQ(v.weight, samples.sample(k).weight) << at;
                    EXPECT_EQ(v.pixel_shift, jitter ? dof::pixelJitter(k) : glm::vec2(0.0f)) << at;
                    for (int ch = 0; ch < 4; ++ch)
                        sum[ch] += double(v.weight) * double(v.rgba[ch]);
                    sum_w += double(v.weight);
                }
                const double inv = 1.0 / sum_w;
                for (int ch = 0; ch < 4; ++ch)
                    EXPECT_EQ(float(sum[ch] * inv), p.rgba[ch]) << at << " channel " << ch;
            }
        }
}

TEST(AccumProbe, ViewDepthsAreTheViewsOwn) {
    // The lens centre's view is the pinhole: its sample's depth is the pinhole depth.
    const Scenario c = demo(48, 36);
    const dof::LensSampleSet one = makeSamples(1);
    ASSERT_EQ(one.sample(0).position, glm::vec2(0.0f));
    std::vector<dof::AccumPixelProbe> probes;
    const std::vector<glm::uvec2> pixels = {{24, 18}};
    dof::AccumSettings s;
    s.probe_pixels = pixels;
    s.probes = &probes;
    const raster::Frame frame = renderAccum(c.scene, c.view, c.lens, one, s);
    ASSERT_EQ(probes.size(), 1u);
    ASSERT_EQ(probes[0].views.size(), 1u);
    EXPECT_EQ(probes[0].views[0].depth, frame.depth.load(18 * 48 + 24));
}

TEST(AccumProbe, SkippedFrameAndBadPixels) {
    const Scenario c = demo(48, 36);
    const dof::LensSampleSet samples = makeSamples(8);
    raster::TaskPool pool(0);
    raster::Renderer renderer(pool);
    const dof::RenderFn fn = [&](const raster::View& v, raster::Frame& f) {
        return renderer.render(c.scene, v, raster::RenderOptions{}, f);
    };
    std::vector<dof::AccumPixelProbe> probes;
    std::vector<glm::uvec2> pixels = {{5, 7}};
    dof::AccumSettings s;
    s.probe_pixels = pixels;
    s.probes = &probes;
    // A pinhole lens: the pinhole render is the result, and the probe has no views.
    raster::Frame frame;
    const raster::Result<dof::AccumStats> r = dof::renderAccum(
        c.view, dof::makeThinLens(c.view, 0.0f, 1.0f), samples, s, fn, frame, &pool);
    ASSERT_TRUE(r.ok());
    ASSERT_TRUE(r->skipped);
    ASSERT_EQ(probes.size(), 1u);
    EXPECT_TRUE(probes[0].views.empty());
    EXPECT_TRUE(sameBits(probes[0].rgba, frame.color.data() + (7 * 48 + 5) * 4));
    // Outside the image: an error.
    for (const glm::uvec2 bad : {glm::uvec2(48, 0), glm::uvec2(0, 36)}) {
        pixels = {bad};
        EXPECT_FALSE(dof::renderAccum(c.view, c.lens, samples, s, fn, frame, &pool).ok());
    }
}

} // namespace
} // namespace focal::test
