// `focal render`: its options, and the command that renders the frame they describe. The options
// are registered in render_options.cpp, turned into the library's requests (view, raster options,
// lens request) in render_request.h, rendered by dof::FrameRenderer in render_command.cpp, and
// reported by render_stats.h (--stats) and render_dumps.h (--dump-layers, --dump-fragments).
#pragma once

#include "apps/dof_method.h"

#include <dof/accum.h>
#include <raster/gltf_import.h>
#include <raster/renderer.h>
#include <raster/scene.h>
#include <raster/status.h>

#include <CLI/CLI.hpp>
#include <glm/vec3.hpp>
#include <nlohmann/json.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace focal {

struct RenderArgs {
    std::string scene;
    std::vector<std::string> outputs; // -o, repeatable: the same image in several files
    uint32_t width = 800;
    uint32_t height = 600;
    std::optional<int> camera;
    std::optional<std::string> eye, target, up;
    std::optional<float> yfov_deg, znear, zfar;
    uint32_t threads = 0; // set to the hardware thread count by addRenderCommand
    uint32_t tile = 64;
    std::string method = "pinhole";
    std::string stats_path;
    uint32_t repeat = 1;
    std::string depth_out;
    std::string depth_format = "float32";
    std::string shading = "material";
    std::string texture_filter = "sampler";

    // Lens: a dof::LensRequest (dof/lens_resolution.h). Unset values come from the scene's
    // LensHint, then the defaults documented in docs/dof/lens.md.
    std::optional<float> aperture_radius;   // E, world units
    std::optional<float> fstop;             // with focal_length_mm: E = f / (2 N)
    std::optional<float> focal_length_mm;   // also sets yfov from the sensor height
    std::optional<float> sensor_height_mm;  // default 24 (vertical fit)
    std::optional<float> focus_distance;    // d_f, world units
    std::optional<std::string> focus_pixel; // "X,Y": focus on the depth seen there
    // Lens sampling (dof/lens_samples.h) and accum (dof/accum.h).
    uint32_t samples = 64;
    dof::AccumSettings accum; // its table's options (dof::accumParams): --pixel-jitter
    std::string lens_pattern = "hammersley";
    std::optional<std::string> aperture_shape; // circle | polygon | image
    std::optional<uint32_t> aperture_blades;
    float aperture_rotation_deg = 0.0f;
    std::string aperture_image;
    uint32_t seed = 0;
    bool no_progress = false;
    bool no_simd = false;
    std::string memory_budget = "auto"; // apps/memory_option.h
    // Check the options, scene, view, lens and memory, print the request, render nothing.
    bool dry_run = false;
    // Looking inside the GPU-emulating targets (docs/targets.md).
    std::string dump_layers;
    uint32_t dump_layer_count = 8;
    std::string dump_fragments;
    uint32_t dump_fragment_layers = 4;
    // Storage of layered targets / fragment lists for the methods in apps/methods.cpp:
    // --precision 16|32 sets both; --target-color half|float32, --target-depth unorm16|float32
    // override one. Unset: the method's default.
    std::optional<int> precision;
    std::optional<std::string> target_color, target_depth;
    // The methods beyond pinhole and accum with this command line's option values (their
    // settings tables' options), made by addRenderOptions.
    std::vector<MethodEntry> methods;
    // Not an option: the observer of the last --repeat run's stages and probes
    // (dof/frame_observer.h), for focal steps and focal probe.
    dof::FrameObserver* observer = nullptr;
};

// A scene loaded once and rendered many times (focal bench): the scene, what loading took, and
// the options it was loaded under (the textures the shading samples, the memory budget).
struct LoadedScene {
    raster::Scene scene;
    raster::ImportStats load;
    std::string key;
};

// The frame a render command describes, in memory: the image (linear RGBA, top row first), the
// depth when --depth-out asks for it, and the --stats object (docs/stats-schema.md).
struct RenderedFrame {
    uint32_t width = 0, height = 0;
    std::vector<float> color, depth;
    nlohmann::json stats;
    double ms_median = 0.0;   // the median render time over --repeat
    uint32_t accum_views = 0; // accum: the views averaged
};

// Loads args.scene as renderFrame does: the textures the shading samples, decoded on
// args.threads threads.
raster::Result<LoadedScene> loadSceneFor(const RenderArgs& args);

// Everything `focal render` does but write the -o, --depth-out and --stats files: checks, scene
// (`loaded` when it was loaded for the same scene, shading and memory budget; else loaded here),
// view, lens, the --repeat runs on one dof::FrameRenderer, --dump-layers/--dump-fragments. A dry
// run prints its line and returns an empty image. Failures come back as the library's message
// (naming settings, not options: withOptionNames turns them into options).
raster::Result<RenderedFrame> renderFrame(const RenderArgs& args,
                                          const LoadedScene* loaded = nullptr);

// Registers the subcommand; `args` must outlive parsing.
CLI::App* addRenderCommand(CLI::App& app, RenderArgs& args);

// Registers the render command's options on `cmd` (focal steps and focal probe share them); -o
// only `with_output`.
void addRenderOptions(CLI::App* cmd, RenderArgs& args, bool with_output);

// Runs it; returns the exit code (errors are printed).
int runRender(const RenderArgs& args);

} // namespace focal
