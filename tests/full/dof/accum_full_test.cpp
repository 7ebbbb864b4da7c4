// accum on the built-in scenes: determinism across thread counts and tile sizes, and
// convergence of the reference itself (more views, closer to a high-N render).
#include "support/builtin_case.h"
#include "support/test_util.h"

#include <dof/accum.h>
#include <dof/lens.h>
#include <dof/lens_samples.h>
#include <dof/metrics.h>
#include <raster/camera.h>
#include <raster/renderer.h>
#include <raster/task_pool.h>
#include <scenes/builtin.h>

#include <gtest/gtest.h>

namespace focal::test {
namespace {

raster::Frame accum(const BuiltinCase& s, uint32_t n, uint32_t threads, uint32_t tile, bool jitter,
                    dof::LensPattern pattern = dof::LensPattern::Hammersley) {
    raster::TaskPool pool(threads);
    raster::Renderer renderer(pool);
    raster::RenderOptions options;
    options.tile_size = tile;
    raster::Result<dof::LensSampleSet> samples = dof::LensSampleSet::create({}, pattern, n, 0);
    EXPECT_TRUE(samples.ok());
    dof::AccumSettings settings;
    settings.pixel_jitter = jitter;
    raster::Frame frame;
    const dof::RenderFn fn = [&](const raster::View& v, raster::Frame& f) {
        return renderer.render(s.scene, v, options, f);
    };
    EXPECT_TRUE(dof::renderAccum(s.view, s.lens, *samples, settings, fn, frame, &pool).ok());
    return frame;
}

TEST(AccumFull, DemoIsDeterministicAcrossThreadsAndTiles) {
    const BuiltinCase s = loadBuiltinCase("demo", 96, 72);
    const uint64_t reference = hashFrame(accum(s, 12, 0, 64, true));
    for (uint32_t threads : {1u, 2u, 3u, 8u})
        for (uint32_t tile : {8u, 32u, 64u, 256u})
            EXPECT_EQ(hashFrame(accum(s, 12, threads, tile, true)), reference)
                << "threads " << threads << " tile " << tile;
}

double psnr(const raster::Frame& a, const raster::Frame& b) {
    const dof::ImageRef ra{a.color.data(), a.width, a.height, 4};
    const dof::ImageRef rb{b.color.data(), b.width, b.height, 4};
    raster::Result<dof::ErrorMetrics> m = dof::compareImages(ra, rb);
    EXPECT_TRUE(m.ok());
    return m->psnr_linear_db;
}

TEST(AccumFull, ConvergesWithMoreViews) {
    const BuiltinCase s = loadBuiltinCase("demo", 96, 72);
    const raster::Frame high = accum(s, 1024, 2, 64, false);
    const double p16 = psnr(accum(s, 16, 2, 64, false), high);
    const double p64 = psnr(accum(s, 64, 2, 64, false), high);
    const double p256 = psnr(accum(s, 256, 2, 64, false), high);
    EXPECT_LT(p16, p64);
    EXPECT_LT(p64, p256);
    EXPECT_GT(p256, 40.0);
}

} // namespace
} // namespace focal::test
