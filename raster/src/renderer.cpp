#include "binning.h"
#include "geometry.h"
#include "light_kernel.h"
#include "sinks.h"
#include "stopwatch.h"
#include "tile_raster.h"

#include <raster/renderer.h>
#include <raster/simd.h>
#include <raster/surface_shading.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <new>
#include <string>
#include <utility>

namespace raster {

struct Renderer::State {
    GeometryState geometry;
    std::vector<ChunkBins> bins;
    RasterContext ctx;
    std::vector<PreparedLight> lights;
    std::vector<TileCounters> tile_counters;
    // Fragment-list collection: head per pixel, one node pool per tile, sort scratch per worker.
    std::vector<uint32_t> list_head;
    std::vector<std::vector<FragmentNode>> list_pools;
    std::vector<std::vector<FragmentNode>> sort_scratch;
    // Per tile: its lists as the resolve keeps them, until they are copied into place.
    std::vector<std::vector<FragmentNode>> list_kept;
    // ListSink early rejection: per worker, the k nearest keys of each pixel of its tile and
    // how many of them are in use.
    std::vector<std::vector<float>> list_nearest;
    std::vector<std::vector<uint8_t>> list_nearest_used;
    static_assert(kMaxEarlyRejectCap <= 255, "ListSink counts a pixel's keys in a uint8_t");
    // The resolve's counts per tile: the longest list appended and the fragments hidden.
    std::vector<uint32_t> list_longest;
    std::vector<uint64_t> list_hidden;
    // Layered rendering: the overlapped interval of each layer.
    std::vector<LayerInterval> layer_intervals;
    // What the geometry and bins were made from (prepared: they are complete), and the
    // caller's promise for the next call that the scene is unchanged since
    // (promiseSceneUnchanged).
    struct {
        bool prepared = false;
        const Scene* scene = nullptr;
        View view;
        uint32_t tile_size = 0;
    } made;
    bool scene_unchanged = false;
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

Status validateTextures(const Scene& scene, ShadingMode mode) {
    const TextureRoles sampled = sampledTextureRoles(mode);
    for (size_t i = 0; i < scene.materials.size(); ++i) {
        const Material& m = scene.materials[i];
        const std::pair<TextureRole, const TextureRef*> refs[] = {
            {TextureRole::BaseColor, &m.base_color_texture},
            {TextureRole::Emissive, &m.emissive_texture}};
        for (const auto& [role, ref] : refs) {
            if (!sampled.has(role) || ref->image < 0)
                continue;
            if (size_t(ref->image) >= scene.images.size() ||
                scene.images[size_t(ref->image)].levels.empty())
                return Status::error("material " + std::to_string(i) + " samples image " +
                                     std::to_string(ref->image) + " as its " +
                                     textureRoleName(role) +
                                     " texture, but the scene has no pixels for it (import "
                                     "with the texture roles the shading samples)");
        }
    }
    return {};
}

namespace {

bool hasBlendMaterial(const Scene& scene) {
    return std::any_of(scene.materials.begin(), scene.materials.end(),
                       [](const Material& m) { return m.alpha_mode == AlphaMode::Blend; });
}
} // namespace

void Renderer::tileTriangleCounts(std::vector<uint32_t>& out, uint32_t& tiles_x,
                                  uint32_t& tiles_y) const {
    const State& st = *state_;
    tiles_x = st.ctx.grid.tiles_x;
    tiles_y = st.ctx.grid.tiles_y;
    out.assign(st.ctx.grid.count(), 0);
    for (const ChunkBins& bins : st.bins)
        for (size_t t = 0; t + 1 < bins.offsets.size() && t < out.size(); ++t)
            out[t] += bins.offsets[t + 1] - bins.offsets[t];
}

Status Renderer::prepare(const Scene& scene, const View& view, const RenderOptions& options,
                         bool scene_unchanged, FrameStats* stats) {
    if (Status s = validate(options); !s.ok())
        return s;
    if (Status s = validate(view); !s.ok())
        return s;
    if (Status s = validateTextures(scene, options.shading); !s.ok())
        return s;
    State& st = *state_;
    // Promised and the same scene: its world-space vertices are kept; and from the same view
    // with the same tiles, the whole geometry and bins.
    const bool keep_world = scene_unchanged && st.geometry.world_scene == &scene;
    const bool reuse = keep_world && st.made.prepared && st.made.scene == &scene &&
                       st.made.view == view && st.made.tile_size == options.tile_size;
    st.ctx = RasterContext{};
    st.ctx.grid = makeTileGrid(view.width, view.height, options.tile_size);
    double ms_geometry = 0.0, ms_binning = 0.0;
    if (!reuse) {
        st.made.prepared = false; // until both are complete
        auto t0 = std::chrono::steady_clock::now();
        runGeometry(pool_, scene, view, st.geometry, keep_world);
        ms_geometry = msSince(t0);
        t0 = std::chrono::steady_clock::now();
        binChunks(pool_, st.geometry, st.ctx.grid, st.bins);
        ms_binning = msSince(t0);
        st.made = {true, &scene, view, options.tile_size};
    }

    st.ctx.geometry = &st.geometry;
    st.ctx.bins = &st.bins;
    st.ctx.shade.scene = &scene;
    st.ctx.shade.eye = st.geometry.eye;
    st.ctx.shade.mode = options.shading;
    st.ctx.shade.filter = options.texture_filter;
    st.ctx.kernel = selectQuadKernel(options.simd);
    st.ctx.fragment_kernel = selectFragmentKernel(options.simd);
    st.ctx.avx2 = useAvx2(options.simd);
    st.ctx.blend_last = hasBlendMaterial(scene);
    st.ctx.depth_only = options.depth_only; // only FrameSink (render) has writeDepth
    prepareLights(scene, defaultLightDirection(view), st.lights);
    st.ctx.shade.lights = st.lights.data();
    st.ctx.shade.light_count = uint32_t(st.lights.size());
    st.ctx.shade.light_kernel = selectLightKernel(options.simd);
    st.ctx.shade.texture_kernel = selectTextureKernel(options.simd);
    st.tile_counters.assign(st.ctx.grid.count(), TileCounters{});
    if (stats) {
        *stats = FrameStats{};
        for (const GeometryChunk& c : st.geometry.chunks) {
            stats->triangles_in += c.triangles_in;
            stats->triangles_culled += c.triangles_culled;
            stats->triangles_clipped += c.triangles_clipped;
            stats->triangles_setup += c.tris.size();
        }
        stats->ms_geometry = ms_geometry;
        stats->ms_binning = ms_binning;
    }
    return {};
}

namespace {

// Records the target's times and size, and adds the per-tile fragment counters in tile order.
// ms_resolve: the resolve's time after the raster; the tiles' own resolve work, done in their
// raster tasks (TileCounters::ms_after), is added to it.
void finishStats(const std::vector<TileCounters>& tiles, double ms_raster, double ms_resolve,
                 uint64_t target_bytes, FrameStats* stats) {
    if (!stats)
        return;
    stats->ms_raster = ms_raster;
    stats->ms_resolve = ms_resolve;
    stats->target_bytes = target_bytes;
    for (const TileCounters& tc : tiles) {
        stats->fragments_covered += tc.covered;
        stats->fragments_passed += tc.passed;
        stats->ms_resolve += tc.ms_after;
    }
}

// Pixel rectangle [x0, x1) x [y0, y1) of a tile.
struct TileRect {
    uint32_t x0, y0, x1, y1;
};
TileRect tileRect(const TileGrid& g, uint32_t tile) {
    const uint32_t x0 = (tile % g.tiles_x) * g.tile_size, y0 = (tile / g.tiles_x) * g.tile_size;
    return {x0, y0, std::min(x0 + g.tile_size, g.width), std::min(y0 + g.tile_size, g.height)};
}

Status validate(const LayeredTargetDesc& desc) {
    const size_t n = desc.bounds.size();
    if (n < 2 || n - 1 > kMaxLayers)
        return Status::error("layered target needs between 1 and " + std::to_string(kMaxLayers) +
                             " layers (got " + std::to_string(n < 1 ? 0 : n - 1) + ")");
    for (size_t i = 0; i < n; ++i) {
        const bool last = i + 1 == n;
        if (!(desc.bounds[i] > 0.0f) || (!last && !std::isfinite(desc.bounds[i])) ||
            (i > 0 && !(desc.bounds[i] > desc.bounds[i - 1])))
            return Status::error("layer bounds must be positive, finite (the last may be "
                                 "infinite) and strictly increasing");
    }
    if (!(desc.overlap >= 0.0f && desc.overlap <= 1.0f))
        return Status::error("layer overlap must be between 0 and 1");
    return {};
}

std::string sizeText(const View& view) {
    return std::to_string(view.width) + "x" + std::to_string(view.height);
}

// The one message for an allocation that failed although the budget admitted it.
Status outOfMemory(const std::string& what) {
    return Status::error("out of memory allocating " + what +
                         " (lower the memory_budget to fail before allocating)");
}

} // namespace

Status Renderer::render(const Scene& scene, const View& view, const RenderOptions& options,
                        Frame& out, FrameStats* stats) try {
    const bool unchanged = std::exchange(state_->scene_unchanged, false); // this call's only
    if (Status s = validate(view); !s.ok())
        return s;
    if (Status s = checkMemory(
            options.memory_budget,
            [&] { return "a " + sizeText(view) + " frame (colour and depth)"; },
            frameBytes(view.width, view.height, options.depth_format, hasBlendMaterial(scene)));
        !s.ok())
        return s;
    if (Status s = prepare(scene, view, options, unchanged, stats); !s.ok())
        return s;
    State& st = *state_;
    out.width = view.width;
    out.height = view.height;
    const size_t pixels = size_t(view.width) * view.height;
    // Sized here, cleared by each tile's owner below.
    out.color.resize(pixels * 4);
    out.depth.resizeUncleared(options.depth_format, view.width, view.height);
    const bool transparency = st.ctx.blend_last; // the scene has BLEND materials
    out.transparent_depth.resizeUncleared(options.depth_format, transparency ? view.width : 0,
                                          transparency ? view.height : 0);
    if (options.peel_depth &&
        (options.peel_depth->format != options.depth_format ||
         options.peel_depth->width != view.width || options.peel_depth->height != view.height))
        return Status::error("the depth-peeling buffer must match the frame's size and format");

    const auto t0 = std::chrono::steady_clock::now();
    pool_.parallelFor(st.ctx.grid.count(), [&](uint32_t tile, uint32_t) {
        // The background and the far depth, filled by the tile's owner rather than by one
        // thread before the tiles.
        const TileRect r = tileRect(st.ctx.grid, tile);
        // One 16-byte texel per pixel, from a local (the scene's colour, read through the
        // frame's float pointer, would be loaded again for every store).
        const float background[4] = {scene.background.r, scene.background.g, scene.background.b,
                                     1.0f};
        for (uint32_t y = r.y0; y < r.y1; ++y) {
            const size_t i = size_t(y) * view.width + r.x0;
            float* c = out.color.data() + i * 4;
            for (uint32_t x = r.x0; x < r.x1; ++x, c += 4)
                std::memcpy(c, background, sizeof(background));
            out.depth.fill(i, r.x1 - r.x0, kFarDepth);
            if (transparency)
                out.transparent_depth.fill(i, r.x1 - r.x0, kFarDepth);
        }
        FrameSink sink{out, options.peel_depth};
        rasterizeTile(st.ctx, tile, sink, st.tile_counters[tile]);
    });
    finishStats(st.tile_counters, msSince(t0), 0.0,
                out.color.size() * sizeof(float) + out.depth.bytes() +
                    out.transparent_depth.bytes(),
                stats);
    return {};
} catch (const std::bad_alloc&) {
    return outOfMemory("a " + sizeText(view) + " frame");
}

void Renderer::promiseSceneUnchanged() {
    state_->scene_unchanged = true;
}

Status Renderer::renderLayers(const Scene& scene, const View& view, const RenderOptions& options,
                              const LayeredTargetDesc& desc, LayeredTarget& out,
                              FrameStats* stats) try {
    const bool unchanged = std::exchange(state_->scene_unchanged, false); // this call's only
    if (Status s = validate(desc); !s.ok())
        return s;
    if (Status s = validate(view); !s.ok())
        return s;
    const uint32_t layer_count = uint32_t(desc.bounds.size() - 1);
    if (Status s = checkMemory(
            options.memory_budget,
            [&] {
                return "a " + sizeText(view) + " layered target with " +
                       std::to_string(layer_count) + " layers";
            },
            layeredTargetBytes(view.width, view.height, layer_count, desc,
                               hasBlendMaterial(scene)));
        !s.ok())
        return s;
    if (Status s = prepare(scene, view, options, unchanged, stats); !s.ok())
        return s;
    State& st = *state_;
    const uint32_t layers = uint32_t(desc.bounds.size() - 1);
    out.width = view.width;
    out.height = view.height;
    out.layer_count = layers;
    out.desc = desc;
    const size_t pixels = out.pixelCount();
    // Sized here, cleared by each tile's owner below.
    out.color.resizeUncleared(desc.color_format, pixels * layers);
    out.depth.resizeUncleared(desc.depth_format, view.width, view.height * layers);
    out.gbuffer.resize(desc.gbuffer ? pixels * layers : 0);
    const bool transparency = st.ctx.blend_last; // the scene has BLEND materials
    out.transparent_color.resizeUncleared(desc.color_format, transparency ? pixels * layers : 0);
    out.transparent_depth.resizeUncleared(desc.depth_format, transparency ? view.width : 0,
                                          transparency ? view.height * layers : 0);
    const bool transparent_gbuffer = transparency && desc.gbuffer;
    out.transparent_gbuffer.resize(transparent_gbuffer ? pixels * layers : 0);
    out.transparent_top_alpha.resize(transparent_gbuffer ? pixels * layers : 0);
    std::vector<LayerInterval>& intervals = st.layer_intervals;
    intervals.resize(layers);
    for (uint32_t l = 0; l < layers; ++l)
        intervals[l] = overlappedInterval(desc, l);

    // The overlapped intervals as ranges of stored depth [near, far), for the copy pass below:
    // the same decisions as testing distanceFromDepth(D) against the intervals, without a
    // division per pixel.
    const bool copy = desc.routing == LayerRouting::MaxVertexDepth;
    float stored_near[kMaxLayers];
    float stored_far[kMaxLayers];
    for (uint32_t l = 0; copy && l < layers; ++l) {
        stored_near[l] = firstDepthAtDistance(view, intervals[l].near_d);
        stored_far[l] = firstDepthAtDistance(view, intervals[l].far_d);
    }
    auto t0 = std::chrono::steady_clock::now();
    pool_.parallelFor(st.ctx.grid.count(), [&](uint32_t tile, uint32_t) {
        // Every layer's pixels of the tile cleared by the tile's owner, as the frame's background
        // in render(): nothing, at the far depth.
        const TileRect r = tileRect(st.ctx.grid, tile);
        const size_t n = r.x1 - r.x0;
        for (uint32_t l = 0; l < layers; ++l)
            for (uint32_t y = r.y0; y < r.y1; ++y) {
                const size_t i = out.index(l, size_t(y) * view.width + r.x0);
                out.color.fill(i, n, glm::vec4(0.0f));
                out.depth.fill(i, n, kFarDepth);
                if (desc.gbuffer)
                    std::fill_n(out.gbuffer.data() + i, n, GSample{});
                if (transparency) {
                    out.transparent_color.fill(i, n, glm::vec4(0.0f));
                    out.transparent_depth.fill(i, n, kFarDepth);
                }
                if (transparent_gbuffer) {
                    std::fill_n(out.transparent_gbuffer.data() + i, n, GSample{});
                    std::fill_n(out.transparent_top_alpha.data() + i, n, 0.0f);
                }
            }
        LayerSink sink{out, intervals, desc.gbuffer};
        rasterizeTile(st.ctx, tile, sink, st.tile_counters[tile]);
        if (!copy)
            return;
        const auto copy_t0 = std::chrono::steady_clock::now();
        // Lee et al. §4.2, second pass: copy each covered pixel into every other layer whose
        // overlapped interval holds its depth, with a manual depth test. Pixels stay where the
        // triangle routing put them (the paper's approximation). Reads a per-pixel snapshot, so
        // the result does not depend on the order of the copies. (BLEND fragments were routed one
        // by one to the layer owning their depth, so the transparent planes need no copy.) Run
        // on the tile just rasterized, by its owner: a pixel's copies read and write only that
        // pixel's layers, which the tile's raster has just written and left in the cache (a
        // separate pass over the image read them back from memory; raster.md §6).
        float snapshot[kMaxLayers];
        uint32_t covered[kMaxLayers];
        for (uint32_t y = r.y0; y < r.y1; ++y)
            for (uint32_t x = r.x0; x < r.x1; ++x) {
                const size_t p = size_t(y) * view.width + x;
                uint32_t covered_count = 0;
                for (uint32_t l = 0; l < layers; ++l) {
                    snapshot[l] = out.depth.load(out.index(l, p));
                    if (snapshot[l] < kFarDepth) // cleared layers have nothing to copy
                        covered[covered_count++] = l;
                }
                for (uint32_t c = 0; c < covered_count; ++c) {
                    const uint32_t src = covered[c];
                    const float z = snapshot[src];
                    for (uint32_t dst = 0; dst < layers; ++dst) {
                        if (dst == src || !(z >= stored_near[dst]) || !(z < stored_far[dst]))
                            continue;
                        const size_t di = out.index(dst, p);
                        if (!(z < out.depth.load(di)))
                            continue;
                        const size_t si = out.index(src, p);
                        out.color.store(di, out.color.load(si));
                        out.depth.store(di, z);
                        if (desc.gbuffer)
                            out.gbuffer[di] = out.gbuffer[si];
                    }
                }
            }
        st.tile_counters[tile].ms_after = msSince(copy_t0);
    });
    // The copy ran inside the tiles' tasks (within ms_raster); finishStats sums its time.
    finishStats(st.tile_counters, msSince(t0), 0.0, out.bytes(), stats);
    return {};
} catch (const std::bad_alloc&) {
    return outOfMemory("a " + sizeText(view) + " layered target");
}

Status Renderer::renderFragmentLists(const Scene& scene, const View& view,
                                     const RenderOptions& options, const FragmentListDesc& desc,
                                     FragmentLists& out, FrameStats* stats) try {
    const bool unchanged = std::exchange(state_->scene_unchanged, false); // this call's only
    if (desc.node_capacity == 0)
        return Status::error("fragment list node capacity must be at least 1");
    if (!(desc.hidden_epsilon >= 0.0f) || !std::isfinite(desc.hidden_epsilon))
        return Status::error("fragment list hidden epsilon must be finite and >= 0");
    if (Status s = validate(view); !s.ok())
        return s;
    // Heads, offsets and list lengths per pixel, before any fragment is collected.
    if (Status s = checkMemory(
            options.memory_budget,
            [&] { return "the per-pixel list heads of a " + sizeText(view) + " image"; },
            mulBytes(uint64_t(view.width) * view.height, 12));
        !s.ok())
        return s;
    if (Status s = prepare(scene, view, options, unchanged, stats); !s.ok())
        return s;
    State& st = *state_;
    const uint32_t tiles = st.ctx.grid.count();
    const size_t pixels = size_t(view.width) * view.height;
    st.list_head.assign(pixels, kNoNode);
    st.list_pools.resize(tiles);
    const bool early =
        desc.early_reject && desc.max_per_pixel > 0 && desc.max_per_pixel <= kMaxEarlyRejectCap;
    const float hidden_scale = desc.hidden_epsilon > 0.0f ? 1.0f + desc.hidden_epsilon : 0.0f;
    // Keys per pixel for early rejection: the N nearest depths, or with hidden fragments more
    // distances than N (nearer ones may turn out hidden; see ListSink).
    const uint32_t early_k = !early                ? 0
                             : hidden_scale > 0.0f ? kMaxEarlyRejectCap
                                                   : desc.max_per_pixel;
    if (st.sort_scratch.size() < pool_.workerCount())
        st.sort_scratch.resize(pool_.workerCount());
    // Every worker's early-rejection keys are sized here, not by the first tile it happens to
    // take: which worker takes which tile varies, and a second identical frame allocates nothing.
    st.list_nearest.resize(pool_.workerCount());
    st.list_nearest_used.resize(pool_.workerCount());
    const size_t tile_pixels = size_t(st.ctx.grid.tile_size) * st.ctx.grid.tile_size;
    const size_t nearest_size = tile_pixels * size_t(early_k);
    for (std::vector<float>& nearest : st.list_nearest)
        nearest.reserve(nearest_size);
    for (std::vector<uint8_t>& used : st.list_nearest_used)
        used.reserve(tile_pixels);

    // Resolve (Selgrad et al. §4), per tile: sort each pixel's list and pick what it keeps into
    // the tile's scratch (its counts into the offsets, summed below). Each tile's owner runs it
    // right after collecting the tile, while the tile's pool is still in the cache (a second
    // pass over the tiles read every list back from memory). So the kept fragments (at most
    // the pool again) are held before the memory budget is checked below, which then stops the
    // image-sized arrays.
    const uint32_t cap = desc.max_per_pixel == 0 ? UINT32_MAX : desc.max_per_pixel;
    out.offsets.assign(pixels + 1, 0);
    out.list_length.assign(pixels, 0);
    st.list_kept.resize(tiles);
    std::vector<uint32_t>& longest = st.list_longest;
    std::vector<uint64_t>& hidden = st.list_hidden;
    longest.assign(tiles, 0);
    hidden.assign(tiles, 0);
    const auto resolveTile = [&](uint32_t tile, uint32_t worker,
                                 const std::vector<FragmentNode>& nodes) {
        const TileRect r = tileRect(st.ctx.grid, tile);
        // Filled and counted in locals and stored once (see the collection below).
        std::vector<FragmentNode> list = std::move(st.sort_scratch[worker]);
        std::vector<FragmentNode> kept = std::move(st.list_kept[tile]);
        kept.clear();
        uint32_t tile_longest = 0;
        uint64_t tile_hidden = 0;
        for (uint32_t y = r.y0; y < r.y1; ++y)
            for (uint32_t x = r.x0; x < r.x1; ++x) {
                const size_t p = size_t(y) * view.width + x;
                // An empty or one-fragment list (most pixels) is already sorted, and its
                // fragment is kept: cap >= 1 and nothing is kept in front to hide it.
                const uint32_t head = st.list_head[p];
                if (head == kNoNode || nodes[head].next == kNoNode) {
                    const uint32_t n = head == kNoNode ? 0 : 1;
                    tile_longest = std::max(tile_longest, n);
                    out.list_length[p] = n;
                    out.offsets[p + 1] = n;
                    if (n == 1)
                        kept.push_back(nodes[head]);
                    continue;
                }
                list.clear();
                for (uint32_t i = head; i != kNoNode; i = nodes[i].next)
                    list.push_back(nodes[i]);
                const uint32_t n = uint32_t(list.size());
                tile_longest = std::max(tile_longest, n);
                out.list_length[p] = n;
                // Total order: depth, then primitive id (never arrival order).
                std::sort(list.begin(), list.end(),
                          [](const FragmentNode& a, const FragmentNode& b) {
                              return a.z < b.z || (a.z == b.z && a.primitive_id < b.primitive_id);
                          });
                // The closest `cap`, skipping those within the factor hidden_scale behind the
                // last kept opaque fragment.
                uint32_t count = 0;
                float opaque = -1.0f; // distance of the last kept opaque fragment
                for (const FragmentNode& f : list) {
                    if (count == cap)
                        break;
                    if (hidden_scale > 0.0f) {
                        const float d = distanceFromDepth(view, f.z);
                        if (opaque >= 0.0f && d <= opaque * hidden_scale) {
                            ++tile_hidden;
                            continue;
                        }
                        if (f.color.a >= 1.0f)
                            opaque = d;
                    }
                    kept.push_back(f);
                    ++count;
                }
                out.offsets[p + 1] = count;
            }
        st.sort_scratch[worker] = std::move(list);
        st.list_kept[tile] = std::move(kept);
        longest[tile] = tile_longest;
        hidden[tile] = tile_hidden;
    };

    // Collection: every fragment, in primitive order, into its tile's pool.
    auto t0 = std::chrono::steady_clock::now();
    pool_.parallelFor(tiles, [&](uint32_t tile, uint32_t worker) {
        // Each vector a task appends to is moved into a local and back (no allocation):
        // neighbouring tiles' and workers' vector headers share cache lines, and updating one's
        // end per fragment made the two workers fight over them.
        std::vector<FragmentNode> nodes = std::move(st.list_pools[tile]);
        nodes.clear();
        ListSink sink{st.list_head, nodes};
        if (early_k > 0) {
            const TileRect r = tileRect(st.ctx.grid, tile);
            // Only the counts are cleared: a pixel's keys beyond its count are never read.
            std::vector<float>& nearest = st.list_nearest[worker];
            std::vector<uint8_t>& used = st.list_nearest_used[worker];
            nearest.resize(nearest_size);
            used.assign(tile_pixels, 0);
            sink.nearest = nearest.data();
            sink.used = used.data();
            sink.k = early_k;
            sink.cap = desc.max_per_pixel;
            sink.hidden_scale = hidden_scale;
            sink.view = &view;
            sink.frame_width = view.width;
            sink.tile_x0 = r.x0, sink.tile_y0 = r.y0, sink.tile_size = st.ctx.grid.tile_size;
        }
        rasterizeTile(st.ctx, tile, sink, st.tile_counters[tile]);
        const auto resolve_t0 = std::chrono::steady_clock::now();
        resolveTile(tile, worker, nodes);
        st.tile_counters[tile].ms_after = msSince(resolve_t0);
        st.list_pools[tile] = std::move(nodes);
    });
    const double ms_raster = msSince(t0);
    uint64_t collected = 0;
    for (const std::vector<FragmentNode>& p : st.list_pools)
        collected += p.size();
    // Reset field by field: the arrays are emptied but keep their memory for the next frame.
    out.primitive.clear();
    out.color.half.clear();
    out.color.float32.clear();
    out.depth.unorm16.clear();
    out.depth.float32.clear();
    out.depth.width = out.depth.height = 0;
    out.width = view.width;
    out.height = view.height;
    out.desc = desc;
    out.fragments_collected = collected;
    out.fragments_rejected = 0;
    out.fragments_hidden = 0;
    out.fragments_kept = 0;
    out.max_list_length = 0;
    out.grew = false;
    for (const TileCounters& c : st.tile_counters)
        out.fragments_rejected += c.rejected;
    out.node_capacity_used = desc.node_capacity;
    // The collected nodes, plus what the resolve stores per kept fragment (at most all of them).
    const uint64_t per_fragment = sizeof(FragmentNode) + bytesPerColor(desc.color_format) +
                                  bytesPerDepth(desc.depth_format) + sizeof(uint32_t);
    if (Status s = checkMemory(
            options.memory_budget,
            [&] { return std::to_string(collected) + " fragments in per-pixel lists"; },
            mulBytes(collected, per_fragment));
        !s.ok())
        return s;
    if (collected > desc.node_capacity) {
        if (desc.on_overflow == OverflowPolicy::Fail)
            return Status::error("fragment list overflow: " + std::to_string(collected) +
                                 " fragments collected but the node pool holds " +
                                 std::to_string(desc.node_capacity) +
                                 " (raise the capacity or let the pool grow)");
        // Collection counted every fragment, so growing the pool to the count needed loses
        // nothing: the lists below are complete.
        out.grew = true;
        out.node_capacity_used = uint32_t(std::min<uint64_t>(collected, UINT32_MAX));
    }

    // The rest of the resolve: prefix sum over the kept counts, then every tile's kept
    // fragments copied into their slots.
    t0 = std::chrono::steady_clock::now();
    for (size_t p = 0; p < pixels; ++p)
        out.offsets[p + 1] += out.offsets[p];
    for (uint32_t t = 0; t < tiles; ++t) {
        out.max_list_length = std::max(out.max_list_length, longest[t]);
        out.fragments_hidden += hidden[t];
    }
    // Every worker's sort scratch holds the longest list, whichever tiles it sorts next time.
    for (std::vector<FragmentNode>& list : st.sort_scratch)
        list.reserve(out.max_list_length);
    const uint32_t total = out.offsets[pixels];
    out.fragments_kept = total;
    // Sized without clearing: the tiles below store every one of the `total` slots.
    out.color.resizeUncleared(desc.color_format, total);
    out.depth.resizeUncleared(desc.depth_format, total, total > 0 ? 1 : 0);
    out.primitive.resize(total);
    pool_.parallelFor(tiles, [&](uint32_t tile, uint32_t) {
        const TileRect r = tileRect(st.ctx.grid, tile);
        const std::vector<FragmentNode>& kept = st.list_kept[tile];
        size_t k = 0; // the tile's pixels in the order they were picked
        for (uint32_t y = r.y0; y < r.y1; ++y)
            for (uint32_t x = r.x0; x < r.x1; ++x) {
                const size_t p = size_t(y) * view.width + x;
                for (uint32_t i = out.offsets[p]; i < out.offsets[p + 1]; ++i, ++k) {
                    out.color.store(i, kept[k].color);
                    out.depth.store(i, kept[k].z);
                    out.primitive[i] = kept[k].primitive_id;
                }
            }
    });
    // The sort and cap ran in the collection's tasks; finishStats adds their time.
    finishStats(st.tile_counters, ms_raster, msSince(t0), out.bytes(), stats);
    return {};
} catch (const std::bad_alloc&) {
    return outOfMemory("per-pixel fragment lists of a " + sizeText(view) + " image");
}

} // namespace raster
