// Golden and determinism tests of every depth-of-field method (issue 21; docs/testing.md). Each
// case is a `focal render` command line, run in-process at 160x120 to an EXR: the golden is
// `focal hash` of that EXR (tests/golden/dof/hashes.txt, compared exactly) and its PNG
// (tests/golden/dof/images, within 1 step). DofDeterminism renders every case at threads
// 0/1/2/3/8 x tiles 8/16/64/256 x SIMD/scalar kernels (--no-simd) and requires the same hash.
#include "apps/cli.h"
#include "apps/image_io.h"
#include "apps/pixel_hash.h"
#include "support/golden.h"
#include "support/subprocess.h"

#include <raster/frame.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <ostream>
#include <string>
#include <unistd.h>
#include <utility>
#include <vector>

namespace {

namespace fs = std::filesystem;
using focal::test::dofGoldens;

constexpr uint32_t kThreadCounts[] = {0, 1, 2, 3, 8};
constexpr uint32_t kTileSizes[] = {8, 16, 64, 256};

struct DofCase {
    std::string name;              // hash key and image file stem
    std::string scene;             // as `focal render` takes it
    std::vector<std::string> args; // the method and its options
};

// Appended to every case's command line: the golden size, and no progress bar.
const std::vector<std::string> kCommon = {"--width", "160", "--height", "120", "--no-progress"};

std::string aperture(const char* file) {
    return std::string(FOCAL_TEST_DATA_DIR) + "/aperture/" + file;
}

// Every method, each with the choices its paper made and with focal's defaults, on scenes that
// exercise it: accum with and without pixel jitter, gather with 32- and 16-bit depth, the
// layered methods on near-field blur (railing), transparency (glass, with half and float
// layers) and shiny surfaces (reflective), and the three aperture shapes on the bokeh scene.
// Lens samples are kept low (16): the goldens pin bytes, not quality.
std::vector<DofCase> dofCases() {
    const std::vector<std::string> mv = {"--method", "multiview", "--samples", "16"};
    const std::vector<std::string> ml = {"--method", "multilayer"};
    const std::vector<std::string> accum = {"--method", "accum", "--samples", "16"};
    // The choices of Lee et al. 2009 where focal's defaults differ (docs/dof/multiview.md).
    const std::vector<std::string> mv_paper = {"--traversal",   "false-position",
                                               "--bound-init",  "on",
                                               "--jitter",      "noise",
                                               "--offscreen",   "discard",
                                               "--cone-misses", "off",
                                               "--cone-centre", "sample",
                                               "--guard-band",  "0"};
    // The choices of Selgrad et al. 2015 where focal's defaults differ (docs/dof/multilayer.md).
    const std::vector<std::string> ml_paper = {"--level-filter", "box", "--merge-depth", "nearest",
                                               "--additive-gap", "inf", "--skip-hidden", "off",
                                               "--mip-levels",   "2"};
    const std::vector<std::string> polygon = {
        "--aperture-shape", "polygon", "--aperture-blades", "6", "--aperture-rotation", "15"};
    const std::vector<std::string> star = {"--aperture-shape", "image", "--aperture-image",
                                           aperture("star.pgm")};
    auto join = [](std::vector<std::string> a, const std::vector<std::string>& b) {
        a.insert(a.end(), b.begin(), b.end());
        return a;
    };
    return {
        {"accum_demo", "builtin:demo", accum},
        {"accum_demo_jitter", "builtin:demo", join(accum, {"--pixel-jitter"})},
        {"accum_railing", "builtin:railing", accum},
        {"gather_demo", "builtin:demo", {"--method", "gather"}},
        {"gather_demo_unorm16",
         "builtin:demo",
         {"--method", "gather", "--depth-format", "unorm16"}},
        {"gather_railing", "builtin:railing", {"--method", "gather"}},
        {"gather_railing_unorm16",
         "builtin:railing",
         {"--method", "gather", "--depth-format", "unorm16"}},
        {"multiview_demo", "builtin:demo", mv},
        {"multiview_demo_paper", "builtin:demo", join(mv, mv_paper)},
        {"multiview_railing", "builtin:railing", mv},
        {"multiview_railing_paper", "builtin:railing", join(mv, mv_paper)},
        {"multiview_glass", "builtin:glass", mv},
        {"multiview_glass_precision32", "builtin:glass", join(mv, {"--precision", "32"})},
        {"multiview_reflective_view_dependent", "builtin:reflective",
         join(mv, {"--view-dependent"})},
        {"multilayer_demo", "builtin:demo", ml},
        {"multilayer_demo_paper", "builtin:demo", join(ml, ml_paper)},
        {"multilayer_railing", "builtin:railing", ml},
        {"multilayer_railing_paper", "builtin:railing", join(ml, ml_paper)},
        {"multilayer_glass_precision32", "builtin:glass", join(ml, {"--precision", "32"})},
        {"accum_bokeh", "builtin:bokeh", accum},
        {"accum_bokeh_polygon", "builtin:bokeh", join(accum, polygon)},
        {"accum_bokeh_star", "builtin:bokeh", join(accum, star)},
        {"multiview_bokeh_polygon", "builtin:bokeh", join(mv, polygon)},
        {"multilayer_bokeh_star", "builtin:bokeh", join(ml, star)},
    };
}

// Pairs of cases whose difference (an option of the method, or the aperture) must show in the
// pixels, so that each variant pins something of its own.
constexpr std::pair<const char*, const char*> kMustDiffer[] = {
    {"accum_demo", "accum_demo_jitter"},
    {"gather_demo", "gather_demo_unorm16"},
    {"gather_railing", "gather_railing_unorm16"},
    {"multiview_demo", "multiview_demo_paper"},
    {"multiview_railing", "multiview_railing_paper"},
    {"multilayer_demo", "multilayer_demo_paper"},
    {"multilayer_railing", "multilayer_railing_paper"},
    {"multiview_glass", "multiview_glass_precision32"},
    {"accum_bokeh", "accum_bokeh_polygon"},
    {"accum_bokeh", "accum_bokeh_star"},
    {"accum_bokeh_polygon", "accum_bokeh_star"},
};

void PrintTo(const DofCase& c, std::ostream* os) {
    *os << c.name << " (" << c.scene;
    for (const std::string& a : c.args)
        *os << ' ' << a;
    *os << ")";
}

// A fresh folder for one test's renders, removed when the test passes. A parameterised test's
// name holds a '/' ("MatchesReference/accum_demo"): kept, it would make the folder a subfolder
// and leave its parent behind.
class ScratchDir {
public:
    ScratchDir() : path_(fs::temp_directory_path() / folderName()) {
        fs::remove_all(path_);
        fs::create_directories(path_);
    }
    ~ScratchDir() {
        if (!::testing::Test::HasFailure()) {
            std::error_code ec;
            fs::remove_all(path_, ec);
        }
    }
    ScratchDir(const ScratchDir&) = delete;
    ScratchDir& operator=(const ScratchDir&) = delete;
    const fs::path& path() const { return path_; }

private:
    static std::string folderName() {
        std::string test = ::testing::UnitTest::GetInstance()->current_test_info()->name();
        std::replace(test.begin(), test.end(), '/', '_');
        return "focal-dof-golden-" + std::to_string(::getpid()) + "-" + test;
    }

    fs::path path_;
};

struct Render {
    raster::Frame frame; // colour only (what the EXR holds)
    uint64_t hash = 0;   // `focal hash` of the EXR
};

// Runs `focal render` in this process, as the command line would, and reads the EXR back.
::testing::AssertionResult render(const DofCase& c, const fs::path& exr, uint32_t threads,
                                  uint32_t tile, bool simd, Render& out) {
    std::vector<std::string> args = {"focal",
                                     "render",
                                     c.scene,
                                     "-o",
                                     exr.string(),
                                     "--threads",
                                     std::to_string(threads),
                                     "--tile",
                                     std::to_string(tile)};
    args.insert(args.end(), kCommon.begin(), kCommon.end());
    args.insert(args.end(), c.args.begin(), c.args.end());
    if (!simd)
        args.push_back("--no-simd");
    std::vector<char*> argv;
    for (std::string& a : args)
        argv.push_back(a.data());
    const int code = focal::runCli(int(argv.size()), argv.data());
    if (code != 0)
        return ::testing::AssertionFailure() << "focal render exited with " << code;
    raster::Result<focal::ImageSamples> samples = focal::readImageSamples(exr.string());
    raster::Result<focal::ImageData> image = focal::readImage(exr.string());
    if (!samples.ok() || !image.ok() || image->channels != 4)
        return ::testing::AssertionFailure() << exr.string() << " is not an RGBA EXR";
    out.hash = focal::pixelHash(*samples);
    out.frame.width = image->width;
    out.frame.height = image->height;
    out.frame.color = std::move(image->pixels);
    return ::testing::AssertionSuccess();
}

class DofCaseTest : public ::testing::TestWithParam<DofCase> {};
using DofGolden = DofCaseTest;
using DofDeterminism = DofCaseTest;

TEST_P(DofGolden, MatchesReference) {
    const DofCase& c = GetParam();
    const ScratchDir dir;
    Render r;
    ASSERT_TRUE(render(c, dir.path() / "golden.exr", 2, 64, true, r));
    EXPECT_TRUE(focal::test::matchesGolden(dofGoldens(), c.name, r.frame, r.hash));
}

// Every thread count, tile size and kernel set gives the bytes of threads 0, tile 64, SIMD.
TEST_P(DofDeterminism, SameBitsForEveryThreadCountTileSizeAndKernel) {
    const DofCase& c = GetParam();
    const ScratchDir dir;
    Render reference;
    ASSERT_TRUE(render(c, dir.path() / "reference.exr", 0, 64, true, reference));
    for (const bool simd : {true, false})
        for (const uint32_t threads : kThreadCounts)
            for (const uint32_t tile : kTileSizes) {
                const std::string label = c.name + "_threads" + std::to_string(threads) + "_tile" +
                                          std::to_string(tile) + (simd ? "" : "_scalar");
                Render r;
                ASSERT_TRUE(render(c, dir.path() / (label + ".exr"), threads, tile, simd, r));
                if (r.hash == reference.hash)
                    continue;
                ADD_FAILURE() << label << " gave hash " << focal::hashHex(r.hash)
                              << ", threads 0, tile 64, SIMD gave "
                              << focal::hashHex(reference.hash) << "\n"
                              << focal::test::describeFrameDifference(label, reference.frame,
                                                                      r.frame);
            }
}

std::string caseName(const ::testing::TestParamInfo<DofCase>& info) {
    return info.param.name;
}

INSTANTIATE_TEST_SUITE_P(Methods, DofGolden, ::testing::ValuesIn(dofCases()), caseName);
INSTANTIATE_TEST_SUITE_P(Methods, DofDeterminism, ::testing::ValuesIn(dofCases()), caseName);

TEST(DofGoldenFiles, HoldExactlyTheKnownCases) {
    std::vector<std::string> names;
    for (const DofCase& c : dofCases())
        names.push_back(c.name);
    EXPECT_TRUE(focal::test::holdsExactly(dofGoldens(), names));
}

TEST(DofGoldenFiles, VariantsDifferFromTheirBase) {
    if (focal::test::updatingGoldens())
        GTEST_SKIP() << "goldens are being rewritten";
    EXPECT_TRUE(focal::test::variantsDiffer(dofGoldens(), kMustDiffer));
}

// The user's recipe (docs/hash.md): `focal render` in its own process, then `focal hash` of the
// EXR, prints the stored golden hash.
TEST(DofGoldenCli, RenderThenHashPrintsTheGoldenHash) {
    if (focal::test::updatingGoldens())
        GTEST_SKIP() << "goldens are being rewritten";
    const DofCase c = dofCases()[3]; // gather_demo: quick
    const ScratchDir dir;
    const std::string exr = (dir.path() / "out.exr").string();
    std::vector<std::string> argv = {FOCAL_BINARY, "render", c.scene, "-o", exr, "--threads", "3"};
    argv.insert(argv.end(), kCommon.begin(), kCommon.end());
    argv.insert(argv.end(), c.args.begin(), c.args.end());
    const focal::test::ProcessResult r = focal::test::runProcess(argv);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto hashes = focal::test::readGoldenHashes(dofGoldens().hashFile());
    ASSERT_TRUE(hashes.count(c.name));
    const focal::test::ProcessResult h = focal::test::runProcess({FOCAL_BINARY, "hash", exr});
    ASSERT_EQ(h.exit_code, 0) << h.err;
    EXPECT_EQ(h.out, focal::hashHex(hashes.at(c.name)) + "  " + exr + "\n");
}

} // namespace
