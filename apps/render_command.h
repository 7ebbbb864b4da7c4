// `focal render`: options, and the render job they describe.
#pragma once

#include <raster/renderer.h>

#include <cstdint>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>
#include <glm/vec3.hpp>

namespace focal {

struct RenderArgs {
    std::string scene;
    std::string output;
    uint32_t width = 800;
    uint32_t height = 600;
    std::optional<int> camera;
    std::optional<std::string> eye, target, up;
    std::optional<float> yfov_deg, znear, zfar;
    uint32_t threads = 0;  // set to the hardware thread count by addRenderCommand
    uint32_t tile = 64;
    std::string method = "pinhole";
    std::string stats_path;
    uint32_t repeat = 1;
    std::string depth_out;
    std::string depth_format = "float32";
    std::string shading = "material";
    std::string texture_filter = "sampler";
};

// Registers the subcommand; `args` must outlive parsing.
CLI::App* addRenderCommand(CLI::App& app, RenderArgs& args);

// Runs it; returns the exit code (errors are printed).
int runRender(const RenderArgs& args);

}  // namespace focal
