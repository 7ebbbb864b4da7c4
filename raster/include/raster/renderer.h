// Renderer: runs the pinhole raster pipeline — geometry (transform, clip, cull), binning,
// tile raster (coverage, depth, shading) — on a TaskPool and fills a Frame. It owns the
// per-frame working memory and reuses it between frames, so render many views with one Renderer.
// Output bytes are identical for any thread count and tile size (docs/raster.md).
#pragma once

#include <raster/camera.h>
#include <raster/fragment_lists.h>
#include <raster/frame.h>
#include <raster/layered_target.h>
#include <raster/memory_budget.h>
#include <raster/scene.h>
#include <raster/status.h>
#include <raster/task_pool.h>
#include <raster/texture.h>

#include <cstdint>
#include <memory>
#include <vector>

namespace raster {

enum class ShadingMode : uint8_t {
    Material, // lit, except materials with KHR_materials_unlit
    Unlit,    // base colour x texture x vertex colour (+ emissive)
    Lit,      // Lambert + Blinn-Phong for every material
};

// The texture roles shading in `mode` can sample: the images a scene must have decoded for it
// (ImportOptions::roles). Every mode reads base colour (colour and alpha) and emissive; lighting
// uses the metallic and roughness factors, never a metallic-roughness, normal or occlusion map.
TextureRoles sampledTextureRoles(ShadingMode mode);

struct RenderOptions {
    uint32_t tile_size = 64; // pixels, a multiple of 8 in [8, 256]
    DepthFormat depth_format = DepthFormat::Float32;
    ShadingMode shading = ShadingMode::Material;
    FilterOverride texture_filter = FilterOverride::Sampler;
    // Use the SIMD kernels when the CPU has them (same bits); false runs the scalar reference.
    bool simd = true;
    // Depth peeling (Everitt 2001), for Renderer::render only: when set, fragments whose stored
    // depth is not strictly behind this buffer's value (same size and format as the frame's) are
    // discarded, so repeated renders peel the scene front to back.
    const DepthBuffer* peel_depth = nullptr;
    // Renderer::render only: OPAQUE surfaces write their depth unshaded (no texture, fragment
    // or lighting kernel), for a caller that needs the visible depths only (multiview's depth
    // range, Lee et al. 2009 §4.1). The depth buffers are the same bits as a shaded render's;
    // the colour is not (MASK and BLEND surfaces are still shaded, their alpha decides what they
    // cover, but opaque surfaces leave the background).
    bool depth_only = false;
    // Checked before the target's buffers are allocated (frameBytes, layeredTargetBytes, the
    // fragment pool: frame.h, layered_target.h); a render that does not fit fails with a Status
    // naming the sizes.
    MemoryBudget memory_budget;
};

// Counts and stage times of one render. Counts are deterministic; times are not.
struct FrameStats {
    uint64_t triangles_in = 0;      // triangles submitted
    uint64_t triangles_culled = 0;  // back-facing, zero-area, or outside the frustum
    uint64_t triangles_clipped = 0; // cut by the near/far planes or beyond the guard band
    uint64_t triangles_setup = 0;   // triangles that reached binning (after clipping)
    uint64_t fragments_covered = 0; // samples inside a triangle
    uint64_t fragments_passed = 0;  // of those, passed alpha and depth tests
    double ms_geometry = 0.0;
    double ms_binning = 0.0;
    double ms_raster = 0.0;
    // Lists: sort, cap and compact; layers: the fragment-copy pass. The per-tile part (the
    // copy; the sort and cap) runs in each tile's raster task while the tile's data is in the
    // cache, so it is part of ms_raster too: its time summed over the tiles, plus (lists) the
    // compaction that follows.
    double ms_resolve = 0.0;
    uint64_t target_bytes = 0; // memory held by the render target's buffers
};

class Renderer {
public:
    explicit Renderer(TaskPool& pool);
    ~Renderer();
    Renderer(const Renderer&) = delete;
    Renderer& operator=(const Renderer&) = delete;

    // Renders `scene` seen through `view` into `out` (resized to view.width x view.height).
    // Fails only on invalid options or views, when a material's texture in a role the shading
    // samples has no pixels (an image import skipped), or when the target exceeds
    // options.memory_budget or cannot be allocated; never on other scene content.
    Status render(const Scene& scene, const View& view, const RenderOptions& options, Frame& out,
                  FrameStats* stats = nullptr);

    // Layered rendering (Lee et al. 2009 §4.2) into desc.bounds.size() - 1 layers, each with its
    // own depth buffer, routed as desc.routing says. options.depth_format is not used (the
    // target has its own formats). Fails on invalid bounds (fewer than 2, not increasing, not
    // positive, more than kMaxLayers layers) or overlap outside [0, 1].
    Status renderLayers(const Scene& scene, const View& view, const RenderOptions& options,
                        const LayeredTargetDesc& desc, LayeredTarget& out,
                        FrameStats* stats = nullptr);

    // Per-pixel fragment lists (Selgrad et al. 2015 §4): collect every fragment, then sort,
    // keep the closest desc.max_per_pixel and compact. When more than desc.node_capacity nodes
    // are needed: OverflowPolicy::Fail returns an error with both counts; Grow enlarges the
    // pool to what was needed (out.grew, out.node_capacity_used). `out`'s arrays are reused:
    // a second call of the same size and lists into the same `out` allocates nothing.
    Status renderFragmentLists(const Scene& scene, const View& view, const RenderOptions& options,
                               const FragmentListDesc& desc, FragmentLists& out,
                               FrameStats* stats = nullptr);

    // The next render call (any kind) reuses the last call's geometry and bins (transform,
    // clipping, culling, setup, binning) when its scene, view and tile size are the last
    // call's, instead of making them again: the caller promises that the scene has not changed
    // since that call, which the Renderer cannot see. For a caller that renders one scene twice
    // from the same eye, as multiview renders a pinhole and then its layers (Lee et al. §4.1,
    // §4.2). From another view of the same scene it keeps what does not depend on the view
    // (the draws, and each vertex's world position, normal, uv and colour) and makes the rest
    // again: accum's views (Haeberli & Akeley). Either way the bytes are a fresh render's. The
    // promise holds for the next call only.
    void promiseSceneUnchanged();

    // Triangles binned to each tile by the last render call (any kind), summed over the geometry
    // chunks, row-major over `tiles_x` x `tiles_y` tiles of options.tile_size pixels: the binning
    // stage's load per tile, for looking inside (focal steps). Resizes `out`.
    void tileTriangleCounts(std::vector<uint32_t>& out, uint32_t& tiles_x, uint32_t& tiles_y) const;

private:
    // Geometry and bins for this call (kept from the last one when scene_unchanged and its
    // scene, view and tile size are the same), and the raster context.
    Status prepare(const Scene& scene, const View& view, const RenderOptions& options,
                   bool scene_unchanged, FrameStats* stats);
    struct State;
    TaskPool& pool_;
    std::unique_ptr<State> state_;
};

constexpr uint32_t kMaxLayers = 64;

// Validates options the user can set (tile size range, etc.).
Status validate(const RenderOptions& options);
Status validate(const View& view);
// Checks that every image a material samples under `mode` was decoded (Image::decoded).
Status validateTextures(const Scene& scene, ShadingMode mode);

} // namespace raster
