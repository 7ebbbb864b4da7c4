// dof/lens_resolution.h: which lens a frame gets. The f-stop mapping, the precedence of the
// aperture and focus sources, autofocus on the shared pinhole frame, and Status errors (naming
// the request's fields, never command-line options) for invalid and absurd requests.
#include "dof_test_util.h"

#include <dof/frame_renderer.h>
#include <dof/lens_resolution.h>

#include <gtest/gtest.h>

#include <cmath>
#include <optional>

namespace focal::test {
namespace {

// A white quad at depth 150 in front of a 64x64 pixel view (pixels ~[25,39) in x and y); the
// view's far plane is 400.
struct QuadScene {
    raster::View view = pixelView(64, 64, 100.0f);
    raster::Scene scene;
    std::optional<raster::Frame> pinhole;
    int renders = 0; // pinhole frames the resolution asked for

    QuadScene() {
        const int32_t white = addMaterial(scene, flatMaterial({1.0f, 1.0f, 1.0f, 1.0f}));
        addQuad(scene, -7.0f, -7.0f, 7.0f, 7.0f, 150.0f, white);
    }
    dof::PinholeSource source() {
        return [this](const raster::View& v) -> raster::Result<const raster::Frame*> {
            ++renders;
            pinhole = render(scene, v);
            return &*pinhole;
        };
    }
    raster::Result<dof::ResolvedLens> resolve(const dof::LensRequest& request) {
        return dof::resolveLens(request, scene, view, source());
    }
};

// The message of a failed resolution; "" when it succeeded.
std::string failure(const raster::Result<dof::ResolvedLens>& r) {
    return r.ok() ? std::string() : r.status().message();
}

TEST(LensResolution, FStopGivesTheBlenderApertureAndFieldOfView) {
    QuadScene s;
    dof::LensRequest request;
    request.fstop = 2.8f;
    request.focal_length_mm = 50.0f;
    request.focus_distance = 150.0f;
    raster::Result<dof::ResolvedLens> r = s.resolve(request);
    ASSERT_TRUE(r.ok()) << failure(r);
    // E = focal_length_mm * 1e-3 / (2 fstop) = 0.05 / 5.6.
    EXPECT_FLOAT_EQ(r->lens.aperture_radius, 50.0f * 1e-3f / (2.0f * 2.8f));
    EXPECT_EQ(r->aperture_source, dof::ApertureSource::FStop);
    // yfov from the 24 mm default sensor (vertical fit), and f_px from that yfov.
    EXPECT_FLOAT_EQ(r->view.yfov, dof::yfovFromFocalLength(50.0f, dof::kDefaultSensorHeightMm));
    EXPECT_FLOAT_EQ(r->lens.focal_length_px, raster::focalLengthPx(r->view));
    EXPECT_EQ(r->view.yfov, dof::photographicView(s.view, request).yfov);
    request.sensor_height_mm = 36.0f;
    r = s.resolve(request);
    ASSERT_TRUE(r.ok()) << failure(r);
    EXPECT_FLOAT_EQ(r->view.yfov, dof::yfovFromFocalLength(50.0f, 36.0f));
    EXPECT_EQ(s.renders, 0); // a focus distance was given: nothing rendered
}

TEST(LensResolution, ApertureComesFromTheRequestThenTheSceneThenZero) {
    QuadScene s;
    dof::LensRequest request;
    request.focus_distance = 150.0f;
    raster::Result<dof::ResolvedLens> r = s.resolve(request);
    ASSERT_TRUE(r.ok()) << failure(r);
    EXPECT_EQ(r->lens.aperture_radius, 0.0f);
    EXPECT_EQ(r->aperture_source, dof::ApertureSource::Default);
    s.scene.lens = raster::LensHint{3.0f, 120.0f};
    r = s.resolve(request);
    ASSERT_TRUE(r.ok()) << failure(r);
    EXPECT_EQ(r->lens.aperture_radius, 3.0f);
    EXPECT_EQ(r->aperture_source, dof::ApertureSource::Scene);
    EXPECT_EQ(r->lens.focus_distance, 150.0f); // the request's focus wins over the hint's
    EXPECT_EQ(r->focus_source, dof::FocusSource::Request);
    request.aperture_radius = 0.5f;
    r = s.resolve(request);
    ASSERT_TRUE(r.ok()) << failure(r);
    EXPECT_EQ(r->lens.aperture_radius, 0.5f);
    EXPECT_EQ(r->aperture_source, dof::ApertureSource::Request);
}

TEST(LensResolution, AutofocusReadsThePinholeFrameAtTheCentre) {
    QuadScene s;
    raster::Result<dof::ResolvedLens> r = s.resolve({});
    ASSERT_TRUE(r.ok()) << failure(r);
    EXPECT_EQ(r->focus_source, dof::FocusSource::Autofocus);
    EXPECT_NEAR(r->lens.focus_distance, 150.0f, 1e-2f);
    EXPECT_EQ(s.renders, 1);
    // The lens owns the focus distance; the resolved view carries the same value.
    EXPECT_EQ(r->view.focus_distance, r->lens.focus_distance);
    EXPECT_GE(r->ms_focus, 0.0);
}

TEST(LensResolution, FocusPixelReadsThatPixel) {
    QuadScene s;
    dof::LensRequest request;
    request.focus_pixel = glm::uvec2(30, 33);
    s.scene.lens = raster::LensHint{1.0f, 120.0f}; // a focus pixel wins over the hint
    raster::Result<dof::ResolvedLens> r = s.resolve(request);
    ASSERT_TRUE(r.ok()) << failure(r);
    EXPECT_EQ(r->focus_source, dof::FocusSource::FocusPixel);
    EXPECT_NEAR(r->lens.focus_distance, 150.0f, 1e-2f);
    // Background and outside the image are errors naming the field.
    request.focus_pixel = glm::uvec2(2, 2);
    r = s.resolve(request);
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.status().message().find("focus_pixel"), std::string::npos);
    EXPECT_NE(r.status().message().find("background"), std::string::npos);
    request.focus_pixel = glm::uvec2(64, 10);
    r = s.resolve(request);
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.status().message().find("outside"), std::string::npos);
}

TEST(LensResolution, WithoutAPinholeOrAnythingInViewFocusFallsBackToTheBounds) {
    QuadScene s;
    // No pinhole source (a dry run): the distance to the centre of the bounds.
    raster::Result<dof::ResolvedLens> r = dof::resolveLens({}, s.scene, s.view, {});
    ASSERT_TRUE(r.ok()) << failure(r);
    EXPECT_EQ(r->focus_source, dof::FocusSource::Bounds);
    EXPECT_FLOAT_EQ(r->lens.focus_distance, 150.0f);
    // The centre shows background: the bounds again.
    QuadScene off;
    off.scene = raster::Scene{};
    const int32_t white = addMaterial(off.scene, flatMaterial({1.0f, 1.0f, 1.0f, 1.0f}));
    addQuad(off.scene, 10.0f, 10.0f, 20.0f, 20.0f, 200.0f, white);
    r = off.resolve({});
    ASSERT_TRUE(r.ok()) << failure(r);
    EXPECT_EQ(off.renders, 1);
    EXPECT_EQ(r->focus_source, dof::FocusSource::Bounds);
    EXPECT_FLOAT_EQ(r->lens.focus_distance, 200.0f);
}

TEST(LensResolution, TheViewOrTheSceneHintNeedNoRender) {
    QuadScene s;
    dof::LensRequest request;
    request.view_focus = true;
    s.view.focus_distance = 130.0f;
    raster::Result<dof::ResolvedLens> r = s.resolve(request);
    ASSERT_TRUE(r.ok()) << failure(r);
    EXPECT_EQ(r->focus_source, dof::FocusSource::ViewFocus);
    EXPECT_EQ(r->lens.focus_distance, 130.0f);
    s.scene.lens = raster::LensHint{1.0f, 120.0f};
    r = s.resolve({});
    ASSERT_TRUE(r.ok()) << failure(r);
    EXPECT_EQ(r->focus_source, dof::FocusSource::Scene);
    EXPECT_EQ(r->lens.focus_distance, 120.0f);
    // A pinhole image without a lens request: no render, and the view's focus distance.
    s.scene.lens.reset();
    request = {};
    request.pinhole_image = true;
    r = s.resolve(request);
    ASSERT_TRUE(r.ok()) << failure(r);
    EXPECT_EQ(r->focus_source, dof::FocusSource::ViewDefault);
    EXPECT_EQ(r->lens.focus_distance, 130.0f);
    EXPECT_EQ(s.renders, 0);
}

TEST(LensResolution, InvalidAndAbsurdRequestsAreErrorsNamingTheField) {
    auto message = [](void (*edit)(dof::LensRequest&)) {
        QuadScene s;
        dof::LensRequest request;
        request.focus_distance = 150.0f;
        edit(request);
        raster::Result<dof::ResolvedLens> r = s.resolve(request);
        return failure(r);
    };
    const std::pair<const char*, void (*)(dof::LensRequest&)> cases[] = {
        {"aperture_radius", [](dof::LensRequest& r) { r.aperture_radius = -1.0f; }},
        {"aperture_radius", [](dof::LensRequest& r) { r.aperture_radius = NAN; }},
        {"aperture_radius", [](dof::LensRequest& r) { r.aperture_radius = INFINITY; }},
        {"fstop", [](dof::LensRequest& r) { r.fstop = 0.0f, r.focal_length_mm = 50.0f; }},
        {"fstop", [](dof::LensRequest& r) { r.fstop = 2.0f; }}, // without a focal length
        {"focal_length_mm",
         [](dof::LensRequest& r) { r.fstop = 2.0f, r.focal_length_mm = -50.0f; }},
        {"sensor_height_mm",
         [](dof::LensRequest& r) { r.focal_length_mm = 50.0f, r.sensor_height_mm = NAN; }},
        {"focus_distance", [](dof::LensRequest& r) { r.focus_distance = 0.0f; }},
        {"focus_distance", [](dof::LensRequest& r) { r.focus_distance = INFINITY; }},
        {"focus_distance", [](dof::LensRequest& r) { r.focus_pixel = glm::uvec2(32, 32); }},
        {"fstop",
         [](dof::LensRequest& r) {
             r.aperture_radius = 1.0f, r.fstop = 2.0f, r.focal_length_mm = 50.0f;
         }},
        // Absurd values: an f-stop so small E overflows to infinity, a focus distance behind
        // the far plane (400), a focal length so short the field of view reaches 180 degrees.
        {"aperture_radius",
         [](dof::LensRequest& r) { r.fstop = 1e-44f, r.focal_length_mm = 50.0f; }},
        {"far plane", [](dof::LensRequest& r) { r.focus_distance = 1e9f; }},
        {"focal length", [](dof::LensRequest& r) { r.focal_length_mm = 1e-30f; }},
    };
    for (const auto& [field, edit] : cases) {
        const std::string m = message(edit);
        EXPECT_NE(m.find(field), std::string::npos) << field << ": '" << m << "'";
        EXPECT_EQ(m.find("--"), std::string::npos) << "names a command-line option: " << m;
    }
}

TEST(LensResolution, FrameRendererFocusesOnThePinholeItReuses) {
    QuadScene s;
    raster::TaskPool pool(0);
    dof::FrameRenderer frames(pool);
    raster::FrameStats stats;
    raster::Result<dof::ResolvedLens> r = frames.resolveLens({}, s.scene, s.view, {}, &stats);
    ASSERT_TRUE(r.ok()) << failure(r);
    EXPECT_EQ(r->focus_source, dof::FocusSource::Autofocus);
    EXPECT_GT(stats.triangles_in, 0u);
    std::vector<float> rgba(size_t(s.view.width) * s.view.height * 4);
    dof::FrameImage image;
    image.rgba = rgba.data();
    image.stride = size_t(s.view.width) * 4;
    dof::FrameReport report;
    dof::GatherMethod gather;
    ASSERT_TRUE(
        frames.render(s.scene, r->view, r->lens, {}, dof::MethodSettings(gather), image, &report)
            .ok());
    EXPECT_TRUE(report.pinhole_reused); // the autofocus frame, not a second render
    EXPECT_EQ(report.renders, 0u);
}

} // namespace
} // namespace focal::test
