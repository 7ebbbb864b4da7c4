// Binning: sorts each geometry chunk's triangles into per-tile lists, keeping primitive order.
// Consumes GeometryState chunks; produces one ChunkBins per chunk (a counting sort: offsets per
// tile into one item array). Tile raster replays chunk 0, 1, ... for each tile, so the order in
// which a pixel sees triangles is submission order whatever thread binned what.
#pragma once

#include "geometry.h"

#include <cstdint>
#include <vector>

namespace raster {

struct TileGrid {
    uint32_t tile_size = 64;
    uint32_t tiles_x = 0, tiles_y = 0;
    uint32_t width = 0, height = 0;
    uint32_t count() const { return tiles_x * tiles_y; }
};

TileGrid makeTileGrid(uint32_t width, uint32_t height, uint32_t tile_size);

struct ChunkBins {
    std::vector<uint32_t> offsets; // tile t owns items[offsets[t], offsets[t+1])
    std::vector<uint32_t> items;   // indices into the chunk's SetupTri array
    std::vector<uint32_t> cursor;  // scratch of the fill pass, kept to reuse its memory
};

// Edge function E(p) = a*px + b*py + c of the edge from vertex i to vertex j, in 24.8 fixed
// point; the interior is E >= 0 after adding `bias` (top-left rule, see docs/raster.md).
struct Edge {
    int64_t a, b, c;
    int64_t bias; // 0 on top and left edges, -1 elsewhere: samples exactly on them stay out
    int64_t at(int64_t px, int64_t py) const { return a * px + b * py + c; }
};

// The three edges of t; edge k is opposite vertex k, so E_k / area2 is barycentric k.
void makeEdges(const SetupTri& t, Edge edges[3]);

// The centre of pixel index i, in fixed point: where coverage is sampled.
inline int64_t pixelCentre(int64_t i) {
    return i * kSubpixelOne + kSubpixelOne / 2;
}

// True when some pixel centre of the rectangle [x0, x1] x [y0, y1] may be inside all three
// edges (each edge tested at the rectangle's most inside centre); for one pixel, exactly
// whether its centre is covered. Binning's tile test, the tile raster's block reject and
// set-up's small-triangle test.
inline bool rectMayOverlap(const Edge edges[3], int64_t x0, int64_t y0, int64_t x1, int64_t y1) {
    for (int k = 0; k < 3; ++k) {
        const Edge& e = edges[k];
        const int64_t px = e.a > 0 ? pixelCentre(x1) : pixelCentre(x0);
        const int64_t py = e.b > 0 ? pixelCentre(y1) : pixelCentre(y0);
        if (e.at(px, py) + e.bias < 0)
            return false;
    }
    return true;
}

// Bins every chunk (in parallel; each chunk writes only its own ChunkBins).
void binChunks(TaskPool& pool, const GeometryState& geometry, const TileGrid& grid,
               std::vector<ChunkBins>& bins);

} // namespace raster
