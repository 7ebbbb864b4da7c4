#include "apps/compare_command.h"

#include "apps/image_io.h"

#include <dof/metrics.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

namespace focal {

using raster::Result;
using raster::Status;

namespace {

// The version of the --json layout (docs/compare-schema.md): bumped on any change that could
// break a reader (a removed or renamed field, a changed meaning or unit), not for new fields.
constexpr int kCompareSchemaVersion = 1;

// Usage and I/O errors: exit 2, so that 1 always means "the images are not within the gate".
int error(const std::string& message) {
    std::fprintf(stderr, "focal: error: %s\n", message.c_str());
    return 2;
}

dof::ImageRef refOf(const ImageData& img) {
    return {img.pixels.data(), img.width, img.height, img.channels};
}

// JSON has no infinity: identical images give null PSNR (documented in docs/dof/accum.md).
nlohmann::json number(double v) {
    return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json();
}

std::string db(double v) {
    char buf[32];
    if (std::isinf(v))
        return "inf";
    std::snprintf(buf, sizeof buf, "%.2f dB", v);
    return buf;
}

// One gate threshold and how the images fared against it.
struct GateCheck {
    std::string metric; // field of "all" in the JSON (or differing_pixels)
    std::string option; // the command-line option that set the limit
    double limit = 0;
    double value = 0;
    bool passed = false;
};

std::vector<GateCheck> runGate(const CompareArgs& args, const dof::ErrorMetrics& m,
                               uint64_t differing) {
    std::vector<GateCheck> checks;
    // "<=" and ">=" are written so that a NaN value fails.
    if (args.max_abs)
        checks.push_back({"max_abs_error", "--max-abs", *args.max_abs, m.max_abs_error,
                          m.max_abs_error <= *args.max_abs});
    if (args.min_psnr)
        checks.push_back({"psnr_linear_db", "--min-psnr", *args.min_psnr, m.psnr_linear_db,
                          m.psnr_linear_db >= *args.min_psnr});
    if (args.min_ssim)
        checks.push_back({"ssim", "--min-ssim", *args.min_ssim, m.ssim, m.ssim >= *args.min_ssim});
    if (args.max_differing)
        checks.push_back({"differing_pixels", "--max-differing", double(*args.max_differing),
                          double(differing), differing <= *args.max_differing});
    return checks;
}

std::string formatValue(double v) {
    if (std::isinf(v))
        return v > 0 ? "inf" : "-inf";
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return buf;
}

nlohmann::json toJson(const dof::ErrorMetrics& m) {
    return {{"pixels", m.pixels},
            {"psnr_linear_db", number(m.psnr_linear_db)},
            {"psnr_srgb_db", number(m.psnr_srgb_db)},
            {"ssim", number(m.ssim)},
            {"ssim_windows", m.ssim_windows},
            {"mean_abs_error", m.mean_abs_error},
            {"max_abs_error", m.max_abs_error}};
}

// The text report on stdout.
void printReport(const CompareArgs& args, const ImageData& a, const dof::ErrorMetrics& all,
                 const std::optional<dof::ErrorMetrics>& band, uint64_t differing,
                 bool wrote_diff) {
    std::printf("%s vs %s (%ux%u)\n", args.a.c_str(), args.b.c_str(), a.width, a.height);
    std::printf("%-14s %16s", "", "all pixels");
    if (band)
        std::printf(" %16s", "depth band");
    std::printf("\n");
    auto row = [&](const char* name, auto get) {
        std::printf("%-14s %16s", name, get(all).c_str());
        if (band)
            std::printf(" %16s", get(*band).c_str());
        std::printf("\n");
    };
    auto fmt = [](const char* f, double v) {
        char buf[32];
        std::snprintf(buf, sizeof buf, f, v);
        return std::string(buf);
    };
    row("pixels", [&](const dof::ErrorMetrics& m) { return fmt("%.0f", double(m.pixels)); });
    row("PSNR linear", [](const dof::ErrorMetrics& m) { return db(m.psnr_linear_db); });
    row("PSNR sRGB", [](const dof::ErrorMetrics& m) { return db(m.psnr_srgb_db); });
    row("SSIM", [&](const dof::ErrorMetrics& m) { return fmt("%.5f", m.ssim); });
    row("mean |err|", [&](const dof::ErrorMetrics& m) { return fmt("%.6f", m.mean_abs_error); });
    row("max |err|", [&](const dof::ErrorMetrics& m) { return fmt("%.6f", m.max_abs_error); });
    std::printf(
        "%-14s %16s\n", "differing px",
        (std::to_string(differing) + " (> " + formatValue(double(args.tolerance)) + ")").c_str());
    if (!args.depth.empty() && !band)
        std::printf("depth band: no depth discontinuities in %s\n", args.depth.c_str());
    if (wrote_diff)
        std::printf("wrote %s\n", args.diff.c_str());
}

} // namespace

CLI::App* addCompareCommand(CLI::App& app, CompareArgs& args) {
    CLI::App* cmd = app.add_subcommand(
        "compare", "Error metrics between two images: PSNR, SSIM, mean/max absolute error");
    cmd->add_option("a", args.a, "first image (the reference)")->required();
    cmd->add_option("b", args.b, "second image")->required();
    cmd->add_option("--depth", args.depth,
                    "linear depth EXR (focal render --depth-out): also report the metrics on "
                    "the band of pixels near depth discontinuities");
    cmd->add_option("--diff", args.diff, "write a false-colour difference image here");
    cmd->add_flag("--json", args.json, "print JSON instead of text");
    cmd->add_option("--band-threshold", args.band_threshold,
                    "relative depth jump between 4-neighbours that marks an edge")
        ->capture_default_str()
        ->check(CLI::Range(1e-6f, 1e6f));
    cmd->add_option("--band-radius", args.band_radius,
                    "band: pixels within this distance (px) of an edge pixel")
        ->capture_default_str()
        ->check(CLI::Range(0.0f, 1000.0f));
    cmd->add_option("--diff-scale", args.diff_scale,
                    "sRGB difference shown at full false-colour scale")
        ->capture_default_str()
        ->check(CLI::Range(1e-6f, 1.0f));
    // Gate (docs/testing.md, "focal compare as a CI gate").
    cmd->add_option("--max-abs", args.max_abs,
                    "gate: fail when the largest |a - b| of linear RGB exceeds E")
        ->check(CLI::NonNegativeNumber);
    cmd->add_option("--min-psnr", args.min_psnr,
                    "gate: fail when the linear PSNR is below DB (identical images: inf)");
    cmd->add_option("--min-ssim", args.min_ssim, "gate: fail when the SSIM is below S")
        ->check(CLI::Range(-1.0, 1.0));
    CLI::Option* max_differing =
        cmd->add_option("--max-differing", args.max_differing,
                        "gate: fail when more than PIXELS pixels differ by more than --tolerance "
                        "in some channel (alpha included)");
    cmd->add_option("--tolerance", args.tolerance,
                    "with --max-differing: per-channel difference (linear values) that counts")
        ->capture_default_str()
        ->check(CLI::NonNegativeNumber)
        ->needs(max_differing);
    return cmd;
}

int runCompare(const CompareArgs& args) {
    for (float v : {args.band_threshold, args.band_radius, args.diff_scale, args.tolerance})
        if (!std::isfinite(v))
            return error("--band-threshold, --band-radius, --diff-scale and --tolerance must be "
                         "finite");
    for (const std::optional<double>& v : {args.max_abs, args.min_psnr, args.min_ssim})
        if (v && std::isnan(*v))
            return error("--max-abs, --min-psnr and --min-ssim must be numbers");
    Result<ImageData> a = readImage(args.a);
    if (!a.ok())
        return error(a.status().message());
    Result<ImageData> b = readImage(args.b);
    if (!b.ok())
        return error(b.status().message());
    if (a->width != b->width || a->height != b->height) {
        // Not an error of the command: the images differ, so the comparison fails.
        std::fprintf(stderr,
                     "focal: compare failed: %s is %ux%u but %s is %ux%u; compare needs images "
                     "of the same size\n",
                     args.a.c_str(), a->width, a->height, args.b.c_str(), b->width, b->height);
        return 1;
    }
    Result<dof::ErrorMetrics> all = dof::compareImages(refOf(*a), refOf(*b));
    if (!all.ok())
        return error(args.a + " vs " + args.b + ": " + all.status().message());
    const uint64_t differing = dof::countDifferingPixels(refOf(*a), refOf(*b), args.tolerance);

    std::optional<dof::ErrorMetrics> band;
    uint64_t band_pixels = 0;
    if (!args.depth.empty()) {
        Result<ImageData> depth = readImage(args.depth);
        if (!depth.ok())
            return error(depth.status().message());
        if (depth->width != a->width || depth->height != a->height)
            return error(args.depth + " is " + std::to_string(depth->width) + "x" +
                         std::to_string(depth->height) + " but the images are " +
                         std::to_string(a->width) + "x" + std::to_string(a->height));
        const std::vector<uint8_t> mask =
            dof::discontinuityBand(refOf(*depth), args.band_threshold, args.band_radius);
        for (uint8_t m : mask)
            band_pixels += m;
        if (band_pixels > 0) {
            Result<dof::ErrorMetrics> r = dof::compareImages(refOf(*a), refOf(*b), &mask);
            if (!r.ok())
                return error(r.status().message());
            band = *r;
        }
    }
    const std::vector<GateCheck> checks = runGate(args, *all, differing);
    const bool passed =
        std::all_of(checks.begin(), checks.end(), [](const GateCheck& c) { return c.passed; });
    // A gate writes the difference image only when it fails: that is when someone looks at it.
    const bool write_diff = !args.diff.empty() && (!args.gated() || !passed);
    if (write_diff) {
        ImageData diff{a->width, a->height, 3,
                       dof::falseColorDifference(refOf(*a), refOf(*b), args.diff_scale)};
        if (Status s = writeImage(args.diff, diff); !s.ok())
            return error(s.message());
    }

    if (args.json) {
        nlohmann::json j;
        j["schema"] = "focal.compare";
        j["schema_version"] = kCompareSchemaVersion;
        j["a"] = args.a;
        j["b"] = args.b;
        j["width"] = a->width;
        j["height"] = a->height;
        j["all"] = toJson(*all);
        j["differing_pixels"] = differing;
        j["tolerance"] = args.tolerance;
        if (!args.depth.empty()) {
            j["depth"] = args.depth;
            j["band_threshold"] = args.band_threshold;
            j["band_radius_px"] = args.band_radius;
            j["band"] = band ? toJson(*band) : nlohmann::json();
        }
        if (write_diff)
            j["diff"] = args.diff;
        if (args.gated()) {
            nlohmann::json list = nlohmann::json::array();
            for (const GateCheck& c : checks)
                list.push_back({{"metric", c.metric},
                                {"option", c.option},
                                {"limit", number(c.limit)},
                                {"value", number(c.value)},
                                {"passed", c.passed}});
            j["gate"] = {{"passed", passed}, {"checks", list}};
        }
        std::printf("%s\n", j.dump(2).c_str());
    } else {
        printReport(args, *a, *all, band, differing, write_diff);
        for (const GateCheck& c : checks)
            std::printf("gate: %-16s %s %s %s: %s\n", c.metric.c_str(),
                        formatValue(c.value).c_str(), c.option.c_str(),
                        formatValue(c.limit).c_str(), c.passed ? "ok" : "FAILED");
    }
    for (const GateCheck& c : checks)
        if (!c.passed)
            std::fprintf(stderr, "focal: compare failed: %s vs %s: %s is %s, %s %s\n",
                         args.a.c_str(), args.b.c_str(), c.metric.c_str(),
                         formatValue(c.value).c_str(), c.option.c_str(),
                         formatValue(c.limit).c_str());
    return passed ? 0 : 1;
}

} // namespace focal
