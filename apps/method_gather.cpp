#include "apps/method_gather.h"

#include "apps/image_io.h"

#include <dof/gather.h>
#include <raster/camera.h>
#include <raster/frame.h>
#include <raster/renderer.h>

#include <chrono>
#include <memory>
#include <string>

namespace focal {

namespace {

// Values of the --gather-* options (owned by the entry, shared by its two functions).
struct GatherArgs {
    dof::GatherSettings settings;
    bool no_skip = false;
    std::string coc_out;
};

raster::Status runGather(const GatherArgs& args, const MethodInput& in, MethodOutput& out) {
    dof::GatherSettings settings = args.settings;
    settings.tile_size = in.options.tile_size;
    settings.skip_tiles = !args.no_skip;
    settings.simd = in.options.simd;
    if (raster::Status s = dof::validate(settings); !s.ok())
        return s;
    if (raster::Status s = dof::validate(in.lens, in.view); !s.ok())
        return s;
    if (!args.coc_out.empty() && !isLinearFormat(args.coc_out))
        return raster::Status::error(args.coc_out + ": --gather-coc-out must be an .exr file");

    // The pinhole frame through the lens centre (§5: the application renders as before).
    const auto t0 = std::chrono::steady_clock::now();
    raster::View pinhole = in.view;
    pinhole.lens_offset = glm::vec2(0.0f);
    pinhole.pixel_shift = glm::vec2(0.0f);
    MethodBuffers local;
    MethodBuffers& buffers = in.buffers ? *in.buffers : local;
    raster::Frame& frame = buffers.pinhole;
    if (raster::Status s = buffers.renderer(in.pool).render(in.scene, pinhole, in.options, frame);
        !s.ok())
        return s;
    const double ms_render =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();

    dof::GatherImage image;
    image.rgba = frame.color.data();
    image.depth = dof::depthRefOf(frame.depth);
    image.width = frame.width;
    image.height = frame.height;
    std::vector<float> coc;
    raster::Result<dof::GatherStats> r =
        dof::gather(image, in.lens, pinhole, settings, out.rgba,
                    args.coc_out.empty() ? nullptr : &coc, &in.pool);
    if (!r.ok())
        return r.status();
    if (!args.coc_out.empty()) {
        ImageData img{frame.width, frame.height, 1, std::move(coc)};
        if (raster::Status s = writeImage(args.coc_out, img); !s.ok())
            return s;
    }

    out.depth.resize(size_t(frame.width) * frame.height);
    for (size_t i = 0; i < out.depth.size(); ++i)
        out.depth[i] = raster::distanceFromDepth(pinhole, frame.depth.load(i));
    const dof::GatherStats& st = *r;
    out.params = {{"max_radius_px", settings.max_radius_px},
                  {"leak_scale", settings.leak_scale},
                  {"min_radius_px", settings.min_radius_px},
                  {"tile_size", settings.tile_size},
                  {"skip_tiles", settings.skip_tiles},
                  {"simd", settings.simd},
                  {"depth_format",
                   frame.depth.format == raster::DepthFormat::Unorm16 ? "unorm16" : "float32"},
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
    out.stage_ms = {{"render", ms_render},
                    {"coc", st.ms_coc},
                    {"vertical", st.ms_vertical},
                    {"horizontal", st.ms_horizontal}};
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
    e.run = [args](const MethodInput& in, MethodOutput& out) { return runGather(*args, in, out); };
    return e;
}

} // namespace focal
