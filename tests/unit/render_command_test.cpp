// `focal render` parsed and run in-process, as `focal bench` does it: a method's options start
// from their defaults on every new command line (they used to keep the previous parse's values).
#include "apps/render_command.h"

#include <CLI/CLI.hpp>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace focal::test {
namespace {

nlohmann::json renderStats(std::vector<std::string> args, const std::string& dir) {
    CLI::App app;
    RenderArgs ra;
    addRenderCommand(app, ra);
    const std::string stats = dir + "/stats.json";
    std::vector<std::string> argv = {"render",   "builtin:demo", "--width",      "16",
                                     "--height", "12",           "-o",           dir + "/out.png",
                                     "--stats",  stats,          "--no-progress"};
    argv.insert(argv.end(), args.begin(), args.end());
    std::reverse(argv.begin(), argv.end()); // CLI11 parses a vector back to front
    app.parse(argv);
    EXPECT_EQ(runRender(ra), 0);
    return nlohmann::json::parse(std::ifstream(stats));
}

TEST(RenderCommand, MethodOptionsStartFromTheirDefaultsOnEveryParse) {
    const std::filesystem::path dir =
        std::filesystem::temp_directory_path() / "focal_render_command_test";
    std::filesystem::create_directories(dir);
    const nlohmann::json first = renderStats(
        {"--method", "multiview", "--samples", "4", "--layers", "8", "--thickness", "inf"},
        dir.string());
    EXPECT_EQ(first["params"]["layers"], 8);
    EXPECT_EQ(first["params"]["thickness_px"], "inf");
    const nlohmann::json second =
        renderStats({"--method", "multiview", "--samples", "4"}, dir.string());
    EXPECT_EQ(second["params"]["layers"], 0);
    EXPECT_EQ(second["params"]["thickness_px"], 0.5);
    const nlohmann::json third =
        renderStats({"--method", "multilayer", "--epsilon", "0.5"}, dir.string());
    const nlohmann::json fourth = renderStats({"--method", "multilayer"}, dir.string());
    EXPECT_NE(third["params"]["epsilon"], fourth["params"]["epsilon"]);
    std::filesystem::remove_all(dir);
}

TEST(RenderCommand, MultiviewStatsGiveTheTracingCostPerRayAndPerLayerStep) {
    const std::filesystem::path dir =
        std::filesystem::temp_directory_path() / "focal_render_command_rates_test";
    std::filesystem::create_directories(dir);
    const nlohmann::json j = renderStats(
        {"--method", "multiview", "--samples", "8", "--aperture-radius", "0.3"}, dir.string());
    const nlohmann::json& c = j["counts"];
    ASSERT_FALSE(c["skipped"].get<bool>());
    const double rays = c["rays"].get<double>(), steps = c["layer_steps"].get<double>();
    EXPECT_EQ(rays, 16.0 * 12.0 * 8.0);
    // A height-field test needs a visit; a ray visits each layer at most once.
    EXPECT_GT(c["layer_tests"].get<double>(), 0.0);
    EXPECT_GE(steps, c["layer_tests"].get<double>());
    EXPECT_LE(steps, rays * c["layers"].get<double>());
    const double ms = j["time_ms"]["tracing"].get<double>();
    EXPECT_DOUBLE_EQ(j["tracing_ns"]["per_ray"].get<double>(), ms * 1e6 / rays);
    EXPECT_DOUBLE_EQ(j["tracing_ns"]["per_layer_step"].get<double>(), ms * 1e6 / steps);
    std::filesystem::remove_all(dir);
}

} // namespace
} // namespace focal::test
