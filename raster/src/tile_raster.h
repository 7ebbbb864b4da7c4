// Tile raster: coverage, depth interpolation and shading for the pixels of one tile, handing each
// shaded fragment to an output-merger "sink" (the frame, the layered target, or the fragment
// lists; see sinks.h). Consumes the geometry chunks and their bins; a sink writes only pixels of
// the tile it is given, so tiles run in parallel without locks. Triangles are replayed in chunk
// order, i.e. submission order, so every pixel sees its fragments in primitive order.
#pragma once

#include "binning.h"
#include "fragment_kernel.h"
#include "geometry.h"
#include "quad_kernel.h"
#include "shading.h"

#include <raster/layered_target.h>

#include <cstdint>
#include <vector>

namespace raster {

struct RasterContext {
    const GeometryState* geometry = nullptr;
    const std::vector<ChunkBins>* bins = nullptr;
    TileGrid grid;
    ShadeContext shade;
    QuadKernel kernel = &quadKernelScalar;
    FragmentKernel fragment_kernel = &fragmentKernelScalar;
    bool blend_last = false; // the scene has BLEND materials: draw their triangles last
    bool depth_only = false; // RenderOptions::depth_only (a sink with writeDepth)
    bool avx2 = false;       // rasterizeTile runs its AVX2 copy (useAvx2)
};

struct TileCounters {
    uint64_t covered = 0;  // samples inside a triangle
    uint64_t passed = 0;   // of those, passed the sink's test and the alpha test
    uint64_t rejected = 0; // of those, failed the sink's early test (never shaded)
    // Time of the work the tile's task does after its raster (renderLayers: the fragment-copy
    // pass; renderFragmentLists: the sort and cap), in ms.
    double ms_after = 0.0;
};

// A shaded fragment as the output merger sees it.
struct Fragment {
    float z = kFarDepth;   // stored depth D (camera.h)
    float distance = 0.0f; // view distance d
    glm::vec4 color{0.0f}; // linear RGB and opacity (1 for OPAQUE and MASK)
    bool blend = false;    // BLEND material: composite with "over", no depth write
    uint32_t primitive_id = 0;
    GSample g; // filled only when the sink asks for it
};

// Rasterizes every triangle binned to `tile` and hands the fragments to `sink`.
// Sink must provide: bool wants_gbuffer; void beginTriangle(const SetupTri&, bool blend);
// bool test(size_t pixel, float z, float distance); void write(size_t pixel, const Fragment&).
template <class Sink>
void rasterizeTile(const RasterContext& ctx, uint32_t tile, Sink& sink, TileCounters& counters);

} // namespace raster
