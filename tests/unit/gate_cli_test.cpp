// `focal hash` and `focal compare` as CI gates (docs/hash.md, docs/compare-schema.md), run as a
// child process: the hash's definition and stability, exit codes 0/1/2, the failing metric on
// stderr, the diff image only on failure, and the JSON gate block.
#include "support/subprocess.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace focal::test {
namespace {

namespace fs = std::filesystem;

const std::string kStar = std::string(FOCAL_TEST_DATA_DIR) + "/aperture/star.pgm";
// `focal hash` of star.pgm, computed from the definition in docs/hash.md by its Python reference
// implementation: pins the definition, not just the code.
constexpr const char* kStarHash = "f8cbedb8bed2f399";

class GateCli : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() /
               ("focal_gate_cli_" +
                std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override {
        if (!HasFailure())
            fs::remove_all(dir_);
    }
    ProcessResult focal(std::vector<std::string> args) {
        args.insert(args.begin(), FOCAL_BINARY);
        return runProcess(args);
    }
    // star.pgm written as a PNG with `edit` applied to its 8-bit grey samples: the same pixels
    // in another file format, or a few changed. No render: every process costs a start-up.
    std::string star(const std::string& name,
                     const std::function<void(std::vector<unsigned char>&)>& edit = {}) {
        auto in = OIIO::ImageInput::open(kStar);
        EXPECT_TRUE(in);
        if (!in)
            return {};
        const OIIO::ImageSpec spec = in->spec();
        std::vector<unsigned char> pixels(size_t(spec.width) * spec.height * spec.nchannels);
        EXPECT_TRUE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::UINT8, pixels.data()));
        if (edit)
            edit(pixels);
        const std::string out = path(name);
        auto writer = OIIO::ImageOutput::create(out);
        EXPECT_TRUE(writer && writer->open(out, spec) &&
                    writer->write_image(OIIO::TypeDesc::UINT8, pixels.data()) && writer->close());
        return out;
    }
    std::string path(const std::string& name) const { return (dir_ / name).string(); }
    fs::path dir_;
};

TEST_F(GateCli, HashFollowsTheDocumentedDefinition) {
    const ProcessResult r = focal({"hash", kStar});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.out, std::string(kStarHash) + "  " + kStar + "\n");
}

TEST_F(GateCli, HashCoversPixelsNotFileBytes) {
    // The same 8-bit pixels as PGM and as PNG: different files, one hash.
    const std::string png = star("star.png");
    const ProcessResult r = focal({"hash", png, kStar});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const std::vector<std::string> lines = splitLines(r.out);
    ASSERT_EQ(lines.size(), 2u) << r.out;
    EXPECT_EQ(lines[0], std::string(kStarHash) + "  " + png);
    // A one-sample change changes it.
    const std::string changed = star("changed.png", [](auto& p) { p[0] ^= 1; });
    EXPECT_EQ(focal({"hash", changed, "--expect", kStarHash}).exit_code, 1);
}

TEST_F(GateCli, HashExpectAndErrors) {
    EXPECT_EQ(focal({"hash", kStar, "--expect", kStarHash}).exit_code, 0);
    EXPECT_EQ(focal({"hash", kStar, "--expect", "F8CBEDB8BED2F399"}).exit_code, 0);
    const ProcessResult wrong = focal({"hash", kStar, "--expect", "0000000000000000"});
    EXPECT_EQ(wrong.exit_code, 1);
    EXPECT_NE(wrong.err.find(std::string(kStarHash) + ", expected 0000000000000000"),
              std::string::npos)
        << wrong.err;
    // I/O errors: 2, the file named, nothing on stdout even for the readable images before it.
    const ProcessResult missing = focal({"hash", kStar, path("nope.png")});
    EXPECT_EQ(missing.exit_code, 2);
    EXPECT_TRUE(missing.out.empty()) << missing.out;
    EXPECT_NE(missing.err.find("nope.png"), std::string::npos) << missing.err;
    EXPECT_EQ(focal({"hash", kStar, "--expect", "xyz"}).exit_code, 2);
    EXPECT_EQ(focal({"hash", kStar, kStar, "--expect", kStarHash}).exit_code, 2);
    EXPECT_EQ(focal({"hash"}).exit_code, 2);
}

// star.pgm with four pixels of the star's tips darkened from 255 to 128: every metric sees it.
std::function<void(std::vector<unsigned char>&)> dentTheStar() {
    return [](std::vector<unsigned char>& p) {
        int dented = 0;
        for (size_t i = 0; i < p.size() && dented < 4; ++i)
            if (p[i] == 255)
                p[i] = 128, ++dented;
    };
}

TEST_F(GateCli, CompareGatePassesWithinAndFailsOutsideEachThreshold) {
    const std::string a = star("a.png");
    const std::string b = star("b.png", dentTheStar());
    const std::string diff = path("diff.png");
    // Identical images pass every threshold, and a gate that passes writes no diff.
    ProcessResult r = focal({"compare", a, kStar, "--max-abs", "0", "--min-psnr", "inf",
                             "--min-ssim", "1", "--max-differing", "0", "--diff", diff});
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_TRUE(r.err.empty()) << r.err;
    EXPECT_FALSE(fs::exists(diff));

    // Each threshold alone fails and names its metric, and the failing gate writes the diff.
    const std::vector<std::pair<std::vector<std::string>, std::string>> failing = {
        {{"--max-abs", "0.1"}, "max_abs_error"},
        {{"--min-psnr", "40"}, "psnr_linear_db"},
        {{"--min-ssim", "0.9999"}, "ssim"},
        {{"--max-differing", "3"}, "differing_pixels"},
    };
    for (const auto& [option, metric] : failing) {
        std::vector<std::string> args = {"compare", a, b, "--diff", diff};
        args.insert(args.end(), option.begin(), option.end());
        r = focal(args);
        EXPECT_EQ(r.exit_code, 1) << option[0];
        EXPECT_NE(r.err.find("compare failed"), std::string::npos) << r.err;
        EXPECT_NE(r.err.find(metric + " is "), std::string::npos) << r.err;
        EXPECT_NE(r.err.find(option[0]), std::string::npos) << r.err;
        EXPECT_TRUE(fs::exists(diff)) << option[0];
        fs::remove(diff);
    }
    // Thresholds the dent stays within pass; a tolerance above it makes no pixel differ.
    r = focal({"compare", a, b, "--max-abs", "1", "--min-psnr", "10", "--min-ssim", "0.5",
               "--max-differing", "4"});
    EXPECT_EQ(r.exit_code, 0) << r.err;
    r = focal({"compare", a, b, "--max-differing", "0", "--tolerance", "1"});
    EXPECT_EQ(r.exit_code, 0) << r.err;
}

TEST_F(GateCli, CompareJsonCarriesTheGate) {
    const std::string b = star("b.png", dentTheStar());
    const ProcessResult r = focal({"compare", kStar, b, "--json", "--min-psnr", "1",
                                   "--max-differing", "3", "--tolerance", "0.01"});
    EXPECT_EQ(r.exit_code, 1) << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["schema"], "focal.compare");
    EXPECT_EQ(j["schema_version"], 1);
    EXPECT_EQ(j["tolerance"].get<double>(), double(0.01f));
    EXPECT_EQ(j["differing_pixels"].get<uint64_t>(), 4u);
    EXPECT_FALSE(j["gate"]["passed"].get<bool>());
    ASSERT_EQ(j["gate"]["checks"].size(), 2u);
    EXPECT_EQ(j["gate"]["checks"][0]["metric"], "psnr_linear_db");
    EXPECT_TRUE(j["gate"]["checks"][0]["passed"].get<bool>());
    EXPECT_EQ(j["gate"]["checks"][1]["metric"], "differing_pixels");
    EXPECT_EQ(j["gate"]["checks"][1]["option"], "--max-differing");
    EXPECT_EQ(j["gate"]["checks"][1]["limit"], 3.0);
    EXPECT_EQ(j["gate"]["checks"][1]["value"], 4.0);
    EXPECT_FALSE(j["gate"]["checks"][1]["passed"].get<bool>());
    EXPECT_FALSE(j.contains("diff"));
}

TEST_F(GateCli, CompareUsageAndIoErrorsExitTwo) {
    for (const std::vector<std::string>& args : std::vector<std::vector<std::string>>{
             {"compare", kStar, path("nope.exr"), "--max-abs", "1"},
             {"compare", kStar, kStar, "--tolerance", "0.1"}, // needs --max-differing
             {"compare", kStar, kStar, "--max-abs", "-1"},
             {"compare", kStar, kStar, "--min-ssim", "2"},
             {"compare", kStar, kStar, "--min-psnr", "nan"},
         }) {
        const ProcessResult r = focal(args);
        EXPECT_EQ(r.exit_code, 2) << args[3] << ": " << r.err;
        EXPECT_NE(r.err.find("focal: error:"), std::string::npos) << r.err;
    }
}

} // namespace
} // namespace focal::test
