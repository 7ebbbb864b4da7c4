// How `focal render --method NAME` runs a depth-of-field method that lives in dof/: each method
// adds its own options to the render command and runs from a MethodInput. The table of methods
// is in apps/methods.cpp (one line per method); render_command.cpp dispatches through it.
#pragma once

#include <dof/lens.h>
#include <dof/lens_samples.h>
#include <dof/multilayer.h>
#include <dof/multiview.h>
#include <raster/camera.h>
#include <raster/renderer.h>
#include <raster/scene.h>
#include <raster/status.h>
#include <raster/task_pool.h>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace focal {

// What a method keeps from one run to the next of a render command (`--repeat`, the bench's
// timed runs): its renderer and its targets and scratch, so that a repeated frame reuses their
// memory instead of allocating, faulting in and clearing it again. The same bytes as fresh ones
// (each method overwrites or clears everything it reads). Issue 20's FrameRenderer is to own
// these in the library.
class MethodBuffers {
public:
    // The renderer over `pool` (made again if the pool changes).
    raster::Renderer& renderer(raster::TaskPool& pool) {
        if (!renderer_ || pool_ != &pool) {
            renderer_ = std::make_unique<raster::Renderer>(pool);
            pool_ = &pool;
        }
        return *renderer_;
    }
    raster::Frame pinhole;        // the pinhole frame through the lens centre
    raster::LayeredTarget layers; // multiview's layered target (§4.2 of Lee et al. 2009)
    dof::MultiviewScratch multiview;
    dof::Multilayer multilayer;

private:
    std::unique_ptr<raster::Renderer> renderer_;
    const raster::TaskPool* pool_ = nullptr;
};

// What every method gets: the scene, the pinhole view through the lens centre, the thin lens
// (from --aperture-radius/--fstop/--focus-distance/...), the lens samples shared with accum
// (--samples, --lens-pattern, --aperture-shape/-blades/-rotation/-image, --seed), the pool and
// the raster options (--tile, --depth-format, --shading, --texture-filter).
struct MethodInput {
    const raster::Scene& scene;
    const raster::View& view;
    const dof::ThinLens& lens;
    const dof::LensSampleSet& lens_samples;
    raster::TaskPool& pool;
    const raster::RenderOptions& options;
    // Storage of the layered target / fragment lists (--precision 16|32, --target-color,
    // --target-depth); unset: the method's own default (e.g. Selgrad et al.: half colour, float
    // depth).
    std::optional<raster::ColorFormat> target_color;
    std::optional<raster::DepthFormat> target_depth;
    // The aperture the lens samples were drawn on (--aperture-shape ...), for methods that draw
    // their own per-pixel sample sets (e.g. multiview's 2N Halton jitter).
    const dof::ApertureShape* aperture = nullptr;
    // Kept between runs by the caller (MethodBuffers).
    MethodBuffers* buffers = nullptr;
};

// What it returns for one run.
struct MethodOutput {
    std::vector<float> rgba;  // linear RGBA, view.width * view.height * 4, top row first
    std::vector<float> depth; // optional: linear distance along the view axis per pixel
    nlohmann::json params;    // every parameter the method used (recorded in --stats)
    nlohmann::json counts;    // method-specific counters (recorded in --stats)
    std::vector<std::pair<std::string, double>> stage_ms; // per-stage times, in stage order
};

struct MethodEntry {
    std::string name;
    std::string summary; // one line for --help
    // Adds the method's options to `focal render` (values live in the method's own statics-free
    // args object owned by the entry).
    std::function<void(CLI::App& render)> add_options;
    std::function<raster::Status(const MethodInput&, MethodOutput&)> run;
    // Optional: a lower bound of the bytes a run holds for `view` with `samples` lens samples on
    // `workers` workers, checked against --memory-budget before anything is rendered.
    std::function<uint64_t(const raster::View& view, uint32_t samples, uint32_t workers)>
        minimum_bytes;
};

// The methods beyond pinhole and accum, in a fixed order (apps/methods.cpp).
std::vector<MethodEntry>& methodTable();

} // namespace focal
