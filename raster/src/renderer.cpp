#include <raster/renderer.h>

#include "binning.h"
#include "geometry.h"
#include "tile_raster.h"

#include <chrono>
#include <cmath>
#include <string>

#include <glm/geometric.hpp>

namespace raster {

struct Renderer::State {
    GeometryState geometry;
    std::vector<ChunkBins> bins;
    std::vector<TileCounters> tile_counters;
};

Renderer::Renderer(TaskPool& pool) : pool_(pool), state_(std::make_unique<State>()) {}
Renderer::~Renderer() = default;

Status validate(const RenderOptions& options) {
    if (options.tile_size < 8 || options.tile_size > 256 || options.tile_size % 8 != 0)
        return Status::error("tile size " + std::to_string(options.tile_size) +
                             " must be a multiple of 8 between 8 and 256");
    return {};
}

Status validate(const View& view) {
    if (view.width == 0 || view.height == 0 || view.width > kMaxViewport ||
        view.height > kMaxViewport)
        return Status::error("image size " + std::to_string(view.width) + "x" +
                             std::to_string(view.height) + " must be between 1 and " +
                             std::to_string(kMaxViewport) + " pixels on each side");
    if (!(view.yfov > 1e-4f && view.yfov < 3.1f))
        return Status::error("vertical field of view must be between 0 and 177 degrees");
    if (!(view.znear > 0.0f) || !std::isfinite(view.znear))
        return Status::error("near plane must be a positive distance");
    if (!(view.zfar == 0.0f || (view.zfar > view.znear && std::isfinite(view.zfar))))
        return Status::error("far plane must be beyond the near plane (or 0 for infinite)");
    const auto unit = [](glm::vec3 v) {
        return std::isfinite(v.x + v.y + v.z) && std::abs(glm::length(v) - 1.0f) < 1e-3f;
    };
    if (!std::isfinite(view.eye.x + view.eye.y + view.eye.z) || !unit(view.forward) ||
        !unit(view.right) || !unit(view.up) || std::abs(glm::dot(view.forward, view.up)) > 1e-3f)
        return Status::error("camera eye and axes must be finite, and up must not be parallel to "
                             "the view direction");
    if (!(view.focus_distance > 0.0f) || !std::isfinite(view.focus_distance))
        return Status::error("focus distance must be a positive, finite distance");
    return {};
}

namespace {
double msSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
        .count();
}
}  // namespace

Status Renderer::render(const Scene& scene, const View& view, const RenderOptions& options,
                        Frame& out, FrameStats* stats) {
    if (Status s = validate(options); !s.ok())
        return s;
    if (Status s = validate(view); !s.ok())
        return s;
    State& st = *state_;
    using Clock = std::chrono::steady_clock;

    // Clear the targets.
    out.width = view.width;
    out.height = view.height;
    const size_t pixels = size_t(view.width) * view.height;
    out.color.resize(pixels * 4);
    for (size_t i = 0; i < pixels; ++i) {
        out.color[i * 4 + 0] = scene.background.r;
        out.color[i * 4 + 1] = scene.background.g;
        out.color[i * 4 + 2] = scene.background.b;
        out.color[i * 4 + 3] = 1.0f;
    }
    out.depth.resize(options.depth_format, view.width, view.height);

    auto t0 = Clock::now();
    runGeometry(pool_, scene, view, st.geometry);
    const double ms_geometry = msSince(t0);

    t0 = Clock::now();
    const TileGrid grid = makeTileGrid(view.width, view.height, options.tile_size);
    binChunks(pool_, st.geometry, grid, st.bins);
    const double ms_binning = msSince(t0);

    t0 = Clock::now();
    RasterContext ctx;
    ctx.geometry = &st.geometry;
    ctx.bins = &st.bins;
    ctx.grid = grid;
    ctx.frame = &out;
    ctx.shade.scene = &scene;
    ctx.shade.eye = st.geometry.eye;
    ctx.shade.mode = options.shading;
    ctx.shade.filter = options.texture_filter;
    // Default light: from above-left, behind the viewer (direction of travel).
    ctx.shade.default_light_dir =
        glm::normalize(0.35f * view.right - 0.6f * view.up + 0.7f * view.forward);
    st.tile_counters.assign(grid.count(), TileCounters{});
    pool_.parallelFor(grid.count(), [&](uint32_t tile, uint32_t) {
        rasterizeTile(ctx, tile, st.tile_counters[tile]);
    });
    const double ms_raster = msSince(t0);

    if (stats) {
        *stats = FrameStats{};
        for (const GeometryChunk& c : st.geometry.chunks) {
            stats->triangles_in += c.triangles_in;
            stats->triangles_culled += c.triangles_culled;
            stats->triangles_clipped += c.triangles_clipped;
            stats->triangles_setup += c.tris.size();
        }
        for (const TileCounters& tc : st.tile_counters) {
            stats->fragments_covered += tc.covered;
            stats->fragments_passed += tc.passed;
        }
        stats->ms_geometry = ms_geometry;
        stats->ms_binning = ms_binning;
        stats->ms_raster = ms_raster;
    }
    return {};
}

}  // namespace raster
