// Multiview's setup stages, run once per frame in this order by synthesizeMultiview before the
// tiles are traced: the float copy of the layer depths, the segments (§4.2), the N-buffers
// (§4.3), the mipmaps (§4.4) and the paths walked in advance. Consume the layered target and
// the Tracer; produce the MultiviewScratch buffers (the caller's, resized in place) and the
// Tracer's segments, mip views and paths.
#pragma once

#include "multiview_tracer.h"

#include <raster/task_pool.h>

namespace dof::multiview_detail {

// The extent of each layer's covered texels in stored D, and of its drawn rows (copyLayerDepths).
struct LayerContent {
    std::vector<float> min, max;      // +inf and -inf when the layer is empty
    std::vector<uint8_t> transparent; // whether its transparent plane has content
    // Rows [row0, row1) of the layer (of its transparent plane) hold every texel whose colour is
    // not the target's clear value, +0 in every channel; none: 0, 0.
    std::vector<uint32_t> row0, row1, transparent_row0, transparent_row1;
};

// The lens cells of one sample set (multiview_lens_cells.cpp): lambda (meanNeighbourDistance)
// and, when asked for, each sample's cell offset (lensCellOffsets). Kept with the set's samples
// and aperture as the key, so they are measured again only when the set changes.
struct LensCells {
    bool valid = false;          // lambda is the key's
    bool has_offsets = false;    // offsets are the key's (may be empty: no cells)
    std::vector<LensSample> key; // the set's samples, bit for bit
    ApertureShape key_shape;     // and its aperture
    float lambda = 0.0f;
    std::vector<glm::vec2> offsets;
};

// Makes `cells` describe `samples` (lambda always, the offsets when `offsets` is set), measuring
// only what the kept values do not already give.
void updateLensCells(const LensSampleSet& samples, bool offsets, LensCells& cells);

// Everything of a frame that is not in MultiviewScratch's public buffers (MultiviewScratch::frame):
// kept between frames, resized in place.
struct FrameState {
    LayerSpacing spacing;           // §4.1
    raster::LayeredTargetDesc desc; // §4.2
    Tracer tracer;                  // reset() at the start of each frame
    LayerContent content;
    std::vector<std::vector<float>> nearest; // per layer: the N-buffer source with BLEND planes
    LensCells lens_cells;
    std::vector<TileCounters> counters;    // per output tile
    std::vector<RayState> ray_states;      // per worker: one tile's rays
    std::vector<PixelLayers> pixel_layers; // per worker: one tile's pixels
    raster::SurfaceShader shader;          // per-ray shading (§5), prepared again each frame
    // What the last frame left for probeMultiview: its tracer (Traced) or the pinhole image
    // (Skipped), and its sample count.
    enum class Kept : uint8_t { None, Traced, Skipped } kept = Kept::None;
    uint32_t sample_count = 0;
};

// Per-layer float depths (empty -> kEmptyDepth) into scratch.depth and transparent_depth, and
// the layers' content extents into `content`; one task per layer, each writing only its own
// slots.
void copyLayerDepths(const raster::LayeredTarget& layers, raster::TaskPool& pool,
                     MultiviewScratch& scratch, LayerContent& content);

// tr.segs from the layer bounds and content; reach_max: the largest reach_px of a non-empty
// layer. Fails when the lens blurs by more than kMaxReachPx.
raster::Status buildSegments(Tracer& tr, const LayerContent& content, MultiviewStats& stats,
                             float& reach_max);

// scratch.nbuffers (§4.3 culling; cleared with culling off). `nearest`: per-layer buffers for
// the layers with a transparent plane.
void buildNBuffers(const Tracer& tr, raster::TaskPool& pool, MultiviewScratch& scratch,
                   std::vector<std::vector<float>>& nearest, MultiviewStats& stats);

// The coverage, owned and transparent mipmaps (§4.4) in scratch, their views in tr, and each
// segment's first missed-cone lookup. Each level stores only the rows `content`'s drawn rows
// reach (MultiviewScratch::mip_row0).
void buildMipmaps(Tracer& tr, const LayerContent& content, float reach_max, raster::TaskPool& pool,
                  MultiviewScratch& scratch, MultiviewStats& stats);

// With the shared sample set (JitterMode::None): tr.first_rays, every ray's starting state.
void buildFirstRays(Tracer& tr);

// With the shared sample set and the scan: every sample's path through every segment into
// tr.paths and tr.cells, and each segment's in-focus bounds. False (nothing walked) when the
// lens makes the paths too long.
bool walkPaths(Tracer& tr, MultiviewStats& stats);

} // namespace dof::multiview_detail
