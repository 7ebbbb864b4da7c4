#include "binning.h"

#include <algorithm>

namespace raster {

TileGrid makeTileGrid(uint32_t width, uint32_t height, uint32_t tile_size) {
    TileGrid g;
    g.tile_size = tile_size;
    g.width = width;
    g.height = height;
    g.tiles_x = (width + tile_size - 1) / tile_size;
    g.tiles_y = (height + tile_size - 1) / tile_size;
    return g;
}

void makeEdges(const SetupTri& t, Edge edges[3]) {
    for (int k = 0; k < 3; ++k) {
        const int i = (k + 1) % 3, j = (k + 2) % 3;
        const int64_t dx = int64_t(t.x[j]) - t.x[i];
        const int64_t dy = int64_t(t.y[j]) - t.y[i];
        // E = dx * (py - yi) - dy * (px - xi): positive inside for area2 > 0 (y down).
        Edge& e = edges[k];
        e.a = -dy;
        e.b = dx;
        e.c = dy * t.x[i] - dx * t.y[i];
        // Top edge: horizontal with the interior below (dx > 0); left edge: going up (dy < 0).
        const bool top_left = (dy == 0 && dx > 0) || dy < 0;
        e.bias = top_left ? 0 : -1;
    }
}

void binChunks(TaskPool& pool, const GeometryState& geometry, const TileGrid& grid,
               std::vector<ChunkBins>& bins) {
    bins.resize(geometry.chunks.size());
    const int64_t ts = grid.tile_size;
    pool.parallelFor(uint32_t(geometry.chunks.size()), [&](uint32_t c, uint32_t) {
        const std::vector<SetupTri>& tris = geometry.chunks[c].tris;
        ChunkBins& out = bins[c];
        out.offsets.assign(grid.count() + 1, 0);
        out.items.clear();
        // Visit the tiles each triangle may touch; pass 0 counts, pass 1 fills.
        auto visit = [&](auto&& emit) {
            for (uint32_t ti = 0; ti < tris.size(); ++ti) {
                const SetupTri& t = tris[ti];
                const int64_t tx0 = t.min_x / ts, tx1 = t.max_x / ts;
                const int64_t ty0 = t.min_y / ts, ty1 = t.max_y / ts;
                if (tx0 == tx1 && ty0 == ty1) {
                    emit(uint32_t(ty0 * grid.tiles_x + tx0), ti);
                    continue;
                }
                Edge edges[3];
                makeEdges(t, edges);
                for (int64_t ty = ty0; ty <= ty1; ++ty) {
                    for (int64_t tx = tx0; tx <= tx1; ++tx) {
                        const int64_t x0 = std::max<int64_t>(tx * ts, t.min_x);
                        const int64_t y0 = std::max<int64_t>(ty * ts, t.min_y);
                        const int64_t x1 = std::min<int64_t>(tx * ts + ts - 1, t.max_x);
                        const int64_t y1 = std::min<int64_t>(ty * ts + ts - 1, t.max_y);
                        if (rectMayOverlap(edges, x0, y0, x1, y1))
                            emit(uint32_t(ty * grid.tiles_x + tx), ti);
                    }
                }
            }
        };
        visit([&](uint32_t tile, uint32_t) { ++out.offsets[tile + 1]; });
        for (uint32_t t = 0; t < grid.count(); ++t)
            out.offsets[t + 1] += out.offsets[t];
        out.items.resize(out.offsets[grid.count()]);
        out.cursor.assign(out.offsets.begin(), out.offsets.end() - 1);
        visit([&](uint32_t tile, uint32_t ti) { out.items[out.cursor[tile]++] = ti; });
    });
}

} // namespace raster
