// `focal bench --quick` (issue 9): the CI smoke run of the run-time-against-error benchmark.
// Runs the binary into a temporary folder and checks that results.csv, results.json,
// temporal.csv and index.html exist and parse: the CSV header has the documented columns, there
// is one main row per scene x method x setting, and PSNR is finite wherever the method is not
// the reference itself. No timing assertions (speed belongs in the benchmark's own output).
#include "support/subprocess.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <unistd.h>
#include <vector>

namespace {

namespace fs = std::filesystem;
using focal::test::runProcess;
using focal::test::splitLines;

std::string readAll(const fs::path& p) {
    std::ifstream f(p);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
}

std::vector<std::string> splitCsv(const std::string& line) {
    std::vector<std::string> cells;
    std::string cell;
    bool quoted = false;
    for (char c : line) {
        if (c == '"')
            quoted = !quoted;
        else if (c == ',' && !quoted) {
            cells.push_back(cell);
            cell.clear();
        } else
            cell += c;
    }
    cells.push_back(cell);
    return cells;
}

class BenchQuick : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() / ("focal_bench_quick_" + std::to_string(::getpid()));
        fs::remove_all(dir_);
    }
    void TearDown() override {
        if (!HasFailure())
            fs::remove_all(dir_);
    }
    fs::path dir_;
};

TEST_F(BenchQuick, WritesParsableResults) {
    const focal::test::ProcessResult r =
        runProcess({FOCAL_BINARY, "bench", "--quick", "-o", dir_.string()});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.err.find("focal: bench ["), std::string::npos) << "no progress line:\n" << r.err;

    // results.csv: the header names the documented columns; every line has as many cells.
    const std::vector<std::string> lines = splitLines(readAll(dir_ / "results.csv"));
    ASSERT_GE(lines.size(), 2u);
    const std::vector<std::string> header = splitCsv(lines[0]);
    std::map<std::string, size_t> col;
    for (size_t i = 0; i < header.size(); ++i)
        col[header[i]] = i;
    for (const char* name : {"scene",
                             "study",
                             "method",
                             "setting",
                             "width",
                             "height",
                             "threads",
                             "repeat",
                             "ms_median",
                             "ms_min",
                             "ms_max",
                             "peak_rss_mib",
                             "peak_rss_added_mib",
                             "psnr_srgb_db",
                             "ssim",
                             "band_psnr_srgb_db",
                             "band_ssim",
                             "reference_samples",
                             "reference_key",
                             "pareto"})
        EXPECT_TRUE(col.count(name)) << "results.csv has no column " << name;
    for (size_t i = 1; i < lines.size(); ++i)
        EXPECT_EQ(splitCsv(lines[i]).size(), header.size()) << "line " << i << ": " << lines[i];

    // results.json: one main row per scene x method x setting (quick: 2 scenes; pinhole 1,
    // accum 4, gather 1, multilayer 1, multiview 1 setting), plus scaling rows.
    const nlohmann::json doc = nlohmann::json::parse(readAll(dir_ / "results.json"));
    ASSERT_TRUE(doc["rows"].is_array());
    EXPECT_EQ(doc["reference_samples"], 64);
    std::map<std::string, std::set<std::string>> settings_of;
    size_t main_rows = 0, scaling_rows = 0;
    for (const auto& row : doc["rows"]) {
        if (row["study"] == "scaling") {
            ++scaling_rows;
            EXPECT_GT(row["parallel_efficiency"].get<double>(), 0.0);
            // The thread counts take turns over three rounds; the row is the median round.
            std::vector<double> rounds = row["scaling_rounds_ms"].get<std::vector<double>>();
            ASSERT_EQ(rounds.size(), 3u);
            std::sort(rounds.begin(), rounds.end());
            EXPECT_EQ(row["ms_median"].get<double>(), rounds[1]);
            continue;
        }
        ++main_rows;
        const std::string key =
            row["scene"].get<std::string>() + " " + row["method"].get<std::string>();
        EXPECT_TRUE(settings_of[key].insert(row["setting"].get<std::string>()).second)
            << "duplicate row " << key << " " << row["setting"];
        EXPECT_GE(row["ms_max"].get<double>(), row["ms_min"].get<double>());
        EXPECT_GT(row["peak_rss_mib"].get<double>(), 0.0);
        // The scene load, from the render's --stats (a built-in scene is generated: > 0 ms).
        EXPECT_GT(row["load_ms"].get<double>(), 0.0) << key;
        // Only accum with the reference's own settings may match it exactly (null PSNR).
        if (row["method"] != "accum") {
            ASSERT_TRUE(row["psnr_srgb_db"].is_number()) << key;
            EXPECT_TRUE(std::isfinite(row["psnr_srgb_db"].get<double>())) << key;
            EXPECT_GT(row["ssim"].get<double>(), 0.0) << key;
        }
        EXPECT_TRUE(fs::exists(dir_ / row["image"].get<std::string>()));
        EXPECT_TRUE(fs::exists(dir_ / row["diff_image"].get<std::string>()));
    }
    EXPECT_EQ(main_rows, 2u * 8u);
    EXPECT_EQ(settings_of.size(), 2u * 5u);
    EXPECT_GE(scaling_rows, 2u * 5u);

    // Temporal stability: one row per method, with the reference's flicker beside it.
    ASSERT_TRUE(doc["temporal"].is_array());
    EXPECT_EQ(doc["temporal"].size(), 5u);
    for (const auto& t : doc["temporal"])
        EXPECT_TRUE(t["flicker"].is_number() && t["reference_flicker"].is_number());

    // Equal-error speed-up (issue 18): per scene, per target, per layered method, render and
    // process time, each a ratio or a reason there is none; the whole-process time was measured.
    const nlohmann::json& eq = doc["equal_error"];
    ASSERT_TRUE(eq["scenes"].is_array());
    ASSERT_EQ(eq["scenes"].size(), 2u);
    EXPECT_EQ(eq["methods"], nlohmann::json({"gather", "multilayer", "multiview"}));
    for (const auto& scene : eq["scenes"]) {
        ASSERT_EQ(scene["targets"].size(), 4u);
        for (const auto& target : scene["targets"])
            for (const char* m : {"gather", "multilayer", "multiview"})
                for (const char* kind : {"render", "process"}) {
                    const nlohmann::json& c = target["methods"][m][kind];
                    const std::string what = scene["scene"].get<std::string>() + " " +
                                             target["target"].get<std::string>() + " " + m + " " +
                                             kind;
                    EXPECT_TRUE(c["accum_ms"].is_number()) << what;
                    EXPECT_EQ(c["ratio"].is_number(), c["bound"] != "method_not_reached") << what;
                    if (c["ratio"].is_number()) {
                        EXPECT_NEAR(c["ratio"].get<double>(),
                                    c["accum_ms"].get<double>() / c["method_ms"].get<double>(),
                                    1e-9)
                            << what;
                    }
                }
    }
    for (const auto& row : doc["rows"])
        if (row["study"] == "main" && row["method"] != "pinhole") {
            EXPECT_EQ(row["process_runs"], 1) << row["method"] << " " << row["setting"];
            EXPECT_GT(row["process_ms_median"].get<double>(), 0.0);
        }
    EXPECT_NE(r.out.find("Speed-up over accum at equal error"), std::string::npos) << r.out;
    EXPECT_TRUE(fs::exists(dir_ / "equal_error.md"));

    EXPECT_TRUE(fs::exists(dir_ / "index.html"));
    EXPECT_TRUE(fs::exists(dir_ / "temporal.csv"));
    // Plots exist unless gnuplot is missing, which the results say.
    if (!doc.contains("plot_note")) {
        EXPECT_TRUE(fs::exists(dir_ / "plots" / "bench_demo.png"));
        EXPECT_TRUE(fs::exists(dir_ / "plots" / "bench_railing.png"));
    }

    // A second run reuses the cached references.
    const focal::test::ProcessResult again =
        runProcess({FOCAL_BINARY, "bench", "--quick", "--scenes", "builtin:demo", "--methods",
                    "pinhole", "--no-scaling", "--temporal-frames", "0", "-o", dir_.string()});
    ASSERT_EQ(again.exit_code, 0) << again.err;
    const nlohmann::json doc2 = nlohmann::json::parse(readAll(dir_ / "results.json"));
    EXPECT_EQ(doc2["scenes"][0]["reference_cached"], true);
}

TEST(BenchErrors, UnknownSceneOrMethodIsAUsageError) {
    const fs::path dir =
        fs::temp_directory_path() / ("focal_bench_err_" + std::to_string(::getpid()));
    focal::test::ProcessResult r = runProcess(
        {FOCAL_BINARY, "bench", "--quick", "--scenes", "builtin:nope", "-o", dir.string()});
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("focal: error:"), std::string::npos) << r.err;
    r = runProcess({FOCAL_BINARY, "bench", "--quick", "--methods", "magic", "-o", dir.string()});
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("unknown method 'magic'"), std::string::npos) << r.err;
    fs::remove_all(dir);
}

} // namespace
