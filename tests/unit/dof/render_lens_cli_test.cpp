// `focal render` lens options and `focal compare`, run as a child process: exit codes, messages,
// no output file on errors, and the stats the lens records.
#include "support/subprocess.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace focal::test {
namespace {

namespace fs = std::filesystem;

class RenderLensCli : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() /
               ("focal_lens_cli_" +
                std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }

    ProcessResult focal(std::vector<std::string> args) {
        args.insert(args.begin(), FOCAL_BINARY);
        return runProcess(args);
    }
    std::vector<std::string> small(const std::string& out) {
        return {"render", "builtin:demo", "-o", out,         "--width",
                "48",     "--height",     "36", "--threads", "2"};
    }
    std::string path(const std::string& name) const { return (dir_ / name).string(); }
    fs::path dir_;
};

TEST_F(RenderLensCli, NonsenseLensValuesFailWithoutOutput) {
    const std::string out = path("x.exr");
    const std::vector<std::vector<std::string>> bad = {
        {"--method", "accum", "--aperture-radius", "-1"},
        {"--method", "accum", "--aperture-radius", "nan"},
        {"--method", "accum", "--focus-distance", "0"},
        {"--method", "accum", "--focus-distance", "-3"},
        {"--method", "accum", "--focus-distance", "inf"},
        {"--method", "accum", "--focus-distance", "1e9"}, // behind the far plane
        {"--method", "accum", "--fstop", "0", "--focal-length", "50"},
        {"--method", "accum", "--fstop", "2", "--focal-length", "-50"},
        {"--method", "accum", "--focus-pixel", "0,0"}, // sky: nothing to focus on
        {"--method", "accum", "--focus-pixel", "500,5"},
        {"--method", "accum", "--focus-pixel", "1;2"},
        {"--method", "accum", "--aperture-shape", "image"},
        {"--method", "accum", "--aperture-image", path("missing.png")},
    };
    for (const auto& extra : bad) {
        std::vector<std::string> args = small(out);
        args.insert(args.end(), extra.begin(), extra.end());
        const ProcessResult r = focal(args);
        EXPECT_EQ(r.exit_code, 1) << extra.back() << "\n" << r.err;
        EXPECT_EQ(r.err.rfind("focal: error: ", 0), 0u) << r.err;
        EXPECT_FALSE(fs::exists(out)) << extra.back();
    }
}

TEST_F(RenderLensCli, ConflictingOptionsAreUsageErrors) {
    const std::string out = path("x.exr");
    const std::vector<std::vector<std::string>> bad = {
        {"--fstop", "2"}, // needs --focal-length
        {"--aperture-radius", "0.1", "--fstop", "2", "--focal-length", "50"},
        {"--focus-distance", "3", "--focus-pixel", "1,1"},
        {"--yfov", "40", "--focal-length", "50"},
        {"--sensor-height", "24"},
        {"--method", "blur"},
        {"--samples", "0"},
        {"--aperture-blades", "2"},
    };
    for (const auto& extra : bad) {
        std::vector<std::string> args = small(out);
        args.insert(args.end(), extra.begin(), extra.end());
        const ProcessResult r = focal(args);
        EXPECT_EQ(r.exit_code, 2) << extra.front() << "\n" << r.err;
        EXPECT_FALSE(fs::exists(out));
    }
}

TEST_F(RenderLensCli, AccumRecordsTheLensInStats) {
    const std::string out = path("a.exr"), stats = path("a.json"), depth = path("d.exr");
    std::vector<std::string> args = small(out);
    for (const char* a : {"--method", "accum", "--samples", "8", "--fstop", "1.4", "--focal-length",
                          "50", "--focus-pixel", "24,20", "--aperture-blades", "5", "--stats"})
        args.push_back(a);
    args.push_back(stats);
    args.push_back("--depth-out");
    args.push_back(depth);
    const ProcessResult r = focal(args);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    ASSERT_TRUE(fs::exists(out) && fs::exists(depth));
    std::ifstream in(stats);
    const nlohmann::json j = nlohmann::json::parse(in);
    EXPECT_EQ(j["schema"], "focal.render-stats");
    EXPECT_EQ(j["schema_version"], 2);
    EXPECT_NEAR(j["lens"]["aperture_radius"].get<double>(), 0.05 / 2.8, 1e-6);
    EXPECT_EQ(j["lens"]["aperture_source"], "fstop");
    EXPECT_EQ(j["lens"]["focus_source"], "focus-pixel");
    EXPECT_EQ(j["lens"]["aperture_shape"], "polygon");
    EXPECT_EQ(j["lens"]["aperture_blades"], 5);
    EXPECT_NEAR(j["camera"]["yfov_deg"].get<double>(), 26.9915, 1e-3);
    EXPECT_EQ(j["accum"]["samples"], 8);
    EXPECT_TRUE(j["time_ms"].contains("total"));
    for (const char* stage : {"geometry", "binning", "raster", "pinhole", "views", "accumulate"})
        EXPECT_TRUE(j["time_ms"].contains(stage)) << stage;

    // compare: the accum image against itself and against a pinhole render.
    const std::string pin = path("p.exr");
    ASSERT_EQ(focal(small(pin)).exit_code, 0);
    ProcessResult same = focal({"compare", out, out, "--json"});
    ASSERT_EQ(same.exit_code, 0) << same.err;
    const nlohmann::json sj = nlohmann::json::parse(same.out);
    EXPECT_EQ(sj["schema"], "focal.compare");
    EXPECT_EQ(sj["schema_version"], 1);
    EXPECT_TRUE(sj["all"]["psnr_linear_db"].is_null());
    EXPECT_EQ(sj["all"]["ssim"], 1.0);
    ProcessResult text = focal({"compare", out, out});
    EXPECT_NE(text.out.find("inf"), std::string::npos);
    const std::string diff = path("diff.png");
    ProcessResult cmp = focal({"compare", pin, out, "--depth", depth, "--diff", diff, "--json"});
    ASSERT_EQ(cmp.exit_code, 0) << cmp.err;
    const nlohmann::json cj = nlohmann::json::parse(cmp.out);
    EXPECT_GT(cj["all"]["psnr_linear_db"].get<double>(), 5.0);
    EXPECT_LT(cj["all"]["ssim"].get<double>(), 1.0);
    EXPECT_GT(cj["band"]["pixels"].get<double>(), 0.0);
    EXPECT_TRUE(fs::exists(diff));
}

TEST_F(RenderLensCli, CompareErrors) {
    const std::string a = path("a.exr"), b = path("b.exr");
    ASSERT_EQ(focal(small(a)).exit_code, 0);
    std::vector<std::string> args = small(b);
    args[5] = "40"; // width
    ASSERT_EQ(focal(args).exit_code, 0);
    ProcessResult r = focal({"compare", a, b});
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.err.find("same size"), std::string::npos) << r.err;
    // I/O errors exit 2: 1 is kept for "the images are not within the gate".
    r = focal({"compare", a, path("nope.exr")});
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("not found"), std::string::npos) << r.err;
    r = focal({"compare", a, a, "--diff", path("no/such/dir/d.png")});
    EXPECT_EQ(r.exit_code, 2);
    r = focal({"compare", a});
    EXPECT_EQ(r.exit_code, 2);
}

TEST_F(RenderLensCli, SkippedAccumSaysSo) {
    const std::string out = path("s.exr"), stats = path("s.json");
    std::vector<std::string> args = small(out);
    for (const char* a : {"--method", "accum", "--aperture-radius", "0", "--stats"})
        args.push_back(a);
    args.push_back(stats);
    const ProcessResult r = focal(args);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    std::ifstream in(stats);
    const nlohmann::json j = nlohmann::json::parse(in);
    EXPECT_EQ(j["accum"]["skipped"], true);
    EXPECT_EQ(j["accum"]["renders"], 1);
    EXPECT_NE(r.err.find("rendered once"), std::string::npos);
}

} // namespace
} // namespace focal::test
