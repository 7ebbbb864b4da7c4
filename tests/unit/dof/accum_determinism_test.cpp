// Determinism of accum (docs/architecture.md, "The determinism contract"): the same bytes for
// every thread count and tile size, on a small scene with depth variation, pixel jitter and a
// polygon lens.
#include "dof_test_util.h"

#include <gtest/gtest.h>

namespace focal::test {
namespace {

raster::Scene layeredScene() {
    raster::Scene scene;
    const int32_t a = addMaterial(scene, flatMaterial({1.0f, 0.8f, 0.2f, 1.0f}));
    const int32_t b = addMaterial(scene, flatMaterial({0.1f, 0.4f, 0.9f, 1.0f}));
    const int32_t c =
        addMaterial(scene, flatMaterial({0.9f, 0.1f, 0.3f, 0.5f}, raster::AlphaMode::Blend));
    addQuad(scene, -80.0f, -80.0f, 80.0f, 80.0f, 180.0f, b);
    addQuad(scene, -15.0f, -20.0f, 25.0f, 10.0f, 100.0f, a);
    addQuad(scene, -30.0f, 5.0f, 0.0f, 30.0f, 60.0f, c);
    return scene;
}

TEST(AccumDeterminism, SameBytesForEveryThreadCountAndTileSize) {
    const raster::View view = pixelView(72, 56, 100.0f);
    const raster::Scene scene = layeredScene();
    const dof::ThinLens lens = dof::makeThinLens(view, 8.0f, 100.0f);
    dof::ApertureShape hex;
    hex.kind = dof::ApertureKind::Polygon;
    hex.blades = 6;
    hex.rotation_deg = 10.0f;
    const dof::LensSampleSet samples = makeSamples(24, hex, dof::LensPattern::Poisson, 5);
    dof::AccumSettings jitter;
    jitter.pixel_jitter = true;
    raster::RenderOptions options;
    const uint64_t reference = hashFrame(renderAccum(scene, view, lens, samples, jitter, 0));
    for (uint32_t threads : {0u, 1u, 2u, 3u, 8u})
        for (uint32_t tile : {8u, 16u, 64u}) {
            options.tile_size = tile;
            const raster::Frame f =
                renderAccum(scene, view, lens, samples, jitter, threads, options);
            EXPECT_EQ(hashFrame(f), reference) << "threads " << threads << " tile " << tile;
        }
    // And the image is not the pinhole one (the test can fail).
    EXPECT_NE(hashFrame(render(scene, view)), reference);
}

} // namespace
} // namespace focal::test
