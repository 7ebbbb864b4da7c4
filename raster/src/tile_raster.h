// Tile raster: coverage, depth test and shading for the pixels of one tile. Consumes the
// geometry chunks and their bins; writes only the Frame pixels of the tile it is given, so tiles
// run in parallel without locks. Triangles are replayed in chunk order, i.e. submission order.
#pragma once

#include "binning.h"
#include "geometry.h"
#include "shading.h"

#include <raster/frame.h>

#include <cstdint>
#include <vector>

namespace raster {

struct RasterContext {
    const GeometryState* geometry = nullptr;
    const std::vector<ChunkBins>* bins = nullptr;
    TileGrid grid;
    ShadeContext shade;
    Frame* frame = nullptr;
};

struct TileCounters {
    uint64_t covered = 0;
    uint64_t passed = 0;
};

// Rasterizes every triangle binned to `tile` into ctx.frame.
void rasterizeTile(const RasterContext& ctx, uint32_t tile, TileCounters& counters);

}  // namespace raster
