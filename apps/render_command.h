// `focal render`: its options, and the command that renders the frame they describe. The options
// are registered in render_options.cpp, turned into the library's requests (view, raster options,
// lens request) in render_request.h, rendered by dof::FrameRenderer in render_command.cpp, and
// reported by render_stats.h (--stats) and render_dumps.h (--dump-layers, --dump-fragments).
#pragma once

#include "apps/dof_method.h"

#include <dof/accum.h>
#include <raster/renderer.h>

#include <CLI/CLI.hpp>
#include <glm/vec3.hpp>

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
    // settings tables' options), made by addRenderCommand.
    std::vector<MethodEntry> methods;
};

// Registers the subcommand; `args` must outlive parsing.
CLI::App* addRenderCommand(CLI::App& app, RenderArgs& args);

// Runs it; returns the exit code (errors are printed).
int runRender(const RenderArgs& args);

} // namespace focal
