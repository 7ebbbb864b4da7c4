// `focal steps` and `focal probe` (issue 22): the folder docs/steps-format.md describes, the
// probe the page shows equal to what `focal probe` prints, and bad requests as clear errors
// that leave no folder behind.
#include "support/subprocess.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <unistd.h>

namespace focal::test {
namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
    const fs::path dir =
        fs::temp_directory_path() / ("focal_steps_" + name + "_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    return dir;
}

std::string readFile(const fs::path& path) {
    std::ifstream in(path);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

ProcessResult focal(std::vector<std::string> args) {
    args.insert(args.begin(), FOCAL_BINARY);
    return runProcess(args);
}

const std::vector<std::string> kSmall = {
    "builtin:demo", "--width", "64",           "--height", "48", "--samples", "8",
    "--threads",    "2",       "--probe-grid", "16"};

TEST(StepsCli, WritesTheFolderTheFormatDescribes) {
    for (const std::string method : {"multiview", "multilayer", "gather", "accum", "pinhole"}) {
        const fs::path dir = scratch(method);
        std::vector<std::string> args = {"steps"};
        args.insert(args.end(), kSmall.begin(), kSmall.end());
        for (const std::string& a : {std::string("--method"), method, std::string("--probe"),
                                     std::string("5,7"), std::string("--reference-samples"),
                                     std::string("16"), std::string("-o"), dir.string()})
            args.push_back(a);
        const ProcessResult r = focal(args);
        ASSERT_EQ(r.exit_code, 0) << method << ": " << r.err;
        EXPECT_NE(r.out.find("index.html"), std::string::npos) << r.out;
        const nlohmann::json j = nlohmann::json::parse(readFile(dir / "steps.json"));
        EXPECT_EQ(j["format_version"], 1);
        EXPECT_EQ(j["method"], method);
        EXPECT_EQ(j["width"], 64);
        EXPECT_EQ(j["height"], 48);
        // The page's script holds the same object.
        const std::string js = readFile(dir / "steps_data.js");
        ASSERT_EQ(js.rfind("window.FOCAL_STEPS = ", 0), 0u);
        EXPECT_EQ(nlohmann::json::parse(js.substr(21, js.size() - 21 - 2)), j);
        // Every stage has an id, a title, a paragraph; every image it names exists.
        ASSERT_GE(j["stages"].size(), 6u) << method;
        EXPECT_EQ(j["stages"].front()["id"], "raster.geometry");
        EXPECT_EQ(j["stages"].back()["id"], "result.image");
        for (const nlohmann::json& s : j["stages"]) {
            EXPECT_FALSE(s["title"].get<std::string>().empty()) << s["id"];
            EXPECT_FALSE(s["text"].get<std::string>().empty()) << s["id"];
            for (const nlohmann::json& img : s["images"])
                EXPECT_TRUE(fs::is_regular_file(dir / img["file"].get<std::string>()))
                    << img["file"];
        }
        for (const char* key : {"result", "reference", "difference"})
            EXPECT_TRUE(fs::is_regular_file(dir / j["compare"][key].get<std::string>())) << key;
        EXPECT_EQ(j["compare"]["reference_samples"], 16);
        // The grid (8,8), (24,8), ... plus 5,7, sorted by (y, x).
        ASSERT_EQ(j["probes"].size(), 4u * 3u + 1u);
        EXPECT_EQ(j["probes"][0]["x"], 5);
        EXPECT_EQ(j["probes"][0]["y"], 7);
        EXPECT_EQ(j["probes"][1]["x"], 8);
        EXPECT_EQ(j["probe_command"].get<std::string>().find("focal probe builtin:demo X,Y"), 0u)
            << j["probe_command"];
        EXPECT_EQ(j["probe_command"].get<std::string>().find("-o"), std::string::npos);
        fs::remove_all(dir);
    }
}

TEST(StepsCli, ProbePrintsWhatThePageShows) {
    const fs::path dir = scratch("probe");
    std::vector<std::string> args = {"steps"};
    args.insert(args.end(), kSmall.begin(), kSmall.end());
    for (const std::string a : {"--method", "multiview", "--reference-samples", "16", "-o"})
        args.push_back(a);
    args.push_back(dir.string());
    ASSERT_EQ(focal(args).exit_code, 0);
    const nlohmann::json page = nlohmann::json::parse(readFile(dir / "steps.json"));
    const nlohmann::json& shown = page["probes"][5];
    const std::string xy =
        std::to_string(shown["x"].get<int>()) + "," + std::to_string(shown["y"].get<int>());
    const ProcessResult r = focal({"probe", "builtin:demo", xy, "--width", "64", "--height", "48",
                                   "--samples", "8", "--method", "multiview", "--threads", "0"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const nlohmann::json probe = nlohmann::json::parse(r.out);
    EXPECT_EQ(probe["x"], shown["x"]);
    EXPECT_EQ(probe["rgba"], shown["rgba"]);
    EXPECT_EQ(probe["fragments"], shown["fragments"]);
    EXPECT_EQ(probe["method"], shown["method"]);
    fs::remove_all(dir);
}

TEST(StepsCli, BadRequestsAreErrorsThatLeaveNoFolder) {
    // A folder that is not a steps folder is never replaced.
    const fs::path other = scratch("other");
    fs::create_directories(other);
    std::ofstream(other / "keep.txt") << "mine";
    ProcessResult r =
        focal({"steps", "builtin:demo", "--width", "32", "--height", "24", "-o", other.string()});
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.err.find("is not a focal steps folder"), std::string::npos) << r.err;
    EXPECT_EQ(readFile(other / "keep.txt"), "mine");
    fs::remove_all(other);

    const fs::path dir = scratch("bad");
    r = focal({"steps", "builtin:demo", "--width", "32", "--height", "24", "--probe", "40,3", "-o",
               dir.string()});
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.err.find("--probe 40,3 is outside the 32x24 image"), std::string::npos) << r.err;
    r = focal({"steps", "builtin:demo", "--width", "32", "--height", "24", "--probe", "x", "-o",
               dir.string()});
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.err.find("--probe expects a pixel X,Y"), std::string::npos) << r.err;
    r = focal({"steps", "missing.gltf", "-o", dir.string()});
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.err.find("missing.gltf"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir));
    for (const fs::directory_entry& e : fs::directory_iterator(dir.parent_path()))
        EXPECT_EQ(e.path().filename().string().rfind(dir.filename().string() + ".partial", 0),
                  std::string::npos)
            << e.path();

    r = focal({"probe", "builtin:demo", "64,0", "--width", "64", "--height", "48"});
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.err.find("pixel 64,0 is outside the 64x48 image"), std::string::npos) << r.err;
    r = focal({"probe", "builtin:demo", "1;2"});
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.err.find("expects a pixel X,Y"), std::string::npos) << r.err;
}

} // namespace
} // namespace focal::test
