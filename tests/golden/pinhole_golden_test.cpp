// Golden and determinism tests of the pinhole renderer on every built-in scene (issue 3 item 7;
// docs/testing.md). Each case renders a scene at 160x120 from its default camera with one set of
// RenderOptions. Golden.MatchesReference compares the render with tests/golden (hash exactly,
// PNG within 1 step); Determinism.SameBitsForEveryThreadCountAndTileSize renders it at threads
// 0/1/2/3/8 x tiles 8/16/64/256 x SIMD/scalar kernels and requires bit-identical colour and
// depth. The depth-of-field methods have their own goldens (dof_golden_test.cpp).
#include "apps/scene_source.h"
#include "support/golden.h"
#include "support/subprocess.h"
#include "support/test_util.h"

#include <raster/camera.h>
#include <raster/renderer.h>
#include <raster/task_pool.h>
#include <scenes/builtin.h>

#include <gtest/gtest.h>

#include <cinttypes>
#include <cstdio>
#include <filesystem>
#include <ostream>
#include <string>
#include <unistd.h>
#include <vector>

namespace {

namespace fs = std::filesystem;
using focal::test::matchesGolden;

constexpr uint32_t kWidth = 160;
constexpr uint32_t kHeight = 120;
constexpr uint32_t kThreadCounts[] = {0, 1, 2, 3, 8};
constexpr uint32_t kTileSizes[] = {8, 16, 64, 256};

// Under ThreadSanitizer (CI runs the Determinism sweep there) only renders with more than one
// worker can race: threads 0 and 1 run every tile on the calling thread, and the scalar kernels
// use the same pool and tiling as the SIMD ones. The other builds check those; under TSan they
// are skipped, which takes the sweep from 41 renders a case to 13.
#if defined(__SANITIZE_THREAD__)
constexpr bool kThreadSanitizer = true;
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
constexpr bool kThreadSanitizer = true;
#else
constexpr bool kThreadSanitizer = false;
#endif
#else
constexpr bool kThreadSanitizer = false;
#endif

struct GoldenCase {
    std::string name;  // hash key and image file stem
    std::string scene; // builtin:NAME or a glTF path, as `focal render` takes it
    raster::RenderOptions options;
};

std::string fixture(const char* file) {
    return std::string(FOCAL_TEST_DATA_DIR) + "/gltf/valid/" + file;
}

// Every golden case: each built-in scene with default options (shading and texture filtering as
// the materials and samplers say) and with 16-bit depth; the lit demo scene forced unlit and
// with the texture filters its samplers do not use; a quad whose sampler is nearest under the
// other filters; and a KHR_materials_unlit triangle as the material says and forced lit.
std::vector<GoldenCase> goldenCases() {
    std::vector<GoldenCase> cases;
    for (const scenes::BuiltinInfo& info : scenes::builtinScenes()) {
        const std::string name(info.name);
        cases.push_back({name, "builtin:" + name, {}});
        raster::RenderOptions unorm16;
        unorm16.depth_format = raster::DepthFormat::Unorm16;
        cases.push_back({name + "_unorm16", "builtin:" + name, unorm16});
    }
    auto shading = [](raster::ShadingMode mode) {
        raster::RenderOptions o;
        o.shading = mode;
        return o;
    };
    auto filter = [](raster::FilterOverride f) {
        raster::RenderOptions o;
        o.texture_filter = f;
        return o;
    };
    cases.push_back({"demo_unlit", "builtin:demo", shading(raster::ShadingMode::Unlit)});
    cases.push_back({"demo_nearest", "builtin:demo", filter(raster::FilterOverride::Nearest)});
    cases.push_back({"demo_bilinear", "builtin:demo", filter(raster::FilterOverride::Bilinear)});
    const std::string quad = fixture("textured_quad.gltf");
    cases.push_back({"textured_quad", quad, {}});
    cases.push_back({"textured_quad_bilinear", quad, filter(raster::FilterOverride::Bilinear)});
    cases.push_back({"textured_quad_trilinear", quad, filter(raster::FilterOverride::Trilinear)});
    const std::string unlit = fixture("unlit.gltf");
    cases.push_back({"unlit", unlit, {}});
    cases.push_back({"unlit_lit", unlit, shading(raster::ShadingMode::Lit)});
    return cases;
}

// Pairs of cases that differ only in an option that must change the pixels of that scene.
constexpr std::pair<const char*, const char*> kMustDiffer[] = {
    {"demo", "demo_unlit"},
    {"demo", "demo_nearest"},
    {"demo", "demo_bilinear"},
    {"demo_nearest", "demo_bilinear"},
    {"textured_quad", "textured_quad_bilinear"},
    {"textured_quad", "textured_quad_trilinear"},
    {"unlit", "unlit_lit"},
};

// Decodes only the textures `shading` samples, as focal render does: the goldens prove that
// skipping the others changes no pixel.
raster::Scene loadScene(const std::string& spec, raster::ShadingMode shading) {
    raster::ImportOptions options;
    options.roles = raster::sampledTextureRoles(shading);
    raster::Result<raster::Scene> scene = focal::loadScene(spec, options);
    EXPECT_TRUE(scene.ok()) << scene.status().message();
    return scene.ok() ? std::move(scene.value()) : raster::Scene{};
}

// The view `focal render SCENE --width 160 --height 120` uses: the scene's first camera (else
// one framing its bounds), focused where its lens hint says.
raster::View defaultView(const raster::Scene& scene) {
    raster::View view = scene.cameras.empty()
                            ? raster::viewFramingBounds(raster::worldBounds(scene), kWidth, kHeight)
                            : raster::viewFromCamera(scene.cameras[0], kWidth, kHeight);
    if (scene.lens)
        view.focus_distance = scene.lens->focus_distance;
    return view;
}

std::string hex(uint64_t v) {
    char buf[17];
    std::snprintf(buf, sizeof buf, "%016" PRIx64, v);
    return buf;
}

void PrintTo(const GoldenCase& c, std::ostream* os) {
    *os << c.name << " (" << c.scene << ")";
}

class GoldenCaseTest : public ::testing::TestWithParam<GoldenCase> {};

using Golden = GoldenCaseTest;
using Determinism = GoldenCaseTest;

TEST_P(Golden, MatchesReference) {
    const GoldenCase& c = GetParam();
    const raster::Scene scene = loadScene(c.scene, c.options.shading);
    ASSERT_FALSE(HasFailure());
    const raster::Frame frame = focal::test::render(scene, defaultView(scene), c.options, 2);
    ASSERT_EQ(frame.width, kWidth);
    ASSERT_EQ(frame.height, kHeight);
    EXPECT_TRUE(
        matchesGolden(focal::test::pinholeGoldens(), c.name, frame, focal::test::hashFrame(frame)));
}

// One Renderer (and one reused Frame) per thread count renders every tile size with both kernel
// sets in turn, so reusing per-frame memory between renders is covered too.
TEST_P(Determinism, SameBitsForEveryThreadCountAndTileSize) {
    const GoldenCase& c = GetParam();
    const raster::Scene scene = loadScene(c.scene, c.options.shading);
    ASSERT_FALSE(HasFailure());
    const raster::View view = defaultView(scene);
    raster::RenderOptions reference_options = c.options;
    reference_options.tile_size = 64;
    const raster::Frame reference = focal::test::render(scene, view, reference_options, 0);
    const uint64_t reference_hash = focal::test::hashFrame(reference);

    for (const uint32_t threads : kThreadCounts) {
        if (kThreadSanitizer && threads < 2)
            continue;
        raster::TaskPool pool(threads);
        raster::Renderer renderer(pool);
        raster::Frame frame;
        for (const uint32_t tile : kTileSizes)
            for (const bool simd : {true, false}) {
                if (kThreadSanitizer && !simd)
                    continue;
                raster::RenderOptions options = c.options;
                options.tile_size = tile;
                options.simd = simd;
                const raster::Status s = renderer.render(scene, view, options, frame);
                ASSERT_TRUE(s.ok()) << s.message();
                const uint64_t h = focal::test::hashFrame(frame);
                if (h == reference_hash)
                    continue;
                const std::string label = c.name + "_threads" + std::to_string(threads) + "_tile" +
                                          std::to_string(tile) + (simd ? "" : "_scalar");
                ADD_FAILURE() << label << " gave hash " << hex(h) << ", threads 0, tile 64 gave "
                              << hex(reference_hash) << "\n"
                              << focal::test::describeFrameDifference(label, reference, frame);
            }
    }
}

std::string caseName(const ::testing::TestParamInfo<GoldenCase>& info) {
    return info.param.name;
}

INSTANTIATE_TEST_SUITE_P(Scenes, Golden, ::testing::ValuesIn(goldenCases()), caseName);
INSTANTIATE_TEST_SUITE_P(Scenes, Determinism, ::testing::ValuesIn(goldenCases()), caseName);

// The hash file has one valid line per case and tests/golden/images one PNG per case, nothing
// stale. With FOCAL_UPDATE_GOLDENS=1 stale entries and images are removed instead.
TEST(GoldenFiles, HoldExactlyTheKnownCases) {
    std::vector<std::string> names;
    for (const GoldenCase& c : goldenCases())
        names.push_back(c.name);
    EXPECT_TRUE(focal::test::holdsExactly(focal::test::pinholeGoldens(), names));
}

// Each option a variant case sets changes the pixels of its scene, so the variants test
// something (checked on the stored hashes).
TEST(GoldenFiles, VariantsDifferFromTheirBase) {
    if (focal::test::updatingGoldens())
        GTEST_SKIP() << "goldens are being rewritten";
    EXPECT_TRUE(focal::test::variantsDiffer(focal::test::pinholeGoldens(), kMustDiffer));
}

// The command line renders exactly the golden image: same default view, same PNG encoding,
// whatever its thread count and tile size.
TEST(GoldenCli, RenderWritesTheGoldenImage) {
    if (focal::test::updatingGoldens())
        GTEST_SKIP() << "goldens are being rewritten";
    const fs::path dir =
        fs::temp_directory_path() / ("focal-golden-cli-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const fs::path out = dir / "demo.png";
    const focal::test::ProcessResult r =
        focal::test::runProcess({FOCAL_BINARY, "render", "builtin:demo", "-o", out.string(),
                                 "--width", std::to_string(kWidth), "--height",
                                 std::to_string(kHeight), "--threads", "3", "--tile", "32"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    uint32_t w = 0, h = 0, gw = 0, gh = 0;
    std::vector<uint8_t> cli, golden;
    std::string error;
    ASSERT_TRUE(focal::test::readPngRgba8(out, w, h, cli, error)) << error;
    const fs::path golden_png = focal::test::pinholeGoldens().imagePath("demo");
    ASSERT_TRUE(focal::test::readPngRgba8(golden_png, gw, gh, golden, error)) << error;
    EXPECT_EQ(w, gw);
    EXPECT_EQ(h, gh);
    EXPECT_TRUE(cli == golden) << "focal render wrote " << out.string()
                               << ", which differs from the golden image " << golden_png.string();
    if (!HasFailure())
        fs::remove_all(dir);
}

} // namespace
