// Tests of the `focal` command line (apps/cli.h, issue 2 item 9), run as a subprocess
// (FOCAL_BINARY) in a per-test temporary folder: help text, exit codes (0 success, 1 failure,
// 2 usage error), one `focal: error:` line on stderr, and no output file left by a failure.
#include "apps/image_io.h"
#include "support/subprocess.h"

#include <raster/scene.h>
#include <scenes/builtin.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <unistd.h>
#include <vector>

namespace {

namespace fs = std::filesystem;
using focal::test::ProcessResult;

const std::string kErrorPrefix = "focal: error: ";

bool contains(const std::string& text, const std::string& needle) {
    return text.find(needle) != std::string::npos;
}

std::string dataPath(const std::string& relative) {
    return std::string(FOCAL_TEST_DATA_DIR) + "/" + relative;
}

// Runs focal in a fresh temporary folder that is removed after a passing test (and kept, with
// its path printed, after a failing one).
class Cli : public ::testing::Test {
protected:
    void SetUp() override {
        const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
        std::string name = std::string(info->test_suite_name()) + "." + info->name();
        std::replace_if(
            name.begin(), name.end(), [](char c) { return !std::isalnum((unsigned char)c); }, '_');
        dir_ = fs::temp_directory_path() / ("focal-cli-" + std::to_string(::getpid()) + "-" + name);
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override {
        if (HasFailure())
            std::printf("kept the test folder %s\n", dir_.c_str());
        else
            fs::remove_all(dir_);
    }

    ProcessResult focal(const std::vector<std::string>& args) const {
        std::vector<std::string> argv{FOCAL_BINARY};
        argv.insert(argv.end(), args.begin(), args.end());
        return focal::test::runProcess(argv, dir_.string());
    }

    // Every file in the test folder (recursively), relative to it.
    std::vector<std::string> files() const {
        std::vector<std::string> names;
        for (const fs::directory_entry& e : fs::recursive_directory_iterator(dir_))
            names.push_back(fs::relative(e.path(), dir_).string());
        std::sort(names.begin(), names.end());
        return names;
    }

    fs::path dir_;
};

// The run failed with `code` and printed exactly one line, "focal: error: ...", on stderr.
::testing::AssertionResult failedWithOneErrorLine(const ProcessResult& r, int code) {
    const std::vector<std::string> lines = focal::test::splitLines(r.err);
    if (r.exit_code != code)
        return ::testing::AssertionFailure()
               << "exit code " << r.exit_code << " instead of " << code << "; stderr:\n"
               << r.err;
    if (lines.size() != 1 || lines[0].rfind(kErrorPrefix, 0) != 0)
        return ::testing::AssertionFailure()
               << "stderr is not one '" << kErrorPrefix << "...' line:\n"
               << r.err;
    return ::testing::AssertionSuccess();
}

// --- help -----------------------------------------------------------------------------------

TEST_F(Cli, HelpListsTheSubcommands) {
    for (const char* flag : {"--help", "-h"}) {
        const ProcessResult r = focal({flag});
        EXPECT_EQ(r.exit_code, 0) << flag << "\n" << r.err;
        EXPECT_TRUE(contains(r.out, "Usage:")) << r.out;
        EXPECT_TRUE(contains(r.out, "render")) << r.out;
        EXPECT_TRUE(contains(r.out, "info")) << r.out;
    }
}

TEST_F(Cli, VersionExitsZero) {
    const ProcessResult r = focal({"--version"});
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_TRUE(contains(r.out, "focal ")) << r.out;
}

// The help block of `option`: its line in `focal render --help` and the description lines that
// follow, up to the next option.
std::string helpBlock(const std::string& help, const std::string& option) {
    const std::vector<std::string> lines = focal::test::splitLines(help);
    std::string block;
    for (size_t i = 0; i < lines.size(); ++i) {
        const std::regex header("^  " + option + "([ ,=]|$).*");
        if (!std::regex_match(lines[i], header))
            continue;
        block = lines[i];
        for (size_t j = i + 1;
             j < lines.size() && lines[j].rfind("  -", 0) != 0 && !lines[j].empty(); ++j)
            block += "\n" + lines[j];
        break;
    }
    return block;
}

TEST_F(Cli, RenderHelpListsEveryOptionWithItsDefault) {
    const ProcessResult r = focal({"render", "--help"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    // Option -> a regular expression its help block must match: the default where there is
    // one, else only the option's presence.
    const std::pair<const char*, const char*> options[] = {
        {"-o,--output", "REQUIRED"},
        {"--width", "=800\\b"},
        {"--height", "=600\\b"},
        {"--camera", "\\[default: 0\\]"},
        {"--eye", ""},
        {"--target", ""},
        {"--up", "\\[default: 0,1,0\\]"},
        {"--yfov", "\\[default: "},
        {"--near", ""},
        {"--far", "0 = infinite"},
        {"--threads", "=[0-9]+\\b"}, // the machine's hardware concurrency
        {"--tile", "=64\\b"},
        {"--method", "=pinhole\\b"},
        {"--stats", ""},
        {"--repeat", "=1\\b"},
        {"--depth-out", ""},
        {"--depth-format", "=float32\\b"},
        {"--shading", "=material\\b"},
        {"--texture-filter", "=sampler\\b"},
        {"--memory-budget", "=auto\\b"},
        {"--dry-run", ""},
    };
    EXPECT_TRUE(contains(r.out, "scene")) << r.out;
    for (const auto& [option, pattern] : options) {
        const std::string block = helpBlock(r.out, option);
        EXPECT_FALSE(block.empty()) << option << " is missing from focal render --help:\n" << r.out;
        EXPECT_TRUE(std::regex_search(block, std::regex(pattern)))
            << option << " does not show /" << pattern << "/ in:\n"
            << block;
    }
}

// --- usage errors: exit 2, one line, nothing written -----------------------------------------

struct UsageCase {
    const char* name;
    std::vector<std::string> args;
};

void PrintTo(const UsageCase& c, std::ostream* os) {
    *os << c.name;
}

class CliUsageError : public Cli, public ::testing::WithParamInterface<UsageCase> {};

TEST_P(CliUsageError, ExitsTwoWithOneErrorLine) {
    const ProcessResult r = focal(GetParam().args);
    EXPECT_TRUE(failedWithOneErrorLine(r, 2));
    EXPECT_TRUE(files().empty()) << ::testing::PrintToString(files());
}

std::vector<std::string> renderArgs(std::vector<std::string> extra) {
    std::vector<std::string> args{"render",  "builtin:demo", "-o",       "out.png",
                                  "--width", "32",           "--height", "24"};
    args.insert(args.end(), extra.begin(), extra.end());
    return args;
}

std::string usageCaseName(const ::testing::TestParamInfo<UsageCase>& p) {
    return p.param.name;
}

INSTANTIATE_TEST_SUITE_P(
    Cases, CliUsageError,
    ::testing::Values(
        UsageCase{"no_subcommand", {}}, UsageCase{"unknown_subcommand", {"paint"}},
        UsageCase{"unknown_option", renderArgs({"--bogus"})},
        UsageCase{"missing_output", {"render", "builtin:demo"}},
        UsageCase{"missing_scene", {"render", "-o", "out.png"}},
        UsageCase{"width_not_a_number", renderArgs({"--width", "abc"})},
        UsageCase{"width_zero", renderArgs({"--width", "0"})},
        UsageCase{"width_negative", renderArgs({"--width", "-5"})},
        UsageCase{"height_too_large", renderArgs({"--height", "100000"})},
        UsageCase{"tile_too_small", renderArgs({"--tile", "4"})},
        UsageCase{"tile_not_multiple_of_8", renderArgs({"--tile", "12"})},
        UsageCase{"tile_not_a_number", renderArgs({"--tile", "big"})},
        UsageCase{"threads_negative", renderArgs({"--threads", "-1"})},
        UsageCase{"method_unknown", renderArgs({"--method", "unknown"})},
        UsageCase{"depth_format_unknown", renderArgs({"--depth-format", "half"})},
        UsageCase{"shading_unknown", renderArgs({"--shading", "glossy"})},
        UsageCase{"texture_filter_unknown", renderArgs({"--texture-filter", "cubic"})},
        UsageCase{"repeat_zero", renderArgs({"--repeat", "0"})},
        UsageCase{"traversal_unknown",
                  renderArgs({"--method", "multiview", "--traversal", "march"})},
        UsageCase{"thickness_not_a_number",
                  renderArgs({"--method", "multiview", "--thickness", "thin"})},
        UsageCase{"thickness_zero", renderArgs({"--method", "multiview", "--thickness", "0"})},
        UsageCase{"bound_init_unknown",
                  renderArgs({"--method", "multiview", "--bound-init", "yes"})},
        UsageCase{"level_filter_unknown",
                  renderArgs({"--method", "multilayer", "--level-filter", "disc"})},
        UsageCase{"aperture_grids_not_numbers",
                  renderArgs({"--method", "multilayer", "--aperture-grids", "four"})},
        UsageCase{"memory_budget_unknown_unit", renderArgs({"--memory-budget", "8X"})},
        UsageCase{"memory_budget_below_1mib", renderArgs({"--memory-budget", "100K"})},
        UsageCase{"memory_budget_over_100_percent", renderArgs({"--memory-budget", "150%"})},
        UsageCase{"memory_budget_not_a_number", renderArgs({"--memory-budget", "lots"})},
        UsageCase{"info_without_scene", {"info"}}),
    usageCaseName);

// --- failures: exit 1, one line naming the file, nothing written -----------------------------

TEST_F(Cli, MissingSceneFileFailsWithOneLineNamingIt) {
    const ProcessResult r = focal({"render", "missing.gltf", "-o", "x.png"});
    EXPECT_TRUE(failedWithOneErrorLine(r, 1));
    EXPECT_TRUE(contains(r.err, "missing.gltf")) << r.err;
    EXPECT_TRUE(files().empty()) << ::testing::PrintToString(files());
}

// Issue 23: the hostile fixtures crashed `focal info` as well as `focal render`.
TEST_F(Cli, InfoRejectsHostileFilesWithOneLine) {
    for (const char* name :
         {"deep_nesting.gltf", "zero_accessors_per_file.gltf", "buffer_uri_directory.gltf"}) {
        const std::string path = dataPath(std::string("gltf/bad/") + name);
        const ProcessResult r = focal({"info", path});
        EXPECT_TRUE(failedWithOneErrorLine(r, 1)) << name;
        EXPECT_TRUE(contains(r.err, path)) << r.err;
    }
}

TEST_F(Cli, DryRunChecksTheRequestAndWritesNothing) {
    const ProcessResult ok = focal(renderArgs({"--method", "multiview", "--dry-run"}));
    EXPECT_EQ(ok.exit_code, 0) << ok.err;
    EXPECT_TRUE(contains(ok.out, "focal: dry run: --method multiview at 32x24 with 64 samples"))
        << ok.out;
    EXPECT_TRUE(files().empty()) << ::testing::PrintToString(files());
    // The same request under a budget it exceeds fails the same way a real run does.
    const ProcessResult over =
        focal({"render", "builtin:demo", "-o", "out.png", "--method", "accum", "--dry-run",
               "--memory-budget", "1M", "--width", "1024", "--height", "1024"});
    EXPECT_TRUE(failedWithOneErrorLine(over, 1));
    EXPECT_TRUE(contains(over.err, "--method accum at 1024x1024 with 64 samples needs 72 MiB, "
                                   "more than the memory budget of 1.0 MiB (--memory-budget)"))
        << over.err;
}

TEST_F(Cli, UnknownBuiltinSceneFailsWithOneLine) {
    const ProcessResult r = focal({"render", "builtin:nope", "-o", "x.png"});
    EXPECT_TRUE(failedWithOneErrorLine(r, 1));
    EXPECT_TRUE(contains(r.err, "nope")) << r.err;
    EXPECT_TRUE(files().empty()) << ::testing::PrintToString(files());
}

TEST_F(Cli, MissingOutputFolderIsAnError) {
    const ProcessResult r = focal({"render", "builtin:demo", "-o", "no_such_folder/x.png",
                                   "--width", "16", "--height", "16"});
    EXPECT_TRUE(failedWithOneErrorLine(r, 1));
    EXPECT_TRUE(contains(r.err, "no_such_folder")) << r.err;
    EXPECT_TRUE(files().empty()) << ::testing::PrintToString(files());
}

// Atomic writes: a write that fails leaves neither the file nor its temporary behind.
TEST_F(Cli, FailedWriteOfAnUnsupportedFormatLeavesNothing) {
    const ProcessResult r =
        focal({"render", "builtin:demo", "-o", "out.xyz", "--width", "16", "--height", "16"});
    EXPECT_TRUE(failedWithOneErrorLine(r, 1));
    EXPECT_TRUE(contains(r.err, "out.xyz")) << r.err;
    EXPECT_TRUE(files().empty()) << ::testing::PrintToString(files());
}

TEST_F(Cli, FailedRenameOntoAFolderLeavesNoTemporary) {
    fs::create_directory(dir_ / "taken.png");
    const ProcessResult r =
        focal({"render", "builtin:demo", "-o", "taken.png", "--width", "16", "--height", "16"});
    EXPECT_TRUE(failedWithOneErrorLine(r, 1));
    EXPECT_TRUE(contains(r.err, "taken.png")) << r.err;
    EXPECT_EQ(files(), std::vector<std::string>{"taken.png"});
}

TEST_F(Cli, DepthOutputMustBeExr) {
    const ProcessResult r = focal({"render", "builtin:demo", "-o", "out.png", "--depth-out",
                                   "depth.png", "--width", "16", "--height", "16"});
    EXPECT_TRUE(failedWithOneErrorLine(r, 1));
    EXPECT_TRUE(contains(r.err, "depth.png")) << r.err;
    EXPECT_TRUE(files().empty()) << ::testing::PrintToString(files());
}

TEST_F(Cli, BadMultilayerSettingsNameTheOption) {
    // Values outside the settings table's range or spelling: rejected while parsing (a usage
    // error, exit 2), one line naming the option.
    for (const std::vector<std::string>& extra :
         {std::vector<std::string>{"--additive-gap", "-1"},
          std::vector<std::string>{"--additive-gap", "wide"},
          std::vector<std::string>{"--aperture-grids", "4,9"}}) {
        std::vector<std::string> args = renderArgs({"--method", "multilayer"});
        args.insert(args.end(), extra.begin(), extra.end());
        const ProcessResult r = focal(args);
        EXPECT_TRUE(failedWithOneErrorLine(r, 2)) << extra[0] << " " << extra[1];
        EXPECT_TRUE(contains(r.err, extra[0])) << r.err;
        EXPECT_TRUE(files().empty()) << ::testing::PrintToString(files());
    }
}

// Every malformed fixture in tests/data/gltf/bad fails cleanly (a name per fixture: fixture
// file name with '.' as '_').
std::vector<std::string> badFixtures() {
    std::vector<std::string> names;
    for (const fs::directory_entry& e : fs::directory_iterator(dataPath("gltf/bad")))
        if (e.is_regular_file())
            names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
}

class CliBadFixture : public Cli, public ::testing::WithParamInterface<std::string> {};

TEST_P(CliBadFixture, FailsWithOneLineNamingItAndWritesNothing) {
    const std::string path = dataPath("gltf/bad/" + GetParam());
    const ProcessResult r =
        focal({"render", path, "-o", "OUT.png", "--width", "32", "--height", "24"});
    EXPECT_TRUE(failedWithOneErrorLine(r, 1));
    EXPECT_TRUE(contains(r.err, GetParam())) << r.err;
    EXPECT_TRUE(files().empty()) << ::testing::PrintToString(files());
}

std::string fixtureName(const ::testing::TestParamInfo<std::string>& p) {
    std::string name = p.param;
    std::replace(name.begin(), name.end(), '.', '_');
    return name;
}

INSTANTIATE_TEST_SUITE_P(Fixtures, CliBadFixture, ::testing::ValuesIn(badFixtures()), fixtureName);

TEST(CliFixtures, TheBadFolderIsNotEmpty) {
    EXPECT_GE(badFixtures().size(), 10u);
}

// --- info -------------------------------------------------------------------------------------

TEST_F(Cli, InfoDescribesABuiltinScene) {
    const ProcessResult r = focal({"info", "builtin:demo"});
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_TRUE(contains(r.out, "triangles")) << r.out;
    EXPECT_TRUE(r.err.empty()) << r.err;
}

TEST_F(Cli, InfoDescribesAGltfFile) {
    const ProcessResult r = focal({"info", dataPath("gltf/valid/textured_quad.gltf")});
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_TRUE(contains(r.out, "triangles: 2")) << r.out;
}

TEST_F(Cli, InfoDecodesWhatShadingSamplesAndReportsLoadTime) {
    // Only the base colour of unsampled_maps.gltf is sampled by any shading mode: its broken
    // normal map is not decoded unless --all-images asks for every image.
    const std::string path = dataPath("gltf/valid/unsampled_maps.gltf");
    const ProcessResult r = focal({"info", path, "--threads", "2"});
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_TRUE(contains(r.out, "images: 4 (3 not decoded: no shading mode samples them)"))
        << r.out;
    EXPECT_TRUE(contains(r.out, "\"broken_normal\": not decoded, used as metallic-roughness, "
                                "normal\n"))
        << r.out;
    EXPECT_TRUE(contains(r.out, "load: ")) << r.out;
    EXPECT_TRUE(contains(r.out, "1 images decoded, 3 skipped")) << r.out;

    const ProcessResult all = focal({"info", path, "--all-images", "--threads", "0"});
    EXPECT_EQ(all.exit_code, 0) << all.err;
    EXPECT_TRUE(contains(all.out, "images: 4\n")) << all.out;
    EXPECT_TRUE(contains(all.out, "image 1 (broken_normal) cannot be decoded")) << all.out;
    EXPECT_TRUE(contains(all.out, "2 images decoded, 0 skipped")) << all.out;
}

TEST_F(Cli, RenderStatsReportTheLoad) {
    const ProcessResult r =
        focal({"render", dataPath("gltf/valid/unsampled_maps.gltf"), "-o", "out.exr", "--stats",
               "s.json", "--width", "16", "--height", "16", "--shading", "lit"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    std::ifstream in(dir_ / "s.json");
    const nlohmann::json j = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
    ASSERT_FALSE(j.is_discarded()) << "s.json is not valid JSON";
    ASSERT_TRUE(j.contains("load")) << j.dump(2);
    const nlohmann::json& load = j["load"];
    for (const char* key : {"total", "parse", "images", "decode", "mipmaps", "scene"})
        EXPECT_TRUE(load["time_ms"][key].is_number()) << key << " " << load.dump(2);
    EXPECT_EQ(load.value("images_decoded", -1), 1) << load.dump(2);
    EXPECT_EQ(load.value("images_skipped", -1), 3) << load.dump(2);
    EXPECT_TRUE(j["time_ms"]["total"].is_number()) << j.dump(2);
}

TEST_F(Cli, InfoOfAMissingFileFailsWithOneLine) {
    const ProcessResult r = focal({"info", "missing.glb"});
    EXPECT_TRUE(failedWithOneErrorLine(r, 1));
    EXPECT_TRUE(contains(r.err, "missing.glb")) << r.err;
}

// --- successful renders -------------------------------------------------------------------------

uint64_t countTriangles(const raster::Scene& scene) {
    uint64_t n = 0;
    for (const raster::Instance& inst : scene.instances)
        for (const raster::Primitive& prim : scene.meshes[inst.mesh].primitives)
            n += prim.indices.size() / 3;
    return n;
}

TEST_F(Cli, RenderWritesImageDepthAndStats) {
    const ProcessResult r =
        focal({"render", "builtin:railing", "-o", "out.exr", "--depth-out", "d.exr", "--stats",
               "s.json", "--repeat", "3", "--width", "96", "--height", "64"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(files(), (std::vector<std::string>{"d.exr", "out.exr", "s.json"}));

    std::ifstream in(dir_ / "s.json");
    const nlohmann::json j = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
    ASSERT_FALSE(j.is_discarded()) << "s.json is not valid JSON";
    ASSERT_TRUE(j.contains("time_ms") && j["time_ms"].contains("total")) << j.dump(2);
    EXPECT_TRUE(j["time_ms"]["total"].is_number()) << j.dump(2);
    ASSERT_TRUE(j.contains("runs") && j["runs"].is_array()) << j.dump(2);
    EXPECT_EQ(j["runs"].size(), 3u);
    for (const nlohmann::json& run : j["runs"])
        EXPECT_TRUE(run.contains("total") && run["total"].is_number()) << run.dump();
    raster::Result<raster::Scene> scene = scenes::makeBuiltinScene("railing");
    ASSERT_TRUE(scene.ok());
    ASSERT_TRUE(j.contains("triangles")) << j.dump(2);
    EXPECT_EQ(j["triangles"].value("in", uint64_t(0)), countTriangles(*scene)) << j.dump(2);
    for (const char* key : {"culled", "clipped", "setup"})
        EXPECT_TRUE(j["triangles"].contains(key)) << key;
    EXPECT_GT(j["triangles"].value("setup", uint64_t(0)), 0u);
    EXPECT_EQ(j.value("width", 0), 96);
    EXPECT_EQ(j.value("height", 0), 64);
    EXPECT_EQ(j.value("repeat", 0), 3);

    raster::Result<focal::ImageData> color = focal::readImage((dir_ / "out.exr").string());
    ASSERT_TRUE(color.ok()) << color.status().message();
    EXPECT_EQ(color->width, 96u);
    EXPECT_EQ(color->height, 64u);
    EXPECT_EQ(color->channels, 4u);
    raster::Result<focal::ImageData> depth = focal::readImage((dir_ / "d.exr").string());
    ASSERT_TRUE(depth.ok()) << depth.status().message();
    EXPECT_EQ(depth->width, 96u);
    EXPECT_EQ(depth->height, 64u);
    EXPECT_EQ(depth->channels, 1u);
    // Linear depth: distances along the view axis, positive wherever something was drawn.
    const size_t positive = size_t(std::count_if(depth->pixels.begin(), depth->pixels.end(),
                                                 [](float d) { return d > 0.0f; }));
    EXPECT_GT(positive, depth->pixels.size() / 2);
}

TEST_F(Cli, PngOutputReadsBackWithItsSize) {
    const ProcessResult r =
        focal({"render", "builtin:demo", "-o", "out.png", "--width", "40", "--height", "30"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_TRUE(r.err.empty()) << r.err;
    EXPECT_TRUE(contains(r.out, "out.png")) << r.out;
    EXPECT_EQ(files(), std::vector<std::string>{"out.png"});
    raster::Result<focal::ImageData> image = focal::readImage((dir_ / "out.png").string());
    ASSERT_TRUE(image.ok()) << image.status().message();
    EXPECT_EQ(image->width, 40u);
    EXPECT_EQ(image->height, 30u);
    EXPECT_EQ(image->channels, 4u);
    // Not blank: the demo scene has ground and sky.
    const auto [lo, hi] = std::minmax_element(image->pixels.begin(), image->pixels.end());
    EXPECT_LT(*lo, *hi);
}

TEST_F(Cli, RenderOfAValidGltfFileSucceeds) {
    const ProcessResult r = focal({"render", dataPath("gltf/valid/triangle.glb"), "-o", "t.exr",
                                   "--width", "24", "--height", "16", "--threads", "0"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    raster::Result<focal::ImageData> image = focal::readImage((dir_ / "t.exr").string());
    ASSERT_TRUE(image.ok()) << image.status().message();
    EXPECT_EQ(image->width, 24u);
    EXPECT_EQ(image->height, 16u);
}

} // namespace
