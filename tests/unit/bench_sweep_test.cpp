// `focal bench`'s sweeps (apps/bench_sweep.h): every setting of every method renders, sets what
// its label says, and the equal-error speed-up has the cheap settings it needs to find a
// method's cheapest way to a target.
#include "apps/bench_render.h"
#include "apps/bench_sweep.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <set>
#include <string>
#include <vector>

namespace focal::test {
namespace {

// The stats of `focal render builtin:demo` at 16x12 with the setting's options, rendered as the
// bench renders them (renderInMemory).
nlohmann::ordered_json renderSetting(const std::string& method, const Setting& setting) {
    std::vector<std::string> args = {"builtin:demo", "--width",  "16",  "--height",
                                     "12",           "--method", method};
    args.insert(args.end(), setting.args.begin(), setting.args.end());
    const RenderRun r = renderInMemory(args, nullptr);
    EXPECT_EQ(r.exit_code, 0) << method << " " << setting.label;
    return r.stats;
}

const Setting* find(const std::vector<Setting>& all, const std::string& label) {
    const auto it =
        std::find_if(all.begin(), all.end(), [&](const Setting& s) { return s.label == label; });
    return it == all.end() ? nullptr : &*it;
}

TEST(BenchSweep, EverySettingOfEveryMethodRenders) {
    for (const char* method : {"pinhole", "accum", "gather", "multiview", "multilayer"})
        for (bool quick : {false, true}) {
            const std::vector<Setting> all = settingsFor(method, quick);
            ASSERT_FALSE(all.empty()) << method;
            std::set<std::string> labels;
            for (const Setting& s : all) {
                EXPECT_TRUE(labels.insert(s.label).second) << method << ": " << s.label;
                const nlohmann::ordered_json j = renderSetting(method, s);
                EXPECT_EQ(j["method"], method);
            }
        }
}

TEST(BenchSweep, LayeredMethodsReachDownToTheirCheapSettings) {
    // Multiview at four lens samples: the cheapest that reaches SSIM 0.98 on demo.
    const std::vector<Setting> mv = settingsFor("multiview", false);
    const Setting* n4 = find(mv, "spacing=4,N=4");
    ASSERT_NE(n4, nullptr);
    const nlohmann::ordered_json a = renderSetting("multiview", *n4);
    EXPECT_EQ(a["params"]["samples"], 4);
    EXPECT_EQ(a["params"]["layer_spacing_px"], 4.0);
    // Multilayer with the paper's box levels.
    const std::vector<Setting> ml = settingsFor("multilayer", false);
    const Setting* box = find(ml, "frags=2,box");
    ASSERT_NE(box, nullptr);
    const nlohmann::ordered_json b = renderSetting("multilayer", *box);
    EXPECT_EQ(b["params"]["fragments_per_pixel"], 2);
    EXPECT_EQ(b["params"]["filter"], "box");
    // The studies keep their settings: multilayer's temporal study the last (frags = 8).
    EXPECT_EQ(studySetting("multilayer", false, &Setting::temporal).label, "frags=8");
    EXPECT_EQ(studySetting("multiview", false, &Setting::scaling).label, "spacing=4,N=16");
}

} // namespace
} // namespace focal::test
