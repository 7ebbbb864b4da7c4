#include "apps/method_gather.h"

#include "apps/image_io.h"

#include <dof/gather.h>
#include <raster/camera.h>

#include <memory>
#include <string>
#include <variant>
#include <vector>

namespace focal {

namespace {

// Values of the --gather-* options (owned by the entry, shared by its two functions).
struct GatherArgs {
    dof::GatherSettings settings;
    bool no_skip = false;
    std::string coc_out;
    std::vector<float> coc; // the signed CoC map of the last frame (with coc_out)
};

raster::Result<dof::MethodSettings> gatherSettings(GatherArgs& args, const MethodContext& in) {
    dof::GatherMethod m;
    m.settings = args.settings;
    m.settings.tile_size = in.options.tile_size; // as dof::FrameRenderer runs it
    m.settings.skip_tiles = !args.no_skip;
    m.settings.simd = in.options.simd;
    if (raster::Status s = dof::validate(m.settings); !s.ok())
        return s;
    if (!args.coc_out.empty() && !isLinearFormat(args.coc_out))
        return raster::Status::error(args.coc_out + ": --gather-coc-out must be an .exr file");
    if (!args.coc_out.empty())
        m.coc_out = &args.coc;
    return dof::MethodSettings(m);
}

raster::Status finishGather(GatherArgs& args, const MethodContext& in,
                            const dof::MethodSettings& method, const dof::FrameReport& report,
                            MethodOutput& out) {
    const dof::GatherSettings& settings = std::get<dof::GatherMethod>(method).settings;
    const dof::GatherStats& st = std::get<dof::GatherStats>(report.method_stats);
    if (!args.coc_out.empty()) {
        ImageData img{in.view.width, in.view.height, 1, args.coc};
        if (raster::Status s = writeImage(args.coc_out, img); !s.ok())
            return s;
    }
    out.params = {{"max_radius_px", settings.max_radius_px},
                  {"leak_scale", settings.leak_scale},
                  {"min_radius_px", settings.min_radius_px},
                  {"tile_size", settings.tile_size},
                  {"skip_tiles", settings.skip_tiles},
                  {"simd", settings.simd},
                  {"depth_format",
                   in.options.depth_format == raster::DepthFormat::Unorm16 ? "unorm16" : "float32"},
                  {"coc_a_px", st.coc.a},
                  {"coc_b_px", st.coc.b}};
    out.counts = {{"tiles", st.tiles},
                  {"tiles_copied_vertical", st.tiles_copied_vertical},
                  {"tiles_copied_horizontal", st.tiles_copied_horizontal},
                  {"tiles_copied", st.tiles_copied},
                  {"samples", st.samples},
                  {"clamped_pixels", st.clamped_pixels},
                  {"min_coc_px", st.min_coc_px},
                  {"max_coc_px", st.max_coc_px}};
    return {};
}

} // namespace

MethodEntry makeGatherMethod() {
    auto args = std::make_shared<GatherArgs>();
    MethodEntry e;
    e.name = "gather";
    e.summary = "Zhou, Chen & Pullen 2007: two-pass adaptive gather filter on the pinhole colour "
                "and depth buffer";
    e.add_options = [args](CLI::App& render) {
        *args = GatherArgs{}; // each new command line starts from the defaults
        render
            .add_option("--gather-max-radius", args->settings.max_radius_px,
                        "gather: largest CoC radius honoured, pixels (1-256); larger CoCs are "
                        "clamped to it")
            ->capture_default_str();
        render
            .add_option("--gather-leak-scale", args->settings.leak_scale,
                        "gather: leakage control L = min(1, scale * r_centre) for samples "
                        "behind the focal plane (per pixel of centre CoC)")
            ->capture_default_str();
        render
            .add_option("--gather-min-radius", args->settings.min_radius_px,
                        "gather: intensity I(r) = 1/max(r, this)^2, pixels (0-1]")
            ->capture_default_str();
        render.add_flag("--gather-no-skip", args->no_skip,
                        "gather: filter every tile over the full reach (no copying of in-focus "
                        "tiles; the same output, slower)");
        render.add_option("--gather-coc-out", args->coc_out,
                          "gather: also write the signed CoC map (pixels) to this EXR");
    };
    e.settings = [args](const MethodContext& in) { return gatherSettings(*args, in); };
    e.finish = [args](const MethodContext& in, const dof::MethodSettings& method,
                      const dof::FrameRenderer&, const dof::FrameReport& report,
                      const std::vector<float>&,
                      MethodOutput& out) { return finishGather(*args, in, method, report, out); };
    return e;
}

} // namespace focal
