// `focal bench`'s sweeps (apps/bench_sweep.h): every setting of every method renders, sets what
// its label says, and the equal-error speed-up has the cheap settings it needs to find a
// method's cheapest way to a target.
#include "apps/bench_sweep.h"
#include "apps/render_command.h"

#include <CLI/CLI.hpp>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <vector>

namespace focal::test {
namespace {

// The stats of `focal render builtin:demo` at 16x12 with the setting's options, as the bench
// parses them (in-process).
nlohmann::json renderSetting(const std::string& method, const Setting& setting,
                             const std::filesystem::path& dir) {
    CLI::App app;
    RenderArgs ra;
    addRenderCommand(app, ra);
    const std::string stats = (dir / "stats.json").string();
    std::vector<std::string> argv = {
        "render",  "builtin:demo", "--width",      "16", "--height",
        "12",      "--method",     method,         "-o", (dir / "o.exr").string(),
        "--stats", stats,          "--no-progress"};
    argv.insert(argv.end(), setting.args.begin(), setting.args.end());
    std::reverse(argv.begin(), argv.end()); // CLI11 parses a vector back to front
    app.parse(argv);
    EXPECT_EQ(runRender(ra), 0) << method << " " << setting.label;
    return nlohmann::json::parse(std::ifstream(stats));
}

const Setting* find(const std::vector<Setting>& all, const std::string& label) {
    const auto it =
        std::find_if(all.begin(), all.end(), [&](const Setting& s) { return s.label == label; });
    return it == all.end() ? nullptr : &*it;
}

TEST(BenchSweep, EverySettingOfEveryMethodRenders) {
    const std::filesystem::path dir =
        std::filesystem::temp_directory_path() / "focal_bench_sweep_test";
    std::filesystem::create_directories(dir);
    for (const char* method : {"pinhole", "accum", "gather", "multiview", "multilayer"})
        for (bool quick : {false, true}) {
            const std::vector<Setting> all = settingsFor(method, quick);
            ASSERT_FALSE(all.empty()) << method;
            std::set<std::string> labels;
            for (const Setting& s : all) {
                EXPECT_TRUE(labels.insert(s.label).second) << method << ": " << s.label;
                const nlohmann::json j = renderSetting(method, s, dir);
                EXPECT_EQ(j["method"], method);
            }
        }
    std::filesystem::remove_all(dir);
}

TEST(BenchSweep, LayeredMethodsReachDownToTheirCheapSettings) {
    const std::filesystem::path dir =
        std::filesystem::temp_directory_path() / "focal_bench_sweep_cheap_test";
    std::filesystem::create_directories(dir);
    // Multiview at four lens samples: the cheapest that reaches SSIM 0.98 on demo.
    const std::vector<Setting> mv = settingsFor("multiview", false);
    const Setting* n4 = find(mv, "spacing=4,N=4");
    ASSERT_NE(n4, nullptr);
    const nlohmann::json a = renderSetting("multiview", *n4, dir);
    EXPECT_EQ(a["params"]["samples"], 4);
    EXPECT_EQ(a["params"]["layer_spacing_px"], 4.0);
    // Multilayer with the paper's box levels.
    const std::vector<Setting> ml = settingsFor("multilayer", false);
    const Setting* box = find(ml, "frags=2,box");
    ASSERT_NE(box, nullptr);
    const nlohmann::json b = renderSetting("multilayer", *box, dir);
    EXPECT_EQ(b["params"]["fragments_per_pixel"], 2);
    EXPECT_EQ(b["params"]["filter"], "box");
    // The studies keep their settings: multilayer's temporal study the last (frags = 8).
    EXPECT_EQ(studySetting("multilayer", false, &Setting::temporal).label, "frags=8");
    EXPECT_EQ(studySetting("multiview", false, &Setting::scaling).label, "spacing=4,N=16");
    std::filesystem::remove_all(dir);
}

} // namespace
} // namespace focal::test
