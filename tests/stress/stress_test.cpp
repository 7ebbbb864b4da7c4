// The stress suite (issue 23): every method at parameter extremes, run as `focal render` does it.
// Each case states what must hold — no NaN or Inf in the image, the same bits for threads 0 and
// 3 and tiles 64 and 16, closeness to the unstressed render where the extreme should not matter,
// a sharp in-focus surface, the pinhole when the lens cannot blur — or the one-line error (exit 1,
// no file written) or warning a request that cannot be honoured must give. Every outcome, with
// its measured error, is written to <build>/tests/stress-results/; docs/stress.md holds the
// table from the last run.
#include "apps/image_io.h"
#include "support/subprocess.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>
#include <string>
#include <unistd.h>
#include <vector>

namespace {

namespace fs = std::filesystem;
using focal::ImageData;

// --- Scenes written as glTF -------------------------------------------------------------------

std::string base64(const std::vector<unsigned char>& bytes) {
    static const char* kAlphabet =
        "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (size_t i = 0; i < bytes.size(); i += 3) {
        const uint32_t n = uint32_t(bytes[i]) << 16 |
                           (i + 1 < bytes.size() ? uint32_t(bytes[i + 1]) << 8 : 0) |
                           (i + 2 < bytes.size() ? uint32_t(bytes[i + 2]) : 0);
        out += kAlphabet[n >> 18 & 63];
        out += kAlphabet[n >> 12 & 63];
        out += i + 1 < bytes.size() ? kAlphabet[n >> 6 & 63] : '=';
        out += i + 2 < bytes.size() ? kAlphabet[n & 63] : '=';
    }
    return out;
}

struct Triangle {
    float v[3][3];
    int material;
};

std::string number(double v) {
    char text[40];
    std::snprintf(text, sizeof(text), "%.9g", v);
    return text;
}

// One mesh of unlit triangles (one primitive per material colour) under one node with the given
// translation and uniform scale.
std::string gltfOf(const std::vector<Triangle>& tris,
                   const std::vector<std::array<float, 3>>& colours, double offset, double scale) {
    std::vector<unsigned char> bin;
    std::string accessors, views, primitives;
    for (size_t m = 0; m < colours.size(); ++m) {
        std::vector<float> pos;
        float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (const Triangle& t : tris)
            if (size_t(t.material) == m)
                for (const auto& v : t.v)
                    for (int c = 0; c < 3; ++c) {
                        pos.push_back(v[c]);
                        lo[c] = std::min(lo[c], v[c]);
                        hi[c] = std::max(hi[c], v[c]);
                    }
        if (pos.empty())
            continue;
        const size_t offset_bytes = bin.size();
        bin.resize(bin.size() + pos.size() * 4);
        std::memcpy(bin.data() + offset_bytes, pos.data(), pos.size() * 4);
        const size_t index =
            views.empty() ? 0 : size_t(std::count(views.begin(), views.end(), '{'));
        views += std::string(views.empty() ? "" : ",") + R"({"buffer":0,"byteOffset":)" +
                 std::to_string(offset_bytes) + R"(,"byteLength":)" +
                 std::to_string(pos.size() * 4) + "}";
        accessors += std::string(accessors.empty() ? "" : ",") + R"({"bufferView":)" +
                     std::to_string(index) + R"(,"componentType":5126,"count":)" +
                     std::to_string(pos.size() / 3) + R"(,"type":"VEC3","min":[)" + number(lo[0]) +
                     "," + number(lo[1]) + "," + number(lo[2]) + R"(],"max":[)" + number(hi[0]) +
                     "," + number(hi[1]) + "," + number(hi[2]) + "]}";
        primitives += std::string(primitives.empty() ? "" : ",") + R"({"attributes":{"POSITION":)" +
                      std::to_string(index) + R"(},"material":)" + std::to_string(m) + "}";
    }
    std::string materials;
    for (const auto& c : colours)
        materials += std::string(materials.empty() ? "" : ",") +
                     R"({"pbrMetallicRoughness":{"baseColorFactor":[)" + number(c[0]) + "," +
                     number(c[1]) + "," + number(c[2]) +
                     R"(,1]},"doubleSided":true,"extensions":{"KHR_materials_unlit":{}}})";
    return R"({"asset":{"version":"2.0"},"extensionsUsed":["KHR_materials_unlit"],)"
           R"("buffers":[{"byteLength":)" +
           std::to_string(bin.size()) + R"(,"uri":"data:application/octet-stream;base64,)" +
           base64(bin) + R"("}],"bufferViews":[)" + views + R"(],"accessors":[)" + accessors +
           R"(],"materials":[)" + materials + R"(],"meshes":[{"primitives":[)" + primitives +
           R"(]}],"nodes":[{"mesh":0,"translation":[)" + number(offset) + "," + number(offset) +
           "," + number(offset) + R"(],"scale":[)" + number(scale) + "," + number(scale) + "," +
           number(scale) + R"(]}],"scenes":[{"nodes":[0]}],"scene":0})";
}

void addQuad(std::vector<Triangle>& tris, float x0, float y0, float x1, float y1, float z,
             int material) {
    tris.push_back({{{x0, y0, z}, {x1, y0, z}, {x1, y1, z}}, material});
    tris.push_back({{{x0, y0, z}, {x1, y1, z}, {x0, y1, z}}, material});
}

// The stage, in units where the eye is at the origin looking down -z: a back wall at d = 20 in
// two colours, a green square at d = 10 (where the lens focuses) and a white one at d = 4.
std::string stageGltf(double offset, double scale, bool squares = true) {
    std::vector<Triangle> t;
    addQuad(t, -30, -20, 0, 20, -20, 0);
    addQuad(t, 0, -20, 30, 20, -20, 1);
    if (squares) {
        addQuad(t, -2, -2, 2, 2, -10, 2);
        addQuad(t, -1.6f, 0.2f, -0.6f, 1.2f, -4, 3);
    }
    return gltfOf(t, {{0.8f, 0.1f, 0.1f}, {0.1f, 0.2f, 0.9f}, {0.1f, 0.8f, 0.2f}, {1, 1, 1}},
                  offset, scale);
}

// Slivers (1e-6 wide, 10 long) in front of the wall, and one triangle 1e7 across that covers
// the view (beyond any guard band) at d = 30.
std::string sliverHugeGltf() {
    std::vector<Triangle> t;
    addQuad(t, -30, -20, 30, 20, -20, 0);
    for (int i = 0; i < 16; ++i) {
        const float x = -4.0f + 0.5f * float(i);
        t.push_back({{{x, -5, -8}, {x + 1e-6f, -5, -8}, {x, 5, -8}}, 1});
    }
    t.push_back({{{-1e7f, -1e7f, -30}, {1e7f, -1e7f, -30}, {0, 1e7f, -30}}, 2});
    return gltfOf(t, {{0.5f, 0.5f, 0.5f}, {1, 1, 0}, {0, 0.3f, 0.6f}}, 0.0, 1.0);
}

// --- Running focal ---------------------------------------------------------------------------

struct FocalRun {
    focal::test::ProcessResult process;
    std::optional<ImageData> image;
};

class StressDir {
public:
    StressDir() {
        dir_ = fs::temp_directory_path() / ("focal-stress-" + std::to_string(::getpid()));
        fs::create_directories(dir_);
        write("stage.gltf", stageGltf(0.0, 1.0));
        write("stage_offset.gltf", stageGltf(1e6, 1.0));
        write("stage_small.gltf", stageGltf(0.0, 1e-4));
        write("stage_large.gltf", stageGltf(0.0, 1e4));
        write("sliver_huge.gltf", sliverHugeGltf());
        write("wall.gltf", stageGltf(0.0, 1.0, false));
    }
    ~StressDir() { fs::remove_all(dir_); }
    std::string path(const std::string& name) const { return (dir_ / name).string(); }
    const fs::path& dir() const { return dir_; }

private:
    void write(const std::string& name, const std::string& text) {
        std::ofstream(dir_ / name) << text;
    }
    fs::path dir_;
};

StressDir& stressDir() {
    static StressDir dir;
    return dir;
}

FocalRun runFocal(std::vector<std::string> args, const std::string& output) {
    fs::remove(stressDir().path(output));
    std::vector<std::string> argv{FOCAL_BINARY, "render"};
    argv.insert(argv.end(), args.begin(), args.end());
    argv.insert(argv.end(), {"-o", output, "--no-progress"});
    FocalRun run;
    run.process = focal::test::runProcess(argv, stressDir().dir().string());
    if (run.process.exit_code == 0) {
        raster::Result<ImageData> img = focal::readImage(stressDir().path(output));
        if (img.ok())
            run.image = std::move(*img);
    }
    return run;
}

size_t nonFinite(const ImageData& img) {
    return size_t(std::count_if(img.pixels.begin(), img.pixels.end(),
                                [](float v) { return !std::isfinite(v); }));
}

double meanAbsDiff(const ImageData& a, const ImageData& b) {
    if (a.pixels.size() != b.pixels.size() || a.pixels.empty())
        return INFINITY;
    double sum = 0.0;
    for (size_t i = 0; i < a.pixels.size(); ++i)
        sum += std::fabs(double(a.pixels[i]) - double(b.pixels[i]));
    return sum / double(a.pixels.size());
}

double mean(const ImageData& img) {
    double sum = 0.0;
    for (size_t i = 0; i < img.pixels.size(); i += 4)
        sum += double(img.pixels[i]) + double(img.pixels[i + 1]) + double(img.pixels[i + 2]);
    return sum / double(img.pixels.size() / 4 * 3);
}

// --- Cases ------------------------------------------------------------------------------------

enum class Expect {
    Image,       // exit 0, finite, same bits for threads 0 / 3 and tiles 64 / 16
    Error,       // exit 1, one "focal: error:" line containing `message`, no file
    WarnedImage, // Image, plus a "focal: warning:" line containing `message`
    SameMean,    // Image, and its mean within 1% of the reference's (blur moves light only)
};

struct StressCase {
    std::string name;
    std::string method;
    std::vector<std::string> args; // besides the scene options below
    Expect expect = Expect::Image;
    std::string message;
    // Image cases: the reference it must stay close to ("" none; "base": the method's unstressed
    // render; "pinhole": the pinhole render) and the largest mean absolute difference allowed.
    std::string reference;
    double max_mean_diff = 0.0;
    std::string what; // the extreme, in words, for the table
};

void PrintTo(const StressCase& c, std::ostream* os) {
    *os << c.method << " " << c.name;
}

const char* kSize[] = {"--width", "64", "--height", "48"};

// The stage seen from its eye, scaled by `scale`: near 0.1, aperture 0.05, focus on the green
// square at 10. Options given later in a case override none of these (CLI11 takes one value), so
// cases that change them build their own list.
std::vector<std::string> stageArgs(const std::string& scene, double offset, double scale, bool lens,
                                   double near = 0.1, double aperture = 0.5, double focus = 10.0) {
    const std::string o = number(offset);
    std::vector<std::string> a = {scene,
                                  "--eye",
                                  o + "," + o + "," + o,
                                  "--target",
                                  o + "," + o + "," + number(offset - scale),
                                  "--yfov",
                                  "45",
                                  "--near",
                                  number(near * scale)};
    if (lens) {
        a.insert(a.end(), {"--aperture-radius", number(aperture * scale), "--focus-distance",
                           number(focus * scale)});
    }
    return a;
}

std::vector<StressCase> stressCases() {
    std::vector<StressCase> cases;
    const std::vector<std::string> methods = {"pinhole", "accum", "gather", "multiview",
                                              "multilayer"};
    for (const std::string& m : methods) {
        const bool lens = m != "pinhole";
        const std::vector<std::string> method = {"--method", m, "--samples", "16"};
        auto stage = [&](double offset, double scale, double near = 0.1, double aperture = 0.5,
                         double focus = 10.0) {
            std::vector<std::string> a = stageArgs(offset == 0.0 && scale == 1.0 ? "stage.gltf"
                                                   : offset != 0.0 ? "stage_offset.gltf"
                                                   : scale < 1.0   ? "stage_small.gltf"
                                                                   : "stage_large.gltf",
                                                   offset, scale, lens, near, aperture, focus);
            a.insert(a.end(), method.begin(), method.end());
            return a;
        };
        auto with = [](std::vector<std::string> a, std::vector<std::string> more) {
            a.insert(a.end(), more.begin(), more.end());
            return a;
        };
        cases.push_back({"base", m, stage(0, 1), Expect::Image, "", "", 0, "unstressed stage"});
        cases.push_back({"offset_1e6", m, stage(1e6, 1), Expect::Image, "", "base", 0.02,
                         "scene and eye 1e6 from the origin"});
        cases.push_back({"scale_1e-4", m, stage(0, 1e-4), Expect::Image, "", "base", 0.002,
                         "scene, near, aperture and focus scaled by 1e-4"});
        cases.push_back({"scale_1e4", m, stage(0, 1e4), Expect::Image, "", "base", 0.002,
                         "scene, near, aperture and focus scaled by 1e4"});
        cases.push_back({"far_1e8", m, with(stage(0, 1), {"--far", "1e8"}), Expect::Image, "",
                         "base", 0.002, "far plane 1e8"});
        cases.push_back({"far_infinite", m, with(stage(0, 1), {"--far", "0"}), Expect::Image, "",
                         "base", 1e-6, "infinite far plane (the default is 41.6 here)"});
        cases.push_back({"near_1e-6", m, stage(0, 1, 1e-6), Expect::Image, "", "base", 0.002,
                         "near 1e-6, float depth (reversed-Z keeps the wall at 20)"});
        cases.push_back({"near_1e-5_unorm16", m,
                         with(stage(0, 1, 1e-5), {"--depth-format", "unorm16"}),
                         Expect::WarnedImage,
                         "unorm16 depth with near 1e-05 stores every distance beyond 1.27 as the "
                         "far plane",
                         "", 0, "near 1e-5, 16-bit depth: the issue's empty image"});
        cases.push_back({"image_1x1", m, with(stage(0, 1), {"--width", "1", "--height", "1"}),
                         Expect::Image, "", "", 0, "1x1 image"});
        cases.push_back({"image_1x4096", m, with(stage(0, 1), {"--width", "1", "--height", "4096"}),
                         Expect::Image, "", "", 0, "1x4096 image"});
        cases.push_back({"sliver_huge", m, with(stageArgs("sliver_huge.gltf", 0, 1, lens), method),
                         Expect::Image, "", "", 0, "16 slivers 1e-6 wide, a triangle 1e7 across"});
        if (m == "pinhole") {
            cases.push_back({"depth_unorm16", m, with(stage(0, 1), {"--depth-format", "unorm16"}),
                             Expect::Image, "", "base", 0.0, "16-bit depth buffer"});
            continue;
        }
        // Lens extremes.
        // Multilayer does not skip an unblurring lens: its half-precision lists round colours.
        cases.push_back({"aperture_1e-9", m, stage(0, 1, 0.1, 1e-9), Expect::Image, "", "pinhole",
                         m == "multilayer" ? 1e-4 : 0.0,
                         "aperture radius 1e-9: the pinhole image"});
        if (m == "multilayer") {
            // §5.2's stack levels grow with the CoC: at 580,000 px they would take tens of GB
            // (8 GB and a minute at 16x12 before the check), which the budget refuses at once.
            cases.push_back({"aperture_1e3", m,
                             with(stage(0, 1, 0.1, 1e3), {"--memory-budget", "4G"}), Expect::Error,
                             "filter levels for a CoC of up to", "", 0,
                             "aperture radius 1e3: CoC up to 8,700 px, 4 GiB budget"});
        } else {
            cases.push_back({"aperture_1e3", m, stage(0, 1, 0.1, 1e3), Expect::Image, "", "", 0,
                             "aperture radius 1e3: CoC up to 8,700 px"});
        }
        cases.push_back({"coc_600px", m, stage(0, 1, 0.1, 70.0), Expect::Image, "", "", 0,
                         "aperture 70: CoC 610 px at the near square, 200 px at the wall"});
        // The wall alone: in focus it must stay the pinhole image; out of focus its mean
        // colour must stay (the blur only moves light).
        cases.push_back(
            {"in_focus_wall", m, with(stageArgs("wall.gltf", 0, 1, true, 0.1, 0.5, 20.0), method),
             Expect::Image, "", "wall pinhole", 1e-3, "focus exactly on the wall: stays sharp"});
        cases.push_back({"energy_wall", m,
                         with(stageArgs("wall.gltf", 0, 1, true, 0.1, 0.5, 5.0), method),
                         Expect::SameMean, "", "wall pinhole", 1.0,
                         "wall defocused (CoC 4.3 px): mean colour conserved within 1%"});
        cases.push_back({"focus_at_near", m, stage(0, 1, 0.1, 0.5, 0.1), Expect::Image, "", "", 0,
                         "focus distance = near plane"});
        cases.push_back({"focus_on_wall", m, stage(0, 1, 0.1, 0.5, 20.0), Expect::Image, "", "", 0,
                         "focus exactly on the back wall (sharp there)"});
        cases.push_back({"focus_3e38", m, with(stage(0, 1, 0.1, 0.5, 3e38), {"--far", "0"}),
                         Expect::Image, "", "", 0,
                         "focus at 3e38 (infinity in float), infinite far plane"});
        cases.push_back({"focus_beyond_far", m, stage(0, 1, 0.1, 0.5, 3e38), Expect::Error,
                         "lies behind the far plane", "", 0,
                         "focus at 3e38 behind the far plane (41.6)"});
        cases.push_back({"focus_inf", m, stage(0, 1, 0.1, 0.5, INFINITY), Expect::Error,
                         "--focus-distance must be a finite number > 0", "", 0,
                         "focus at infinity"});
        cases.push_back(
            {"samples_1", m,
             with(stageArgs("stage.gltf", 0, 1, true), {"--method", m, "--samples", "1"}),
             Expect::Image, "", "", 0, "1 lens sample"});
        cases.push_back({"precision_16", m, with(stage(0, 1), {"--precision", "16"}), Expect::Image,
                         "", "base", m == "accum" ? 0.0 : 0.01,
                         "16-bit targets (--precision 16; accum has none)"});
        cases.push_back({"depth_unorm16", m, with(stage(0, 1), {"--depth-format", "unorm16"}),
                         Expect::Image, "", "base", 0.01, "16-bit pinhole depth"});
    }
    // 65536 lens samples: accum renders them (a 16x16 image); multiview's per-tile ray states
    // alone need ~1.5 GiB, which a 256 MiB budget refuses before rendering anything.
    cases.push_back({"samples_65536",
                     "accum",
                     {"stage.gltf", "--eye", "0,0,0", "--target", "0,0,-1", "--near", "0.1",
                      "--aperture-radius", "0.05", "--focus-distance", "10", "--method", "accum",
                      "--samples", "65536", "--width", "16", "--height", "16"},
                     Expect::Image,
                     "",
                     "",
                     0,
                     "65536 lens samples, 16x16"});
    cases.push_back({"samples_65536_budget",
                     "multiview",
                     {"stage.gltf", "--eye",
                      "0,0,0",      "--target",
                      "0,0,-1",     "--near",
                      "0.1",        "--aperture-radius",
                      "0.05",       "--focus-distance",
                      "10",         "--method",
                      "multiview",  "--samples",
                      "65536",      "--width",
                      "16",         "--height",
                      "16",         "--memory-budget",
                      "256M"},
                     Expect::Error,
                     "--method multiview at 16x16 with 65536 samples needs",
                     "",
                     0,
                     "65536 lens samples under a 256 MiB budget"});
    // The sizes: 8192x8192 pinhole fits the default budget (checked by a dry run, rendering it
    // would write a 1 GiB EXR); under 1 GiB it fails before allocating. The issue's absurd
    // request fails in milliseconds instead of aborting after 49 s.
    cases.push_back({"image_8192_dry_run",
                     "pinhole",
                     {"builtin:demo", "--width", "8192", "--height", "8192", "--dry-run"},
                     Expect::Image,
                     "",
                     "",
                     0,
                     "8192x8192 pinhole (dry run)"});
    // Requests that cannot be honoured: one error line naming what needed how much.
    auto refused = [&](const char* name, const char* method, std::vector<std::string> args,
                       const char* message, const char* what) {
        cases.push_back({name, method, std::move(args), Expect::Error, message, "", 0, what});
    };
    refused("image_8192_budget", "pinhole",
            {"builtin:demo", "--width", "8192", "--height", "8192", "--memory-budget", "1G"},
            "--method pinhole at 8192x8192 needs 1.2 GiB, more than the memory budget of 1.0 GiB",
            "8192x8192 under a 1 GiB budget");
    refused("absurd_16384_multiview", "multiview",
            {"builtin:demo", "--width", "16384", "--height", "16384", "--method", "multiview",
             "--samples", "65536", "--memory-budget", "8G"},
            "--method multiview at 16384x16384 with 65536 samples needs",
            "16384x16384, 65536 samples (issue 23)");
    refused("layers_64_8k", "multiview",
            {"builtin:demo", "--width", "8192", "--height", "8192", "--method", "multiview",
             "--layers", "64", "--memory-budget", "8G"},
            "--method multiview at 8192x8192 with 64 samples needs", "64 layers at 8192x8192");
    return cases;
}

// --- The test --------------------------------------------------------------------------------

// The arguments of the render a case is compared with (StressCase::reference).
std::vector<std::string> referenceArgs(const StressCase& c) {
    if (c.reference == "pinhole")
        return stageArgs("stage.gltf", 0, 1, false);
    if (c.reference == "wall pinhole")
        return stageArgs("wall.gltf", 0, 1, false);
    std::vector<std::string> a = stageArgs("stage.gltf", 0, 1, c.method != "pinhole"); // base
    a.insert(a.end(), {"--method", c.method, "--samples", "16"});
    return a;
}

// Each case appends its row of the outcome table to stress-results/METHOD_CASE.md (CTest runs
// every case in its own process); docs/stress.md is `cat stress-results/*.md` of the last run.
void recordOutcome(const StressCase& c, const std::string& outcome) {
    fs::create_directories("stress-results");
    std::ofstream("stress-results/" + c.method + "_" + c.name + ".md")
        << "| " << c.method << " | " << c.name << " | " << c.what << " | " << outcome << " |\n";
}

// The unstressed render a case is compared with.
ImageData reference(const std::vector<std::string>& base_args, const std::string& output) {
    const FocalRun run = runFocal(base_args, output);
    EXPECT_EQ(run.process.exit_code, 0) << run.process.err;
    return run.image.value_or(ImageData{});
}

std::vector<std::string> withSize(std::vector<std::string> args) {
    const bool sized = std::find(args.begin(), args.end(), "--width") != args.end();
    if (!sized)
        args.insert(args.end(), std::begin(kSize), std::end(kSize));
    return args;
}

class Stress : public ::testing::TestWithParam<StressCase> {};

TEST_P(Stress, HoldsItsPromise) {
    const StressCase& c = GetParam();
    const std::string output = c.method + "_" + c.name + ".exr";
    const std::vector<std::string> args = withSize(c.args);
    std::vector<std::string> first = args;
    first.insert(first.end(), {"--threads", "0", "--tile", "64"});
    const FocalRun run = runFocal(first, output);
    std::string outcome;
    const std::vector<std::string> err_lines = focal::test::splitLines(run.process.err);

    if (c.expect == Expect::Error) {
        EXPECT_EQ(run.process.exit_code, 1) << run.process.err;
        ASSERT_EQ(err_lines.size(), 1u) << run.process.err;
        EXPECT_EQ(err_lines[0].rfind("focal: error: ", 0), 0u) << err_lines[0];
        EXPECT_NE(err_lines[0].find(c.message), std::string::npos) << err_lines[0];
        EXPECT_FALSE(fs::exists(stressDir().path(output)));
        outcome = "error: `" + err_lines[0].substr(std::strlen("focal: error: ")) + "`";
    } else {
        ASSERT_EQ(run.process.exit_code, 0) << run.process.err;
        const bool dry_run = std::find(args.begin(), args.end(), "--dry-run") != args.end();
        if (dry_run) {
            EXPECT_FALSE(fs::exists(stressDir().path(output)));
            EXPECT_NE(run.process.out.find("focal: dry run:"), std::string::npos);
            outcome =
                "ok (dry run): `" + run.process.out.substr(0, run.process.out.find('\n')) + "`";
        } else {
            ASSERT_TRUE(run.image.has_value());
            const ImageData& img = *run.image;
            EXPECT_EQ(nonFinite(img), 0u) << "NaN or Inf in the image";
            // Bit-exact for another thread count and tile size.
            std::vector<std::string> second = args;
            second.insert(second.end(), {"--threads", "3", "--tile", "16"});
            const FocalRun again = runFocal(second, "again_" + output);
            ASSERT_EQ(again.process.exit_code, 0) << again.process.err;
            ASSERT_TRUE(again.image.has_value());
            EXPECT_EQ(std::memcmp(img.pixels.data(), again.image->pixels.data(),
                                  img.pixels.size() * sizeof(float)),
                      0)
                << "threads 0 / tile 64 and threads 3 / tile 16 differ";
            char text[160];
            std::snprintf(text, sizeof(text), "ok: finite, same bits for threads 0/3, mean %.4f",
                          mean(img));
            outcome = text;
            if (!c.reference.empty()) {
                const ImageData ref = reference(withSize(referenceArgs(c)), "reference_" + output);
                const double diff = meanAbsDiff(img, ref);
                EXPECT_LE(diff, c.max_mean_diff) << "mean |difference| from " << c.reference;
                std::snprintf(text, sizeof(text), "; mean abs diff from %s %.2e (limit %.0e)",
                              c.reference.c_str(), diff, c.max_mean_diff);
                outcome += text;
                if (c.expect == Expect::SameMean) {
                    const double shift = std::fabs(mean(img) / mean(ref) - 1.0);
                    EXPECT_LE(shift, 0.01) << "mean colour moved from " << mean(ref);
                    std::snprintf(text, sizeof(text), "; mean moved %.2e (limit 1e-02)", shift);
                    outcome += text;
                }
            }
        }
        const auto warning = std::find_if(err_lines.begin(), err_lines.end(), [](const auto& l) {
            return l.rfind("focal: warning: ", 0) == 0 &&
                   l.find("lens options have no effect") == std::string::npos;
        });
        if (c.expect == Expect::WarnedImage) {
            ASSERT_NE(warning, err_lines.end()) << run.process.err;
            EXPECT_NE(warning->find(c.message), std::string::npos) << *warning;
            outcome += "; warns: `" + warning->substr(std::strlen("focal: warning: ")) + "`";
        } else {
            EXPECT_EQ(warning, err_lines.end()) << "unexpected: " << *warning;
        }
    }
    recordOutcome(c, outcome);
}

std::string caseName(const ::testing::TestParamInfo<StressCase>& info) {
    std::string name = info.param.method + "_" + info.param.name;
    std::replace_if(
        name.begin(), name.end(), [](char ch) { return !std::isalnum((unsigned char)ch); }, '_');
    return name;
}

INSTANTIATE_TEST_SUITE_P(Extremes, Stress, ::testing::ValuesIn(stressCases()), caseName);

} // namespace
