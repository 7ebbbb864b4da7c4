#include "apps/method_gather.h"

#include "apps/image_io.h"
#include "apps/settings_options.h"

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
    dof::GatherSettings settings; // the table's options (dof::gatherParams)
    std::string coc_out;
    std::vector<float> coc; // the signed CoC map of the last frame (with coc_out)
};

raster::Result<dof::MethodSettings> gatherSettings(GatherArgs& args, const MethodContext& in) {
    dof::GatherMethod m;
    m.settings = args.settings;
    m.settings.tile_size = in.options.tile_size; // as dof::FrameRenderer runs it
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
    out.params = settingsJson(dof::gatherParams(), settings);
    out.params["tile_size"] = settings.tile_size;
    out.params["simd"] = settings.simd;
    out.params["depth_format"] =
        in.options.depth_format == raster::DepthFormat::Unorm16 ? "unorm16" : "float32";
    out.params["coc_a_px"] = st.coc.a;
    out.params["coc_b_px"] = st.coc.b;
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
        addSettingsOptions(render, "gather", dof::gatherParams(), args->settings);
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
