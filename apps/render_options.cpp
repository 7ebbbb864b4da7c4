#include "apps/dof_method.h"
#include "apps/memory_option.h"
#include "apps/render_command.h"
#include "apps/settings_options.h"

#include <algorithm>
#include <cstdlib>
#include <thread>

namespace focal {

namespace {

// The scene, the image, the camera, the raster options, the method and what is written.
void addFrameOptions(CLI::App* cmd, RenderArgs& args, bool with_output) {
    cmd->add_option("scene", args.scene, "glTF file (.gltf/.glb) or builtin:NAME")->required();
    if (with_output)
        cmd->add_option("-o,--output", args.outputs,
                        "output image: .exr (linear float RGBA) or .png "
                        "(8-bit sRGB)")
            ->required();
    cmd->add_option("--width", args.width, "image width in pixels")
        ->capture_default_str()
        ->check(CLI::Range(1, 16384));
    cmd->add_option("--height", args.height, "image height in pixels")
        ->capture_default_str()
        ->check(CLI::Range(1, 16384));
    cmd->add_option("--camera", args.camera, "index of the glTF camera to use [default: 0]");
    cmd->add_option("--eye", args.eye, "camera position X,Y,Z (world units)");
    cmd->add_option("--target", args.target, "point looked at X,Y,Z (world units)");
    cmd->add_option("--up", args.up, "up direction X,Y,Z [default: 0,1,0]");
    cmd->add_option("--yfov", args.yfov_deg,
                    "vertical field of view in degrees [default: the "
                    "camera's, or 45]")
        ->check(CLI::Range(0.01f, 177.0f));
    cmd->add_option("--near", args.znear, "near clip distance (world units)");
    cmd->add_option("--far", args.zfar, "far clip distance (world units; 0 = infinite)");
    cmd->add_option("--threads", args.threads, "worker threads (0 = run inline on the caller)")
        ->capture_default_str()
        ->check(CLI::Range(0, 256));
    cmd->add_option("--memory-budget", args.memory_budget,
                    "the most memory one render may use: auto (half of physical memory), a "
                    "size (8G, 512MiB) or a percentage of physical memory (25%)")
        ->capture_default_str()
        ->check(CLI::Validator(
            [](const std::string& text) {
                const raster::Result<raster::MemoryBudget> r = parseMemoryBudget(text);
                return r.ok() ? std::string() : r.status().message();
            },
            "SIZE"));
    cmd->add_flag("--dry-run", args.dry_run,
                  "check the options, scene, view, lens and memory budget, print the request "
                  "and stop: nothing is rendered or written (autofocus falls back to the scene "
                  "bounds)");
    cmd->add_option("--tile", args.tile, "tile size in pixels (multiple of 8, 8 to 256)")
        ->capture_default_str()
        ->check(CLI::Range(8, 256))
        ->check(CLI::Validator(
            [](const std::string& text) {
                const int v = std::atoi(text.c_str());
                return v % 8 == 0 ? std::string() : text + " is not a multiple of 8";
            },
            "MULTIPLE OF 8"));
    cmd->add_option("--method", args.method, "depth-of-field method")
        ->capture_default_str()
        ->check(CLI::IsMember(methodNames()));
    cmd->add_option("--stats", args.stats_path,
                    "write every parameter, stage times (ms) and "
                    "counts to this JSON file");
    cmd->add_option("--repeat", args.repeat, "render K times; stats keep every run and the median")
        ->capture_default_str()
        ->check(CLI::Range(1, 100000));
    cmd->add_option("--depth-out", args.depth_out,
                    "also write linear depth (distance along the "
                    "view axis, world units) to this EXR");
    cmd->add_option("--depth-format", args.depth_format, "depth buffer storage")
        ->capture_default_str()
        ->check(CLI::IsMember({"float32", "unorm16"}));
    cmd->add_option("--shading", args.shading, "material: as the material says; unlit; lit")
        ->capture_default_str()
        ->check(CLI::IsMember({"material", "unlit", "lit"}));
    cmd->add_option("--texture-filter", args.texture_filter, "sampler: as the glTF sampler says")
        ->capture_default_str()
        ->check(CLI::IsMember({"sampler", "nearest", "bilinear", "trilinear"}));
}

// The lens, its samples and aperture (dof/lens_resolution.h, dof/lens_samples.h).
void addLensOptions(CLI::App* cmd, RenderArgs& args) {
    // The lens (docs/dof/lens.md). Value checks (NaN, negative, focus beyond the far plane)
    // happen in checkRenderArgs (apps/render_request.h) so they print a sentence, not a
    // validator message.
    CLI::Option* aperture = cmd->add_option(
        "--aperture-radius", args.aperture_radius,
        "lens radius E in world units (0 = pinhole) [default: the scene's lens, else 0]");
    CLI::Option* fstop = cmd->add_option(
        "--fstop", args.fstop, "f-number N; with --focal-length: E = focal_length/(2 N) in metres");
    CLI::Option* focal = cmd->add_option(
        "--focal-length", args.focal_length_mm,
        "lens focal length in mm; also sets yfov = 2 atan(sensor/2 / focal) (Blender)");
    CLI::Option* sensor = cmd->add_option("--sensor-height", args.sensor_height_mm,
                                          "sensor height in mm, vertical fit [default: 24]");
    CLI::Option* focus_d = cmd->add_option(
        "--focus-distance", args.focus_distance,
        "focus distance d_f along the view axis (world units) [default: see docs/dof/lens.md]");
    CLI::Option* focus_p =
        cmd->add_option("--focus-pixel", args.focus_pixel,
                        "focus on the depth a pinhole render shows at pixel X,Y");
    fstop->needs(focal);
    sensor->needs(focal);
    aperture->excludes(fstop);
    focus_d->excludes(focus_p);
    cmd->get_option("--yfov")->excludes(focal);
    cmd->add_option("--samples", args.samples, "accum: lens samples (views) N")
        ->capture_default_str()
        ->check(CLI::Range(1, 1 << 20));
    addSettingsOptions(*cmd, "accum", dof::accumParams(), args.accum);
    cmd->add_option("--lens-pattern", args.lens_pattern, "lens sample pattern")
        ->capture_default_str()
        ->check(CLI::IsMember({"halton", "hammersley", "poisson"}));
    cmd->add_option("--aperture-shape", args.aperture_shape,
                    "circle, polygon (--aperture-blades) or image (--aperture-image) "
                    "[default: circle]")
        ->check(CLI::IsMember({"circle", "polygon", "image"}));
    cmd->add_option("--aperture-blades", args.aperture_blades,
                    "polygon aperture: number of blades (3-64) [default: 6]")
        ->check(CLI::Range(3, 64));
    cmd->add_option("--aperture-rotation", args.aperture_rotation_deg,
                    "polygon aperture: rotation in degrees, counter-clockwise (0: a vertex up)")
        ->capture_default_str();
    cmd->add_option("--aperture-image", args.aperture_image,
                    "aperture image (bokeh mask): transmission = mean RGB x alpha, top row = up");
    cmd->add_option("--seed", args.seed,
                    "lens pattern seed (0: the unrotated pattern; otherwise a Cranley-Patterson "
                    "rotation and, for poisson, other candidates)")
        ->capture_default_str();
    cmd->add_flag("--no-progress", args.no_progress, "accum: no progress bar on stderr");
    cmd->add_flag("--no-simd", args.no_simd,
                  "run the scalar reference kernels instead of the SIMD ones (same bits)");
}

// Looking inside the GPU-emulating targets and choosing their storage (docs/targets.md).
void addTargetOptions(CLI::App* cmd, RenderArgs& args) {
    cmd->add_option("--dump-layers", args.dump_layers,
                    "write a layered decomposition (colour, depth per layer) into this folder");
    cmd->add_option("--dump-layer-count", args.dump_layer_count,
                    "layers for --dump-layers, uniform in 1/d over the visible depths")
        ->capture_default_str()
        ->check(CLI::Range(1, 64));
    cmd->add_option("--dump-fragments", args.dump_fragments,
                    "write per-pixel fragment-list counts and the first K fragment layers into "
                    "this folder");
    cmd->add_option("--dump-fragment-layers", args.dump_fragment_layers, "K for --dump-fragments")
        ->capture_default_str()
        ->check(CLI::Range(0, 64));
    cmd->add_option("--precision", args.precision,
                    "layered targets / fragment lists: 16 (half colour, unorm16 depth) or 32 "
                    "(float) [default: the method's]")
        ->check(CLI::IsMember({16, 32}));
    cmd->add_option("--target-color", args.target_color,
                    "layered targets / fragment lists: colour storage")
        ->check(CLI::IsMember({"half", "float32"}));
    cmd->add_option("--target-depth", args.target_depth,
                    "layered targets / fragment lists: depth storage")
        ->check(CLI::IsMember({"unorm16", "float32"}));
}

} // namespace

void addRenderOptions(CLI::App* cmd, RenderArgs& args, bool with_output) {
    args.threads = std::max(1u, std::thread::hardware_concurrency());
    addFrameOptions(cmd, args, with_output);
    addLensOptions(cmd, args);
    addTargetOptions(cmd, args);
    // Each method in apps/methods.cpp adds its own options, bound to this command line's table.
    args.methods = makeMethodTable();
    for (MethodEntry& m : args.methods)
        if (m.add_options)
            m.add_options(*cmd);
}

CLI::App* addRenderCommand(CLI::App& app, RenderArgs& args) {
    CLI::App* cmd = app.add_subcommand("render", "Render a scene to an image");
    addRenderOptions(cmd, args, true);
    return cmd;
}

} // namespace focal
