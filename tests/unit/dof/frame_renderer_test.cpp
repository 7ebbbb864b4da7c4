// dof::FrameRenderer (dof/frame_renderer.h): the one call gives the bytes of the method
// functions called directly, writes only the caller's pixels, gives the bytes of a fresh object
// whatever it rendered before, shares the pinhole frame, and turns bad input into a Status.
#include "dof_test_util.h"

#include <dof/frame_renderer.h>
#include <scenes/builtin.h>

#include <gtest/gtest.h>

#include <cstring>
#include <map>
#include <span>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

namespace focal::test {
namespace {

struct Fixture {
    raster::Scene scene;
    dof::LensSampleSet samples = makeSamples(64);
    dof::LensSampleSet few = makeSamples(8);
    dof::LensSampleSet other = makeSamples(12, {}, dof::LensPattern::Halton, 3);
};

const Fixture& fixture() {
    static const Fixture f = [] {
        Fixture x;
        raster::Result<raster::Scene> s = scenes::makeBuiltinScene("demo");
        FOCAL_CHECK(s.ok());
        x.scene = std::move(*s);
        return x;
    }();
    return f;
}

raster::View viewOf(uint32_t width, uint32_t height) {
    const raster::Scene& scene = fixture().scene;
    raster::View view = raster::viewFromCamera(scene.cameras.at(0), width, height);
    view.focus_distance = scene.lens->focus_distance;
    return view;
}

dof::ThinLens lensOf(const raster::View& view) {
    const raster::LensHint hint = *fixture().scene.lens;
    return dof::makeThinLens(view, hint.aperture_radius, hint.focus_distance);
}

raster::View pinholeView(const raster::View& view) {
    raster::View v = view;
    v.lens_offset = glm::vec2(0.0f);
    v.pixel_shift = glm::vec2(0.0f);
    return v;
}

// The settings of every method tested, by name.
dof::MethodSettings methodNamed(const std::string& name) {
    const Fixture& f = fixture();
    if (name == "pinhole")
        return dof::PinholeMethod{};
    if (name == "accum")
        return dof::AccumMethod{{}, &f.few, {}};
    if (name == "gather")
        return dof::GatherMethod{};
    if (name == "multiview")
        return dof::MultiviewMethod{{}, &f.few};
    if (name == "multiview_halton") {
        dof::MultiviewSettings s;
        s.jitter = dof::JitterMode::Halton;
        return dof::MultiviewMethod{s, &f.few};
    }
    if (name == "multiview_halton_other") { // another sample set: another 2N sequence
        dof::MultiviewSettings s;
        s.jitter = dof::JitterMode::Halton;
        return dof::MultiviewMethod{s, &f.other};
    }
    if (name == "multilayer")
        return dof::MultilayerMethod{{}, &f.samples};
    dof::MultilayerSettings s; // multilayer_box: the second moment of the samples matters
    s.filter = dof::LevelFilter::Box;
    return dof::MultilayerMethod{s, &f.samples};
}

const std::vector<std::string> kMethods = {
    "pinhole", "accum", "gather", "multiview", "multiview_halton", "multilayer", "multilayer_box"};

// The method functions called directly, as the FrameRenderer documents it derives its settings.
std::vector<float> direct(const std::string& name, const raster::View& view,
                          const raster::RenderOptions& options, uint32_t threads) {
    const Fixture& f = fixture();
    const raster::Scene& scene = f.scene;
    const dof::ThinLens lens = lensOf(view);
    raster::TaskPool pool(threads);
    raster::Renderer renderer(pool);
    const dof::MethodSettings method = methodNamed(name);
    raster::Frame frame;
    std::vector<float> rgba;
    if (name == "pinhole") {
        FOCAL_CHECK(renderer.render(scene, pinholeView(view), options, frame).ok());
        return frame.color;
    }
    if (name == "accum") {
        const dof::RenderFn fn = [&](const raster::View& v, raster::Frame& out) {
            return renderer.render(scene, v, options, out);
        };
        FOCAL_CHECK(dof::renderAccum(view, lens, f.few, {}, fn, frame, &pool).ok());
        return frame.color;
    }
    if (name == "gather") {
        FOCAL_CHECK(renderer.render(scene, pinholeView(view), options, frame).ok());
        dof::GatherSettings s;
        s.tile_size = options.tile_size;
        s.simd = options.simd;
        const dof::GatherImage image{frame.color.data(), dof::depthRefOf(frame.depth), frame.width,
                                     frame.height};
        FOCAL_CHECK(dof::gather(image, lens, pinholeView(view), s, rgba, nullptr, &pool).ok());
        return rgba;
    }
    if (name.rfind("multiview", 0) == 0) {
        dof::MultiviewSettings s = std::get<dof::MultiviewMethod>(method).settings;
        s.seed = f.few.seed();
        raster::Result<dof::LensSampleSet> seq = dof::LensSampleSet::create(
            f.few.shape(), dof::LensPattern::Halton, 2 * f.few.size(), f.few.seed());
        FOCAL_CHECK(seq.ok());
        if (s.jitter == dof::JitterMode::Halton)
            s.sequence_2n = &*seq;
        const dof::PinholeFn pin = pinholeFnOf(renderer, scene, options);
        const dof::LayersFn lay = layersFnOf(renderer, scene, options);
        dof::ShadingInputs shading;
        shading.scene = &scene;
        shading.simd = options.simd;
        FOCAL_CHECK(dof::renderMultiview(view, lens, f.few, s, shading, scene.background, pin, lay,
                                         pool, rgba)
                        .ok());
        return rgba;
    }
    dof::MultilayerSettings s = std::get<dof::MultilayerMethod>(method).settings;
    s.aperture = f.samples.shape();
    s.aperture_second_moment = dof::apertureSecondMoment(f.samples);
    s.memory_budget = options.memory_budget;
    const dof::CollectFn collect = [&](const raster::FragmentListDesc& desc,
                                       raster::FragmentLists& lists) {
        return renderer.renderFragmentLists(scene, pinholeView(view), options, desc, lists);
    };
    dof::Multilayer multilayer;
    dof::MultilayerImage image;
    FOCAL_CHECK(
        multilayer.render(pinholeView(view), lens, scene.background, s, collect, pool, image).ok());
    return image.rgba;
}

// One frame through `frames` into a tight image.
std::vector<float> oneCall(dof::FrameRenderer& frames, const std::string& name,
                           const raster::View& view, const raster::RenderOptions& options = {},
                           dof::FrameReport* report = nullptr,
                           dof::FrameObserver* observer = nullptr) {
    std::vector<float> rgba(size_t(view.width) * view.height * 4, -1.0f);
    const dof::FrameImage image{rgba.data(), size_t(view.width) * 4, nullptr, 0};
    const raster::Status s = frames.render(fixture().scene, view, lensOf(view), options,
                                           methodNamed(name), image, report, observer);
    EXPECT_TRUE(s.ok()) << name << ": " << s.message();
    return rgba;
}

bool sameBytes(const std::vector<float>& a, const std::vector<float>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

TEST(FrameRenderer, OneCallGivesTheBytesOfTheMethodFunctions) {
    const raster::View view = viewOf(64, 48);
    for (uint32_t threads : {0u, 2u}) {
        raster::TaskPool pool(threads);
        for (const std::string& name : kMethods) {
            dof::FrameRenderer frames(pool);
            dof::FrameReport report;
            const std::vector<float> got = oneCall(frames, name, view, {}, &report);
            EXPECT_TRUE(sameBytes(got, direct(name, view, {}, threads)))
                << name << " at " << threads << " threads";
            // The scene's lens blurs: the comparison is not of pinhole images.
            EXPECT_EQ(sameBytes(got, direct("pinhole", view, {}, threads)), name == "pinhole")
                << name;
            EXPECT_EQ(report.method_stats.index() == 0, name == "pinhole") << name;
            EXPECT_EQ(report.stage_ms.empty(), name == "pinhole") << name;
        }
    }
    // Other raster options reach the methods (the scalar kernels, unorm16 depth, small tiles).
    raster::RenderOptions options;
    options.simd = false;
    options.depth_format = raster::DepthFormat::Unorm16;
    options.tile_size = 16;
    raster::TaskPool pool(2);
    for (const std::string name : {"gather", "multiview", "multilayer"}) {
        dof::FrameRenderer frames(pool);
        EXPECT_TRUE(sameBytes(oneCall(frames, name, view, options), direct(name, view, options, 2)))
            << name;
    }
}

TEST(FrameRenderer, DepthIsTheMethodsDepth) {
    const raster::View view = viewOf(40, 30);
    raster::TaskPool pool(0);
    dof::FrameRenderer frames(pool);
    std::vector<float> rgba(40 * 30 * 4), depth(40 * 30);
    const dof::FrameImage image{rgba.data(), 40 * 4, depth.data(), 40};
    ASSERT_TRUE(
        frames.render(fixture().scene, view, lensOf(view), {}, dof::PinholeMethod{}, image, nullptr)
            .ok());
    raster::Renderer renderer(pool);
    raster::Frame frame;
    ASSERT_TRUE(renderer.render(fixture().scene, view, {}, frame).ok());
    for (size_t i = 0; i < depth.size(); ++i)
        ASSERT_EQ(depth[i], raster::distanceFromDepth(view, frame.depth.load(i))) << i;

    ASSERT_TRUE(frames
                    .render(fixture().scene, view, lensOf(view), {}, methodNamed("multilayer"),
                            image, nullptr)
                    .ok());
    EXPECT_TRUE(sameBytes(depth, frames.multilayerImage().depth));
}

TEST(FrameRenderer, StrideLargerThanTheWidthLeavesThePaddingUntouched) {
    const raster::View view = viewOf(37, 21); // odd sizes: rows are not multiples of anything
    const size_t stride = 37 * 4 + 13, depth_stride = 37 + 5;
    constexpr float kPad = -12345.0f;
    raster::TaskPool pool(2);
    dof::FrameRenderer frames(pool);
    for (const std::string& name : kMethods) {
        const std::vector<float> tight = oneCall(frames, name, view);
        std::vector<float> rgba(stride * 21 + 7, kPad), depth(depth_stride * 21 + 3, kPad);
        const dof::FrameImage image{rgba.data(), stride, depth.data(), depth_stride};
        ASSERT_TRUE(
            frames
                .render(fixture().scene, view, lensOf(view), {}, methodNamed(name), image, nullptr)
                .ok())
            << name;
        for (size_t y = 0; y < 21; ++y) {
            EXPECT_EQ(std::memcmp(&rgba[y * stride], &tight[y * 37 * 4], 37 * 4 * sizeof(float)), 0)
                << name << " row " << y;
            for (size_t i = y * stride + 37 * 4; i < (y + 1) * stride; ++i)
                ASSERT_EQ(rgba[i], kPad) << name << " colour padding at " << i;
            for (size_t x = 0; x < 37; ++x)
                ASSERT_NE(depth[y * depth_stride + x], kPad) << name << " depth not written";
            for (size_t i = y * depth_stride + 37; i < (y + 1) * depth_stride; ++i)
                ASSERT_EQ(depth[i], kPad) << name << " depth padding at " << i;
        }
        for (size_t i = stride * 21; i < rgba.size(); ++i)
            ASSERT_EQ(rgba[i], kPad) << name << " past the image";
        for (size_t i = depth_stride * 21; i < depth.size(); ++i)
            ASSERT_EQ(depth[i], kPad) << name << " past the depth image";
    }
}

TEST(FrameRenderer, RepeatedFramesGiveTheBytesOfAFreshRenderer) {
    struct Step {
        std::string method;
        uint32_t width, height;
    };
    // Same and different sizes and methods one after another, every method at least twice.
    const std::vector<Step> steps = {{"multiview", 64, 48},
                                     {"multiview", 64, 48},
                                     {"gather", 32, 24},
                                     {"multilayer", 64, 48},
                                     {"multiview", 40, 56},
                                     {"accum", 64, 48},
                                     {"multilayer_box", 24, 16},
                                     {"pinhole", 64, 48},
                                     {"gather", 64, 48},
                                     {"multiview_halton", 64, 48},
                                     {"multiview_halton_other", 64, 48},
                                     {"multilayer", 64, 48},
                                     {"accum", 32, 24},
                                     {"multiview", 64, 48},
                                     {"pinhole", 16, 8},
                                     {"gather", 32, 24}};
    raster::TaskPool pool(2);
    dof::FrameRenderer kept(pool);
    for (size_t i = 0; i < steps.size(); ++i) {
        const raster::View view = viewOf(steps[i].width, steps[i].height);
        dof::FrameRenderer fresh(pool);
        EXPECT_TRUE(
            sameBytes(oneCall(kept, steps[i].method, view), oneCall(fresh, steps[i].method, view)))
            << "step " << i << ": " << steps[i].method;
    }
}

TEST(FrameRenderer, PinholeIsSharedWithTheNextFrameOnly) {
    const raster::View view = viewOf(64, 48);
    raster::TaskPool pool(0);
    for (const std::string name : {"pinhole", "accum", "gather", "multiview"}) {
        dof::FrameRenderer frames(pool);
        raster::View focus_view = view;
        focus_view.focus_distance = 3.0f * view.focus_distance; // does not move pinhole pixels
        ASSERT_TRUE(frames.pinhole(fixture().scene, focus_view, {}).ok());
        dof::FrameReport report;
        const std::vector<float> shared = oneCall(frames, name, view, {}, &report);
        EXPECT_TRUE(report.pinhole_reused) << name;
        EXPECT_TRUE(sameBytes(shared, direct(name, view, {}, 0))) << name;
        ASSERT_NE(frames.lastPinhole(fixture().scene, view, {}), nullptr) << name;
        // The next frame renders the scene again.
        oneCall(frames, name, view, {}, &report);
        EXPECT_FALSE(report.pinhole_reused) << name;
        // A pinhole of other options is not used.
        ASSERT_TRUE(frames.pinhole(fixture().scene, view, {}).ok());
        raster::RenderOptions unorm;
        unorm.depth_format = raster::DepthFormat::Unorm16;
        oneCall(frames, name, view, unorm, &report);
        EXPECT_FALSE(report.pinhole_reused) << name;
        if (name == "multiview") { // its pinhole holds depth only: not one to share
            EXPECT_EQ(frames.lastPinhole(fixture().scene, view, unorm), nullptr) << name;
        } else if (name != "accum") { // accum renders its pinhole into its own frame
            EXPECT_NE(frames.lastPinhole(fixture().scene, view, unorm), nullptr) << name;
        }
    }
}

raster::Status renderWith(const dof::MethodSettings& method, const dof::FrameImage& image,
                          const raster::View& view) {
    raster::TaskPool pool(0);
    dof::FrameRenderer frames(pool);
    return frames.render(fixture().scene, view, lensOf(view), {}, method, image);
}

void expectError(const raster::Status& s, const std::string& words) {
    ASSERT_FALSE(s.ok()) << "expected an error naming " << words;
    EXPECT_NE(s.message().find(words), std::string::npos) << s.message();
}

TEST(FrameRenderer, BadInputIsAStatusNamingTheProblem) {
    const raster::View view = viewOf(16, 8);
    std::vector<float> rgba(16 * 8 * 4), depth(16 * 8);
    const dof::FrameImage good{rgba.data(), 16 * 4, nullptr, 0};
    for (const std::string& name : kMethods) {
        expectError(renderWith(methodNamed(name), {nullptr, 16 * 4, nullptr, 0}, view),
                    "FrameImage::rgba is null");
        expectError(renderWith(methodNamed(name), {rgba.data(), 16 * 4 - 1, nullptr, 0}, view),
                    "colour row stride 63 is below width*4 = 64");
        expectError(renderWith(methodNamed(name), {rgba.data(), 16 * 4, depth.data(), 15}, view),
                    "depth row stride 15 is below width = 16");
        raster::View empty = view;
        empty.width = 0;
        EXPECT_FALSE(renderWith(methodNamed(name), good, empty).ok()) << name;
    }
    expectError(renderWith(dof::AccumMethod{}, good, view), "AccumMethod::samples is null");
    expectError(renderWith(dof::MultiviewMethod{}, good, view), "MultiviewMethod::samples is null");
    dof::GatherMethod gather;
    gather.settings.max_radius_px = 0.0f;
    EXPECT_FALSE(renderWith(gather, good, view).ok());
    dof::MultiviewMethod multiview{{}, &fixture().few};
    multiview.settings.overlap = -1.0f;
    EXPECT_FALSE(renderWith(multiview, good, view).ok());
    dof::MultilayerMethod multilayer{{}, &fixture().samples};
    multilayer.settings.epsilon = -1.0f;
    EXPECT_FALSE(renderWith(multilayer, good, view).ok());
    // A lens that is not one: every method but pinhole fails, pinhole ignores it.
    raster::TaskPool pool(0);
    dof::FrameRenderer frames(pool);
    dof::ThinLens bad = lensOf(view);
    bad.aperture_radius = -1.0f;
    for (const std::string& name : kMethods)
        EXPECT_EQ(
            frames.render(fixture().scene, view, bad, {}, methodNamed(name), good, nullptr).ok(),
            name == "pinhole")
            << name;
    // A bad frame leaves the renderer usable: the next good one gives the right bytes.
    EXPECT_TRUE(sameBytes(oneCall(frames, "gather", viewOf(64, 48)),
                          direct("gather", viewOf(64, 48), {}, 0)));
}

// Keeps what a frame's observer is told (frame_observer.h): the stages' ids, copies of their
// images, and the probes.
struct Recorder final : dof::FrameObserver {
    std::vector<glm::uvec2> pixels;
    std::vector<std::string> ids;
    std::vector<dof::Stage> stages; // images' pixels copied into `kept`
    std::vector<std::vector<float>> kept;
    std::vector<dof::PixelProbe> probes;
    std::span<const glm::uvec2> probePixels() override { return pixels; }
    void stage(const dof::Stage& stage) override {
        ids.push_back(stage.id);
        stages.push_back(stage);
        for (dof::StageImage& img : stages.back().images) {
            EXPECT_GE(img.stride, size_t(img.width) * img.channels) << stage.id << " " << img.name;
            kept.emplace_back(img.pixels, img.pixels + img.stride * img.height);
            img.pixels = kept.back().data();
        }
    }
    void probe(const dof::PixelProbe& probe) override { probes.push_back(probe); }
    const dof::Stage& find(const std::string& id) const {
        for (const dof::Stage& s : stages)
            if (s.id == id)
                return s;
        ADD_FAILURE() << "no stage " << id;
        return stages.front();
    }
};

TEST(FrameRenderer, AnObserverSeesEveryStageInOrderAndChangesNoByte) {
    const raster::View view = viewOf(64, 48);
    const std::vector<std::string> raster_stages = {"raster.geometry", "raster.binning",
                                                    "raster.coverage", "raster.color",
                                                    "targets.fragment_lists"};
    const std::map<std::string, std::vector<std::string>> method_stages = {
        {"pinhole", {}},
        {"accum", {"accum.lens", "accum.views", "accum.average"}},
        {"gather", {"gather.coc", "gather.vertical", "gather.horizontal"}},
        {"multiview",
         {"multiview.decomposition", "targets.layers", "multiview.nbuffer", "multiview.mipmaps",
          "multiview.lens", "multiview.tracing"}},
        {"multilayer",
         {"multilayer.collect", "multilayer.levels", "multilayer.borders",
          "multilayer.accumulate"}}};
    for (uint32_t threads : {0u, 2u}) {
        raster::TaskPool pool(threads);
        for (const auto& [name, stages] : method_stages) {
            dof::FrameRenderer plain(pool), observed(pool);
            const std::vector<float> want = oneCall(plain, name, view);
            Recorder rec;
            rec.pixels = {{0, 0}, {31, 20}, {63, 47}};
            EXPECT_TRUE(sameBytes(oneCall(observed, name, view, {}, nullptr, &rec), want)) << name;
            // The next frame without an observer is not disturbed by the observed one.
            EXPECT_TRUE(sameBytes(oneCall(observed, name, view), want)) << name;
            std::vector<std::string> ids = raster_stages;
            ids.insert(ids.end(), stages.begin(), stages.end());
            ids.push_back("result.image");
            EXPECT_EQ(rec.ids, ids) << name;
            // Each probe's colour is the frame's pixel, bit for bit.
            ASSERT_EQ(rec.probes.size(), rec.pixels.size()) << name;
            for (const dof::PixelProbe& p : rec.probes)
                EXPECT_EQ(
                    std::memcmp(p.rgba, &want[(size_t(p.y) * view.width + p.x) * 4], sizeof p.rgba),
                    0)
                    << name << " " << p.x << "," << p.y;
            // The method's own record (its probe function on the frame's kept data) agrees.
            const std::string& method_name = name; // a lambda cannot capture a binding (C++17)
            for (const dof::PixelProbe& p : rec.probes) {
                EXPECT_EQ(p.method.index() == 0, name == "pinhole") << name;
                std::visit(
                    [&](const auto& m) {
                        if constexpr (!std::is_same_v<std::decay_t<decltype(m)>, std::monostate>) {
                            EXPECT_EQ(std::memcmp(m.rgba, p.rgba, sizeof p.rgba), 0)
                                << method_name << " " << p.x << "," << p.y;
                        }
                    },
                    p.method);
            }
            // The result stage shows the result.
            const dof::StageImage& result = rec.find("result.image").images.at(0);
            EXPECT_EQ(std::memcmp(result.pixels, want.data(), want.size() * sizeof(float)), 0)
                << name;
        }
    }
}

TEST(FrameRenderer, ObservedStagesHoldWhatTheFrameMade) {
    const raster::View view = viewOf(64, 48);
    raster::TaskPool pool(2);
    dof::FrameRenderer frames(pool);
    Recorder rec;
    for (uint32_t y = 0; y < view.height; y += 5)
        for (uint32_t x = 0; x < view.width; x += 7)
            rec.pixels.emplace_back(x, y);
    const std::vector<float> pinhole = oneCall(frames, "pinhole", view, {}, nullptr, &rec);
    // The colour target is the pinhole frame.
    const dof::StageImage& color = rec.find("raster.color").images.at(0);
    EXPECT_EQ(std::memcmp(color.pixels, pinhole.data(), pinhole.size() * sizeof(float)), 0);
    // The tile heat map adds up to the count it reports, over ceil(64/64) x ceil(48/64) tiles.
    const dof::Stage& binning = rec.find("raster.binning");
    const dof::StageImage& heat = binning.images.at(0);
    EXPECT_EQ(heat.width, 1u);
    EXPECT_EQ(heat.height, 1u);
    EXPECT_EQ(heat.scale, 64u);
    double sum = 0.0;
    for (uint32_t i = 0; i < heat.width * heat.height; ++i)
        sum += double(heat.pixels[i]);
    for (const auto& [n, v] : binning.counts) {
        if (n == "binned_triangles") {
            EXPECT_EQ(v, sum);
        }
    }
    EXPECT_GT(sum, 0.0);
    // Probes: the fragments are nearest first; the nearest one is the geometry stage's triangle,
    // the list length is the coverage stage's count, and an opaque scene's pinhole pixel is the
    // nearest fragment's colour.
    const dof::StageImage& nearest = rec.find("raster.geometry").images.at(0);
    const dof::StageImage& counts = rec.find("raster.coverage").images.at(1);
    ASSERT_EQ(rec.probes.size(), rec.pixels.size());
    size_t covered = 0;
    for (const dof::PixelProbe& p : rec.probes) {
        const size_t i = size_t(p.y) * view.width + p.x;
        EXPECT_EQ(float(p.fragments.size()), counts.pixels[i]) << p.x << "," << p.y;
        for (size_t k = 1; k < p.fragments.size(); ++k)
            EXPECT_LE(p.fragments[k - 1].distance, p.fragments[k].distance);
        if (p.fragments.empty()) {
            EXPECT_EQ(nearest.pixels[i], -1.0f);
            continue;
        }
        ++covered;
        EXPECT_EQ(nearest.pixels[i], float(p.fragments[0].primitive));
        for (int c = 0; c < 3; ++c)
            EXPECT_EQ(p.rgba[c], p.fragments[0].rgba[c]) << p.x << "," << p.y << " channel " << c;
    }
    EXPECT_GT(covered, rec.probes.size() / 2);
}

TEST(FrameRenderer, AccumsLastRunningAverageIsItsResult) {
    const raster::View view = viewOf(48, 32);
    raster::TaskPool pool(2);
    dof::FrameRenderer frames(pool);
    Recorder rec;
    const std::vector<float> result = oneCall(frames, "accum", view, {}, nullptr, &rec);
    const dof::Stage& avg = rec.find("accum.average");
    // After 1, 2, 4 and 8 views (the fixture's few samples).
    ASSERT_EQ(avg.images.size(), 4u);
    EXPECT_EQ(avg.images.back().name, "after 8 views");
    EXPECT_EQ(std::memcmp(avg.images.back().pixels, result.data(), result.size() * sizeof(float)),
              0);
    EXPECT_EQ(rec.find("accum.views").images.size(), 4u);
    EXPECT_EQ(rec.find("accum.lens").plots.at(0).points.size(), 8u);
}

TEST(FrameRenderer, AProbeOutsideTheImageIsAnError) {
    const raster::View view = viewOf(32, 24);
    raster::TaskPool pool(0);
    dof::FrameRenderer frames(pool);
    Recorder rec;
    rec.pixels = {{32, 0}};
    std::vector<float> rgba(32 * 24 * 4);
    const raster::Status s =
        frames.render(fixture().scene, view, lensOf(view), {}, methodNamed("gather"),
                      dof::FrameImage{rgba.data(), 32 * 4, nullptr, 0}, nullptr, &rec);
    ASSERT_FALSE(s.ok());
    EXPECT_NE(s.message().find("probe pixel 32,0 is outside the 32x24 image"), std::string::npos)
        << s.message();
    EXPECT_TRUE(rec.ids.empty());
}

} // namespace
} // namespace focal::test
