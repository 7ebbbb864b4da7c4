#include "apps/compare_command.h"

#include "apps/image_io.h"

#include <dof/metrics.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <optional>

namespace focal {

using raster::Result;
using raster::Status;

namespace {

int fail(const std::string& message) {
    std::fprintf(stderr, "focal: error: %s\n", message.c_str());
    return 1;
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

nlohmann::json toJson(const dof::ErrorMetrics& m) {
    return {{"pixels", m.pixels},
            {"psnr_linear_db", number(m.psnr_linear_db)},
            {"psnr_srgb_db", number(m.psnr_srgb_db)},
            {"ssim", number(m.ssim)},
            {"ssim_windows", m.ssim_windows},
            {"mean_abs_error", m.mean_abs_error},
            {"max_abs_error", m.max_abs_error}};
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
    return cmd;
}

int runCompare(const CompareArgs& args) {
    for (float v : {args.band_threshold, args.band_radius, args.diff_scale})
        if (!std::isfinite(v))
            return fail("--band-threshold, --band-radius and --diff-scale must be finite");
    Result<ImageData> a = readImage(args.a);
    if (!a.ok())
        return fail(a.status().message());
    Result<ImageData> b = readImage(args.b);
    if (!b.ok())
        return fail(b.status().message());
    if (a->width != b->width || a->height != b->height)
        return fail(args.a + " is " + std::to_string(a->width) + "x" + std::to_string(a->height) +
                    " but " + args.b + " is " + std::to_string(b->width) + "x" +
                    std::to_string(b->height) + "; compare needs images of the same size");
    Result<dof::ErrorMetrics> all = dof::compareImages(refOf(*a), refOf(*b));
    if (!all.ok())
        return fail(args.a + " vs " + args.b + ": " + all.status().message());

    std::optional<dof::ErrorMetrics> band;
    uint64_t band_pixels = 0;
    if (!args.depth.empty()) {
        Result<ImageData> depth = readImage(args.depth);
        if (!depth.ok())
            return fail(depth.status().message());
        if (depth->width != a->width || depth->height != a->height)
            return fail(args.depth + " is " + std::to_string(depth->width) + "x" +
                        std::to_string(depth->height) + " but the images are " +
                        std::to_string(a->width) + "x" + std::to_string(a->height));
        const std::vector<uint8_t> mask =
            dof::discontinuityBand(refOf(*depth), args.band_threshold, args.band_radius);
        for (uint8_t m : mask)
            band_pixels += m;
        if (band_pixels > 0) {
            Result<dof::ErrorMetrics> r = dof::compareImages(refOf(*a), refOf(*b), &mask);
            if (!r.ok())
                return fail(r.status().message());
            band = *r;
        }
    }
    if (!args.diff.empty()) {
        ImageData diff{a->width, a->height, 3,
                       dof::falseColorDifference(refOf(*a), refOf(*b), args.diff_scale)};
        if (Status s = writeImage(args.diff, diff); !s.ok())
            return fail(s.message());
    }

    if (args.json) {
        nlohmann::json j;
        j["a"] = args.a;
        j["b"] = args.b;
        j["width"] = a->width;
        j["height"] = a->height;
        j["all"] = toJson(*all);
        if (!args.depth.empty()) {
            j["depth"] = args.depth;
            j["band_threshold"] = args.band_threshold;
            j["band_radius_px"] = args.band_radius;
            j["band"] = band ? toJson(*band) : nlohmann::json();
        }
        if (!args.diff.empty())
            j["diff"] = args.diff;
        std::printf("%s\n", j.dump(2).c_str());
        return 0;
    }
    std::printf("%s vs %s (%ux%u)\n", args.a.c_str(), args.b.c_str(), a->width, a->height);
    std::printf("%-14s %16s", "", "all pixels");
    if (band)
        std::printf(" %16s", "depth band");
    std::printf("\n");
    auto row = [&](const char* name, auto get) {
        std::printf("%-14s %16s", name, get(*all).c_str());
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
    if (!args.depth.empty() && !band)
        std::printf("depth band: no depth discontinuities in %s\n", args.depth.c_str());
    if (!args.diff.empty())
        std::printf("wrote %s\n", args.diff.c_str());
    return 0;
}

} // namespace focal
