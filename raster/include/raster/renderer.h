// Renderer: runs the pinhole raster pipeline — geometry (transform, clip, cull), binning,
// tile raster (coverage, depth, shading) — on a TaskPool and fills a Frame. It owns the
// per-frame working memory and reuses it between frames, so render many views with one Renderer.
// Output bytes are identical for any thread count and tile size (docs/raster.md).
#pragma once

#include <raster/camera.h>
#include <raster/frame.h>
#include <raster/scene.h>
#include <raster/status.h>
#include <raster/task_pool.h>
#include <raster/texture.h>

#include <cstdint>
#include <memory>

namespace raster {

enum class ShadingMode : uint8_t {
    Material,  // lit, except materials with KHR_materials_unlit
    Unlit,     // base colour x texture x vertex colour (+ emissive)
    Lit,       // Lambert + Blinn-Phong for every material
};

struct RenderOptions {
    uint32_t tile_size = 64;  // pixels, a multiple of 8 in [8, 256]
    DepthFormat depth_format = DepthFormat::Float32;
    ShadingMode shading = ShadingMode::Material;
    FilterOverride texture_filter = FilterOverride::Sampler;
};

// Counts and stage times of one render. Counts are deterministic; times are not.
struct FrameStats {
    uint64_t triangles_in = 0;       // triangles submitted
    uint64_t triangles_culled = 0;   // back-facing, zero-area, or outside the frustum
    uint64_t triangles_clipped = 0;  // cut by the near/far planes or beyond the guard band
    uint64_t triangles_setup = 0;    // triangles that reached binning (after clipping)
    uint64_t fragments_covered = 0;  // samples inside a triangle
    uint64_t fragments_passed = 0;   // of those, passed alpha and depth tests
    double ms_geometry = 0.0;
    double ms_binning = 0.0;
    double ms_raster = 0.0;
};

class Renderer {
public:
    explicit Renderer(TaskPool& pool);
    ~Renderer();
    Renderer(const Renderer&) = delete;
    Renderer& operator=(const Renderer&) = delete;

    // Renders `scene` seen through `view` into `out` (resized to view.width x view.height).
    // Fails only on invalid options or views; never on scene content.
    Status render(const Scene& scene, const View& view, const RenderOptions& options, Frame& out,
                  FrameStats* stats = nullptr);

private:
    struct State;
    TaskPool& pool_;
    std::unique_ptr<State> state_;
};

// Validates options the user can set (tile size range, etc.).
Status validate(const RenderOptions& options);
Status validate(const View& view);

}  // namespace raster
