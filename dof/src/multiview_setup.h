// Multiview's setup stages, run once per frame in this order by synthesizeMultiview before the
// tiles are traced: the float copy of the layer depths, the segments (§4.2), the N-buffers
// (§4.3), the mipmaps (§4.4) and the paths walked in advance. Consume the layered target and
// the Tracer; produce the MultiviewScratch buffers (the caller's, resized in place) and the
// Tracer's segments, mip views and paths.
#pragma once

#include "multiview_tracer.h"

#include <raster/task_pool.h>

namespace dof::multiview_detail {

// The extent of each layer's covered texels in stored D (copyLayerDepths).
struct LayerContent {
    std::vector<float> min, max;      // +inf and -inf when the layer is empty
    std::vector<uint8_t> transparent; // whether its transparent plane has content
};

// Per-layer float depths (empty -> kEmptyDepth) into scratch.depth and transparent_depth, and
// the layers' content extents; one task per layer, each writing only its own slots.
LayerContent copyLayerDepths(const raster::LayeredTarget& layers, raster::TaskPool& pool,
                             MultiviewScratch& scratch);

// tr.segs from the layer bounds and content; reach_max: the largest reach_px of a non-empty
// layer. Fails when the lens blurs by more than kMaxReachPx.
raster::Status buildSegments(Tracer& tr, const LayerContent& content, MultiviewStats& stats,
                             float& reach_max);

// scratch.nbuffers (§4.3 culling; cleared with culling off).
void buildNBuffers(const Tracer& tr, raster::TaskPool& pool, MultiviewScratch& scratch,
                   MultiviewStats& stats);

// The coverage, owned and transparent mipmaps (§4.4) in scratch, their views in tr, and each
// segment's first missed-cone lookup.
void buildMipmaps(Tracer& tr, float reach_max, raster::TaskPool& pool, MultiviewScratch& scratch,
                  MultiviewStats& stats);

// With the shared sample set and the scan: every sample's path through every segment into
// tr.paths and tr.cells, and each segment's in-focus bounds. False (nothing walked) when the
// lens makes the paths too long.
bool walkPaths(Tracer& tr, MultiviewStats& stats);

} // namespace dof::multiview_detail
