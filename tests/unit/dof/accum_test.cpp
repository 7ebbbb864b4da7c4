// Analytic tests of the accumulation reference (dof/accum.h) against the thin lens (dof/lens.h).
#include "dof_test_util.h"

#include <dof/accum.h>

#include <gtest/gtest.h>

#include <cmath>

namespace focal::test {
namespace {

constexpr uint32_t kW = 64, kH = 64;
constexpr float kFocus = 100.0f; // pixelView: f_px = d_f = 100, one world unit = 1 px there

raster::View testView() {
    return pixelView(kW, kH, kFocus);
}

// A lens whose CoC is +6 px at d = 200 and -6 px at d = 200/3.
dof::ThinLens testLens(const raster::View& v) {
    return dof::makeThinLens(v, 12.0f, kFocus);
}
constexpr float kBehind = 200.0f;
constexpr float kFront = 200.0f / 3.0f;

// A checkerboard wall of 4x4-unit squares at depth d; edges sit on pixel boundaries at d = d_f.
raster::Scene checkerWall(float d) {
    raster::Scene scene;
    const int32_t white = addMaterial(scene, flatMaterial({1.0f, 1.0f, 1.0f, 1.0f}));
    const int32_t dark = addMaterial(scene, flatMaterial({0.1f, 0.3f, 0.05f, 1.0f}));
    const float s = d / kFocus; // world units per pixel at depth d
    for (int j = -12; j < 12; ++j)
        for (int i = -12; i < 12; ++i)
            addQuad(scene, float(4 * i) * s, float(4 * j) * s, float(4 * i + 4) * s,
                    float(4 * j + 4) * s, d, ((i + j) & 1) ? white : dark);
    return scene;
}

// A white square whose pinhole image is the pixel (kW/2, kH/2), at depth d, on black.
raster::Scene emitter(float d) {
    raster::Scene scene;
    const int32_t white = addMaterial(scene, flatMaterial({1.0f, 1.0f, 1.0f, 1.0f}));
    const float s = d / kFocus;
    addQuad(scene, 0.0f, -1.0f * s, 1.0f * s, 0.0f, d, white);
    return scene;
}

TEST(Accum, WallAtFocusDistanceMatchesPinhole) {
    const raster::View view = testView();
    raster::Scene scene = checkerWall(kFocus);
    // Every visible depth in focus: accum knows the lens cannot change the image.
    dof::AccumStats stats;
    const raster::Frame skipped =
        renderAccum(scene, view, testLens(view), makeSamples(64), {}, 0, {}, &stats);
    EXPECT_TRUE(stats.skipped);
    EXPECT_EQ(hashFrame(render(scene, view)), hashFrame(skipped));

    // A small quad in front, in the top-left corner, forces the 64 sheared views; away from it
    // (farther than its 6 px CoC) the in-focus wall must come out as in the pinhole image.
    const int32_t red = addMaterial(scene, flatMaterial({1.0f, 0.0f, 0.0f, 1.0f}));
    const float s = kFront / kFocus;
    addQuad(scene, -32.0f * s, 24.0f * s, -24.0f * s, 32.0f * s, kFront, red);
    const raster::Frame pinhole = render(scene, view);
    const raster::Frame accum =
        renderAccum(scene, view, testLens(view), makeSamples(64), {}, 0, {}, &stats);
    EXPECT_FALSE(stats.skipped);
    EXPECT_EQ(stats.views, 64u);
    float max_diff = 0.0f;
    uint32_t compared = 0;
    for (uint32_t y = 0; y < kH; ++y)
        for (uint32_t x = 0; x < kW; ++x) {
            if (x < 8 + 8 && y < 8 + 8)
                continue; // the quad covers pixels [0,8)^2; its blur reaches 6 px further
            ++compared;
            for (int c = 0; c < 4; ++c)
                max_diff =
                    std::max(max_diff, std::fabs(pixel(pinhole, x, y)[c] - pixel(accum, x, y)[c]));
        }
    EXPECT_GT(compared, 3800u);
    EXPECT_LT(max_diff, 1e-6f);
}

TEST(Accum, WallOffFocusIsBlurred) {
    // The same wall behind the focal plane must differ from its pinhole image (the test above
    // can fail).
    const raster::View view = testView();
    const raster::Scene scene = checkerWall(kBehind);
    const raster::Frame pinhole = render(scene, view);
    const raster::Frame accum = renderAccum(scene, view, testLens(view), makeSamples(64));
    float max_diff = 0.0f;
    for (size_t i = 0; i < pinhole.color.size(); ++i)
        max_diff = std::max(max_diff, std::fabs(pinhole.color[i] - accum.color[i]));
    EXPECT_GT(max_diff, 0.2f);
}

TEST(Accum, OneSampleEqualsPinhole) {
    const raster::View view = testView();
    raster::Scene scene = checkerWall(kBehind);
    const raster::Scene front = emitter(kFront);
    scene.materials.push_back(front.materials[0]);
    addQuad(scene, -10.0f, -10.0f, 5.0f, 5.0f, kFront, int32_t(scene.materials.size() - 1));
    for (dof::LensPattern p :
         {dof::LensPattern::Halton, dof::LensPattern::Hammersley, dof::LensPattern::Poisson}) {
        const raster::Frame pinhole = render(scene, view);
        const raster::Frame accum = renderAccum(scene, view, testLens(view), makeSamples(1, {}, p));
        EXPECT_EQ(hashFrame(pinhole), hashFrame(accum)) << "pattern " << int(p);
    }
}

TEST(Accum, SkipsWhenTheLensCannotChangeTheImage) {
    const raster::View view = testView();
    const raster::Scene scene = checkerWall(kBehind);
    dof::AccumStats stats;
    // E = 0.
    renderAccum(scene, view, dof::makeThinLens(view, 0.0f, kFocus), makeSamples(16), {}, 0, {},
                &stats);
    EXPECT_TRUE(stats.skipped);
    EXPECT_EQ(stats.renders, 1u);
    // |C| = E f (1/100 - 1/200) = 0.4 px < 0.5 for E = 0.8.
    renderAccum(scene, view, dof::makeThinLens(view, 0.8f, kFocus), makeSamples(16), {}, 0, {},
                &stats);
    EXPECT_TRUE(stats.skipped);
    EXPECT_NEAR(stats.coc.max_abs_px, 0.4f, 1e-4f);
    // 0.6 px: render the views.
    renderAccum(scene, view, dof::makeThinLens(view, 1.2f, kFocus), makeSamples(16), {}, 0, {},
                &stats);
    EXPECT_FALSE(stats.skipped);
    EXPECT_EQ(stats.renders, 17u);
    // Pixel jitter asks for anti-aliasing: never skipped.
    dof::AccumSettings jitter;
    jitter.pixel_jitter = true;
    renderAccum(scene, view, dof::makeThinLens(view, 0.0f, kFocus), makeSamples(16), jitter, 0, {},
                &stats);
    EXPECT_FALSE(stats.skipped);
    // A BLEND pane writes no depth but is visible: out of focus in front of an in-focus wall,
    // it must still be blurred.
    raster::Scene with_pane = checkerWall(kFocus);
    const int32_t pane =
        addMaterial(with_pane, flatMaterial({1.0f, 0.0f, 0.0f, 0.5f}, raster::AlphaMode::Blend));
    addQuad(with_pane, -10.0f, -10.0f, 10.0f, 10.0f, kFront, pane);
    renderAccum(with_pane, view, testLens(view), makeSamples(16), {}, 0, {}, &stats);
    EXPECT_FALSE(stats.skipped);
    EXPECT_GT(stats.coc.max_abs_px, 1.0f);
}

// Radius of a uniform disk from its second moment: E[r^2] = R^2/2, plus the 1/6 px^2 that
// rounding each view's hit to a pixel centre adds.
double diskRadius(const Moments& m) {
    return std::sqrt(std::max(0.0, 2.0 * (m.mean_r2 - 1.0 / 6.0)));
}

TEST(Accum, EmitterBlurRadiusMatchesCoc) {
    const raster::View view = testView();
    const dof::ThinLens lens = testLens(view);
    const dof::LensSampleSet samples = makeSamples(1024);
    for (float d : {kFront, kBehind, 150.0f, 80.0f}) {
        const float coc = dof::cocRadiusPx(lens, d);
        const raster::Frame f = renderAccum(emitter(d), view, lens, samples);
        const Moments m = momentsOf(f, {kW / 2 + 0.5, kH / 2 + 0.5});
        EXPECT_NEAR(m.weight, 1.0, 1e-3) << "d = " << d; // the emitter's energy is kept
        EXPECT_NEAR(diskRadius(m), std::fabs(coc), 0.5) << "d = " << d;
        EXPECT_LE(m.max_r, double(std::fabs(coc)) + 0.75) << "d = " << d;
        EXPECT_NEAR(m.centroid.x, kW / 2 + 0.5, 0.1);
        EXPECT_NEAR(m.centroid.y, kH / 2 + 0.5, 0.1);
    }
}

// Half-width of the blur of a vertical step edge from the line-spread function's variance:
// a uniform disk of radius R has an LSF (chord length) with variance R^2 / 4.
double edgeBlurRadius(const raster::Frame& f, uint32_t row) {
    double sum = 0.0, mean = 0.0, var = 0.0;
    std::vector<double> lsf(f.width, 0.0);
    for (uint32_t x = 1; x < f.width; ++x) {
        lsf[x] = double(f.color[(size_t(row) * f.width + x) * 4]) -
                 double(f.color[(size_t(row) * f.width + x - 1) * 4]);
        sum += lsf[x];
        mean += lsf[x] * double(x);
    }
    mean /= sum;
    for (uint32_t x = 1; x < f.width; ++x)
        var += lsf[x] * (double(x) - mean) * (double(x) - mean);
    var /= sum;
    // Point sampling quantises the ESF to pixel centres: +1/12 px^2.
    return 2.0 * std::sqrt(std::max(0.0, var - 1.0 / 12.0));
}

TEST(Accum, StepEdgeBlurWidthMatchesCoc) {
    const raster::View view = testView();
    const dof::ThinLens lens = testLens(view);
    const dof::LensSampleSet samples = makeSamples(1024);
    for (float d : {kFront, kBehind, 150.0f}) {
        raster::Scene scene;
        const int32_t white = addMaterial(scene, flatMaterial({1.0f, 1.0f, 1.0f, 1.0f}));
        const float s = d / kFocus;
        addQuad(scene, 0.0f, -200.0f * s, 200.0f * s, 200.0f * s, d, white); // x >= 0 white
        const raster::Frame f = renderAccum(scene, view, lens, samples);
        const float coc = std::fabs(dof::cocRadiusPx(lens, d));
        for (uint32_t row : {20u, 32u, 44u})
            EXPECT_NEAR(edgeBlurRadius(f, row), coc, 0.5) << "d = " << d << " row " << row;
        // Fully dark / fully lit beyond the CoC, partial inside it.
        const uint32_t edge = kW / 2;
        auto at = [&](int dx) { return f.color[(size_t(32) * kW + size_t(int(edge) + dx)) * 4]; };
        EXPECT_EQ(at(-int(std::ceil(coc)) - 1), 0.0f);
        EXPECT_EQ(at(int(std::ceil(coc))), 1.0f);
        EXPECT_GT(at(-1), 0.2f);
        EXPECT_LT(at(0), 0.8f);
    }
}

// Aperture: the top-right quadrant of the disk (lens +x right, +y up).
dof::ApertureShape quadrantAperture() {
    dof::ApertureShape shape;
    shape.kind = dof::ApertureKind::Image;
    shape.mask.width = shape.mask.height = 64;
    shape.mask.transmission.resize(64 * 64);
    for (uint32_t y = 0; y < 64; ++y)
        for (uint32_t x = 0; x < 64; ++x) {
            const float u = (float(x) + 0.5f) / 32.0f - 1.0f, v = 1.0f - (float(y) + 0.5f) / 32.0f;
            shape.mask.transmission[y * 64 + x] = (u > 0 && v > 0 && u * u + v * v < 1) ? 1.f : 0.f;
        }
    return shape;
}

TEST(Accum, AsymmetricApertureFlipsInFrontOfTheFocalPlane) {
    const raster::View view = testView();
    const dof::ThinLens lens = testLens(view);
    const dof::LensSampleSet samples = makeSamples(1024, quadrantAperture());
    // Mean lens position of a quarter disk: (4/(3 pi), 4/(3 pi)).
    const double mv = 4.0 / (3.0 * 3.14159265358979);
    const glm::dvec2 q(kW / 2 + 0.5, kH / 2 + 0.5);
    for (float d : {kBehind, kFront}) {
        const double coc = dof::cocRadiusPx(lens, d);
        const Moments m = momentsOf(renderAccum(emitter(d), view, lens, samples), q);
        // The emitter shows at p = q + C (v.x, -v.y) (lens.h): behind the focal plane (C > 0)
        // the bokeh is the quadrant upright (right and up); in front it is rotated 180 degrees.
        EXPECT_NEAR(m.centroid.x - q.x, coc * mv, 0.4) << "d = " << d;
        EXPECT_NEAR(m.centroid.y - q.y, -coc * mv, 0.4) << "d = " << d;
        if (d > kFocus) {
            EXPECT_GT(m.centroid.x, q.x + 1.0);
            EXPECT_LT(m.centroid.y, q.y - 1.0);
        } else {
            EXPECT_LT(m.centroid.x, q.x - 1.0);
            EXPECT_GT(m.centroid.y, q.y + 1.0);
        }
    }
}

TEST(Accum, LensRayImageOffsetAgreesWithRenderedShift) {
    // One lens sample: the whole image shifts by lensRayImageOffset(C, v).
    const raster::View view = testView();
    const dof::ThinLens lens = testLens(view);
    const glm::vec2 v(0.5f, 0.25f);
    const raster::View shifted = dof::lensView(view, lens, v, {0.0f, 0.0f});
    for (float d : {kBehind, kFront}) {
        const raster::Frame f = render(emitter(d), shifted);
        const Moments m = momentsOf(f, {0.0, 0.0});
        const glm::vec2 off = dof::lensRayImageOffset(dof::cocRadiusPx(lens, d), v);
        // The pixel p that sees the emitter satisfies p + off = q, so p = q - off.
        EXPECT_NEAR(m.centroid.x, kW / 2 + 0.5 - double(off.x), 0.5 + 1e-3) << "d = " << d;
        EXPECT_NEAR(m.centroid.y, kH / 2 + 0.5 - double(off.y), 0.5 + 1e-3) << "d = " << d;
    }
}

TEST(Accum, PixelJitterAntiAliasesAnInFocusEdge) {
    // A wall edge at the focus distance halfway across a pixel column: point sampling gives
    // 0 or 1, the jittered box filter gives the covered fraction.
    const raster::View view = testView();
    raster::Scene scene;
    const int32_t white = addMaterial(scene, flatMaterial({1.0f, 1.0f, 1.0f, 1.0f}));
    addQuad(scene, 0.25f, -40.0f, 40.0f, 40.0f, kFocus, white); // covers 3/4 of column kW/2
    dof::AccumSettings jitter;
    jitter.pixel_jitter = true;
    const raster::Frame f =
        renderAccum(scene, view, dof::makeThinLens(view, 0.0f, kFocus), makeSamples(256), jitter);
    EXPECT_NEAR(pixel(f, kW / 2, 32).r, 0.75f, 0.05f);
    EXPECT_EQ(pixel(f, kW / 2 + 2, 32).r, 1.0f);
    EXPECT_EQ(pixel(f, kW / 2 - 2, 32).r, 0.0f);
}

TEST(Accum, BlurPreservesTheMeanOfAConstantImage) {
    const raster::View view = testView();
    raster::Scene scene;
    const int32_t grey = addMaterial(scene, flatMaterial({0.3f, 0.5f, 0.7f, 1.0f}));
    addQuad(scene, -400.0f, -400.0f, 400.0f, 400.0f, kBehind, grey);
    const raster::Frame f = renderAccum(scene, view, testLens(view), makeSamples(64));
    for (uint32_t y = 0; y < kH; y += 7)
        for (uint32_t x = 0; x < kW; x += 7)
            EXPECT_NEAR(pixel(f, x, y).g, 0.5f, 1e-6f);
}

TEST(Accum, DepthIsThePinholeDepth) {
    const raster::View view = testView();
    const raster::Scene scene = checkerWall(kBehind);
    const raster::Frame pinhole = render(scene, view);
    const raster::Frame accum = renderAccum(scene, view, testLens(view), makeSamples(8));
    EXPECT_EQ(pinhole.depth.float32, accum.depth.float32);
}

TEST(Accum, RejectsAnInvalidLens) {
    const raster::View view = testView();
    raster::TaskPool pool(0);
    raster::Renderer renderer(pool);
    raster::Frame frame;
    const raster::Scene scene = checkerWall(kFocus);
    const dof::RenderFn fn = [&](const raster::View& v, raster::Frame& f) {
        return renderer.render(scene, v, {}, f);
    };
    const dof::LensSampleSet samples = makeSamples(4);
    for (dof::ThinLens lens :
         {dof::makeThinLens(view, -1.0f, kFocus), dof::makeThinLens(view, NAN, kFocus),
          dof::makeThinLens(view, 1.0f, 0.0f), dof::makeThinLens(view, 1.0f, 1e6f)}) {
        const auto r = dof::renderAccum(view, lens, samples, {}, fn, frame);
        EXPECT_FALSE(r.ok());
    }
}

} // namespace
} // namespace focal::test
