#include "apps/steps_command.h"

#include "apps/image_io.h"
#include "apps/render_request.h"
#include "apps/settings_options.h"
#include "apps/steps_page.h"
#include "apps/steps_recorder.h"
#include "apps/text_file.h"

#include <dof/metrics.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <system_error>
#include <unistd.h>

namespace focal {

using raster::Result;
using raster::Status;

namespace {

namespace fs = std::filesystem;

int fail(const std::string& message) {
    std::fprintf(stderr, "focal: error: %s\n", withOptionNames(message).c_str());
    return 1;
}

// The grid's pixels (every `grid` pixels, from grid/2) and the extra ones, sorted by (y, x),
// without repeats.
Result<std::vector<glm::uvec2>> probePixels(const StepsArgs& args) {
    std::vector<glm::uvec2> pixels;
    const uint32_t w = args.render.width, h = args.render.height, g = args.probe_grid;
    if (g > 0)
        for (uint32_t y = g / 2; y < h; y += g)
            for (uint32_t x = g / 2; x < w; x += g)
                pixels.emplace_back(x, y);
    for (const std::string& text : args.probes) {
        Result<glm::uvec2> p = parsePixel("--probe", text);
        if (!p.ok())
            return p.status();
        if (p->x >= w || p->y >= h)
            return Status::error("--probe " + text + " is outside the " + std::to_string(w) + "x" +
                                 std::to_string(h) + " image");
        pixels.push_back(*p);
    }
    std::sort(pixels.begin(), pixels.end(),
              [](glm::uvec2 a, glm::uvec2 b) { return a.y != b.y ? a.y < b.y : a.x < b.x; });
    pixels.erase(std::unique(pixels.begin(), pixels.end()), pixels.end());
    return pixels;
}

std::string joined(const std::vector<std::string>& words) {
    std::string s;
    for (const std::string& w : words)
        s += (s.empty() ? "" : " ") + (w.find(' ') == std::string::npos ? w : "'" + w + "'");
    return s;
}

// The steps command line turned into the probe command's, with X,Y to fill in: `steps` becomes
// `probe`, the pixel follows the scene, and the options only steps has are dropped.
std::string probeCommand(const StepsArgs& args) {
    std::vector<std::string> words;
    const std::vector<std::string>& cmd = args.command;
    const auto steps_only = [](const std::string& w) {
        return w == "-o" || w == "--output" || w == "--probe-grid" || w == "--probe" ||
               w == "--reference-samples";
    };
    for (size_t i = 0; i < cmd.size(); ++i) {
        const std::string& w = cmd[i];
        if (steps_only(w)) {
            ++i; // and its value
            continue;
        }
        if (w.rfind("--output=", 0) == 0 || w.rfind("--probe-grid=", 0) == 0 ||
            w.rfind("--probe=", 0) == 0 || w.rfind("--reference-samples=", 0) == 0)
            continue;
        words.push_back(w == "steps" ? "probe" : w);
        if (w == args.render.scene)
            words.push_back("X,Y");
    }
    return joined(words);
}

// A new empty folder next to `dir` that becomes `dir` when everything is written, so a failure
// never leaves half a folder under the name asked for.
Result<std::string> partialFolder(const std::string& dir) {
    std::error_code ec;
    if (fs::exists(dir, ec) && !fs::exists(fs::path(dir) / "steps.json", ec))
        return Status::error(dir + ": exists and is not a focal steps folder (no steps.json); "
                                   "choose another -o");
    const std::string tmp = dir + ".partial-" + std::to_string(::getpid());
    fs::remove_all(tmp, ec);
    if (!fs::create_directories(fs::path(tmp) / "images", ec) || ec)
        return Status::error(tmp + ": cannot create the folder (" + ec.message() + ")");
    return tmp;
}

Status replaceFolder(const std::string& tmp, const std::string& dir) {
    std::error_code ec;
    fs::remove_all(dir, ec);
    if (ec)
        return Status::error(dir + ": cannot replace the old folder (" + ec.message() + ")");
    fs::rename(tmp, dir, ec);
    if (ec)
        return Status::error(dir + ": cannot move " + tmp + " into place (" + ec.message() + ")");
    return {};
}

std::vector<float> rgbOf(const std::vector<float>& rgba) {
    std::vector<float> rgb(rgba.size() / 4 * 3);
    for (size_t i = 0; i < rgba.size() / 4; ++i)
        std::copy(&rgba[4 * i], &rgba[4 * i] + 3, &rgb[3 * i]);
    return rgb;
}

// The side-by-side: result, reference and difference pictures and the metrics between them.
Result<nlohmann::json> compareBlock(const std::string& folder, const RenderedFrame& result,
                                    const RenderedFrame& reference, uint32_t samples) {
    constexpr float kDiffScale = 0.1f; // sRGB difference shown at full colour
    const dof::ImageRef a{result.color.data(), result.width, result.height, 4};
    const dof::ImageRef b{reference.color.data(), reference.width, reference.height, 4};
    const ImageData diff{result.width, result.height, 3,
                         dof::falseColorDifference(a, b, kDiffScale)};
    for (const auto& [file, image] :
         {std::pair{"images/result.png",
                    ImageData{result.width, result.height, 3, rgbOf(result.color)}},
          std::pair{"images/reference.png",
                    ImageData{reference.width, reference.height, 3, rgbOf(reference.color)}},
          std::pair{"images/difference.png", diff}})
        if (Status s = writeImage(folder + "/" + file, image); !s.ok())
            return s;
    nlohmann::json j = {{"result", "images/result.png"},
                        {"reference", "images/reference.png"},
                        {"difference", "images/difference.png"},
                        {"reference_samples", samples},
                        {"psnr_db", nullptr},
                        {"ssim", nullptr}};
    // The metrics need 11x11 pixels (SSIM's window); smaller frames show the pictures only.
    if (Result<dof::ErrorMetrics> m = dof::compareImages(a, b); m.ok()) {
        j["psnr_db"] = finiteOrNull(m->psnr_srgb_db);
        j["ssim"] = m->ssim;
    }
    j["caption"] = "difference: the largest |result − reference| over RGB of sRGB values, full "
                   "colour at 0.1; PSNR over sRGB, SSIM of the sRGB luma (docs/compare-schema.md)";
    return j;
}

} // namespace

CLI::App* addStepsCommand(CLI::App& app, StepsArgs& args) {
    CLI::App* cmd = app.add_subcommand(
        "steps", "Step through every stage of one frame in a browser: writes DIR/index.html "
                 "(docs/steps.md)");
    // Small frames: a page shows every stage's pictures.
    args.render.width = 320;
    args.render.height = 240;
    addRenderOptions(cmd, args.render, false);
    cmd->add_option("-o,--output", args.out_dir,
                    "folder to write (created; replaced when it holds an older steps folder)")
        ->required();
    cmd->add_option("--probe-grid", args.probe_grid,
                    "probe every N pixels in x and y (0: only the --probe pixels)")
        ->capture_default_str()
        ->check(CLI::Range(0, 4096));
    cmd->add_option("--probe", args.probes, "also probe this pixel X,Y (repeatable)");
    cmd->add_option("--reference-samples", args.reference_samples,
                    "lens samples of the accum reference shown beside the result")
        ->capture_default_str()
        ->check(CLI::Range(1, 65536));
    return cmd;
}

CLI::App* addProbeCommand(CLI::App& app, ProbeArgs& args) {
    CLI::App* cmd = app.add_subcommand(
        "probe", "Print what made one pixel of a frame as JSON (the probe focal steps shows)");
    addRenderOptions(cmd, args.render, false);
    cmd->add_option("pixel", args.pixel, "the pixel X,Y (0,0 is the top-left)")->required();
    return cmd;
}

int runSteps(StepsArgs& args) {
    RenderArgs& render = args.render;
    if (render.dry_run)
        return fail("--dry-run renders nothing: there are no stages to step through");
    Result<std::vector<glm::uvec2>> pixels = probePixels(args);
    if (!pixels.ok())
        return fail(pixels.status().message());
    Result<LoadedScene> loaded = loadSceneFor(render);
    if (!loaded.ok())
        return fail(loaded.status().message());
    Result<std::string> folder = partialFolder(args.out_dir);
    if (!folder.ok())
        return fail(folder.status().message());
    const auto failed = [&](const std::string& message) {
        std::error_code ec;
        fs::remove_all(*folder, ec);
        return fail(message);
    };

    StepsRecorder recorder(*folder, *pixels);
    render.observer = &recorder;
    Result<RenderedFrame> frame = renderFrame(render, &*loaded);
    render.observer = nullptr;
    if (!frame.ok())
        return failed(frame.status().message());
    if (!recorder.status().ok())
        return failed(recorder.status().message());

    // The reference beside it: accum with the same lens and more samples.
    RenderArgs ref = render;
    ref.method = "accum";
    ref.samples = args.reference_samples;
    ref.repeat = 1;
    ref.dump_layers.clear();
    ref.dump_fragments.clear();
    ref.depth_out.clear();
    ref.no_progress = true;
    Result<RenderedFrame> reference = renderFrame(ref, &*loaded);
    if (!reference.ok())
        return failed("the accum reference: " + reference.status().message());
    Result<nlohmann::json> compare =
        compareBlock(*folder, *frame, *reference, args.reference_samples);
    if (!compare.ok())
        return failed(compare.status().message());
    for (nlohmann::json& p : recorder.probes()) {
        const float* r =
            reference->color.data() + (size_t(p["y"]) * reference->width + size_t(p["x"])) * 4;
        p["reference_rgba"] = {finiteOrNull(r[0]), finiteOrNull(r[1]), finiteOrNull(r[2]),
                               finiteOrNull(r[3])};
    }

    const nlohmann::json data = {{"format_version", 1},
                                 {"focal_version", "0.1.0"},
                                 {"command", joined(args.command)},
                                 {"probe_command", probeCommand(args)},
                                 {"scene", render.scene},
                                 {"method", render.method},
                                 {"width", frame->width},
                                 {"height", frame->height},
                                 {"stages", std::move(recorder.stages())},
                                 {"compare", std::move(*compare)},
                                 {"probe_grid", args.probe_grid},
                                 {"probes", std::move(recorder.probes())}};
    const std::string json = data.dump();
    if (Status s = writeTextFile(*folder + "/steps.json", json + "\n"); !s.ok())
        return failed(s.message());
    if (Status s =
            writeTextFile(*folder + "/steps_data.js", "window.FOCAL_STEPS = " + json + ";\n");
        !s.ok())
        return failed(s.message());
    if (Status s = writeStepsPage(*folder); !s.ok())
        return failed(s.message());
    if (Status s = replaceFolder(*folder, args.out_dir); !s.ok())
        return failed(s.message());
    std::printf("focal: wrote %s/index.html (%s, %zu stages, %zu probed pixels)\n",
                args.out_dir.c_str(), render.method.c_str(), data["stages"].size(),
                data["probes"].size());
    return 0;
}

int runProbe(ProbeArgs& args) {
    Result<glm::uvec2> pixel = parsePixel("pixel", args.pixel);
    if (!pixel.ok())
        return fail(pixel.status().message());
    if (pixel->x >= args.render.width || pixel->y >= args.render.height)
        return fail("pixel " + args.pixel + " is outside the " + std::to_string(args.render.width) +
                    "x" + std::to_string(args.render.height) + " image");
    StepsRecorder recorder("", {*pixel});
    args.render.observer = &recorder;
    Result<RenderedFrame> frame = renderFrame(args.render);
    args.render.observer = nullptr;
    if (!frame.ok())
        return fail(frame.status().message());
    std::printf("%s\n", recorder.probes().at(0).dump(2).c_str());
    return 0;
}

} // namespace focal
