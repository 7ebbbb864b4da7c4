#include "tile_raster.h"

#include "sinks.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

namespace raster {

namespace {

constexpr int32_t kBlockSize = 8;  // hierarchical test: tile -> 8x8 block -> 2x2 quad -> pixel

int64_t centre(int64_t i) { return i * kSubpixelOne + kSubpixelOne / 2; }

// Per-triangle constants for the pixel loop.
struct TriangleRaster {
    const SetupTri* tri;
    const ShadeVertex* v[3];
    const Material* material;
    Edge edges[3];
    double inv_area2;
    glm::vec3 face_normal;  // faces the eye; used when the primitive has no normals
    bool has_normals;
    bool has_colors;  // without vertex colours the colour is exactly white
};

// Perspective-correct barycentrics from the three edge values of one sample; returns the view
// distance d = w there (1/w is affine in screen space).
float barycentrics(const TriangleRaster& tr, const int64_t e[3], float lambda[3], float persp[3]) {
    float q[3];
    for (int k = 0; k < 3; ++k) {
        lambda[k] = float(double(e[k]) * tr.inv_area2);
        q[k] = lambda[k] * tr.tri->inv_w[k];
    }
    const float sum = q[0] + q[1] + q[2];
    const float inv = sum != 0.0f ? 1.0f / sum : 0.0f;
    for (int k = 0; k < 3; ++k)
        persp[k] = q[k] * inv;
    return inv;
}

glm::vec2 interpolateUv(const TriangleRaster& tr, const float b[3]) {
    return b[0] * tr.v[0]->uv + b[1] * tr.v[1]->uv + b[2] * tr.v[2]->uv;
}

// One 2x2 quad at (qx, qy) (even coordinates). `e` holds the edge values at its top-left pixel.
template <class Sink>
void shadeQuad(const RasterContext& ctx, const TriangleRaster& tr, int32_t qx, int32_t qy,
               const int64_t e[3], Sink& sink, TileCounters& counters) {
    const SetupTri& t = *tr.tri;
    const int64_t step_x[3] = {tr.edges[0].a * kSubpixelOne, tr.edges[1].a * kSubpixelOne,
                               tr.edges[2].a * kSubpixelOne};
    const int64_t step_y[3] = {tr.edges[0].b * kSubpixelOne, tr.edges[1].b * kSubpixelOne,
                               tr.edges[2].b * kSubpixelOne};
    int64_t pe[4][3];
    uint32_t mask = 0;
    for (int p = 0; p < 4; ++p) {
        const int dx = p & 1, dy = p >> 1;
        bool inside = qx + dx < int32_t(ctx.grid.width) && qy + dy < int32_t(ctx.grid.height);
        for (int k = 0; k < 3; ++k) {
            pe[p][k] = e[k] + dx * step_x[k] + dy * step_y[k];
            inside = inside && pe[p][k] + tr.edges[k].bias >= 0;
        }
        mask |= uint32_t(inside) << p;
    }
    if (mask == 0)
        return;

    // Interpolate the whole quad (helper pixels included) so uv derivatives exist.
    float lambda[4][3], persp[4][3], distance[4];
    for (int p = 0; p < 4; ++p)
        distance[p] = barycentrics(tr, pe[p], lambda[p], persp[p]);
    const Material& m = *tr.material;
    const bool textured = m.base_color_texture.image >= 0 || m.emissive_texture.image >= 0;
    UvFootprint quad_uv[4];
    if (textured) {
        glm::vec2 uv[4];
        for (int p = 0; p < 4; ++p)
            uv[p] = interpolateUv(tr, persp[p]);
        // Coarse derivatives, one pair per quad (as GPUs' ddx/ddy).
        const glm::vec2 ddx = uv[1] - uv[0], ddy = uv[2] - uv[0];
        for (int p = 0; p < 4; ++p)
            quad_uv[p] = {uv[p], ddx, ddy};
    }

    for (int p = 0; p < 4; ++p) {
        if (!(mask & (1u << p)))
            continue;
        ++counters.covered;
        const int32_t x = qx + (p & 1), y = qy + (p >> 1);
        const size_t idx = size_t(y) * ctx.grid.width + size_t(x);
        const float* l = lambda[p];
        Fragment frag;
        frag.z = std::clamp(l[0] * t.z[0] + l[1] * t.z[1] + l[2] * t.z[2], 0.0f, 1.0f);
        frag.distance = distance[p];
        // Early depth test: legal because this tile's owner is the only writer of the pixel.
        if (!sink.test(idx, frag.z, frag.distance))
            continue;
        const float* b = persp[p];
        const glm::vec4 vcolor =
            tr.has_colors ? b[0] * tr.v[0]->color + b[1] * tr.v[1]->color + b[2] * tr.v[2]->color
                          : glm::vec4(1.0f);
        const glm::vec4 base = baseColor(ctx.shade, m, quad_uv[p], vcolor);
        if (m.alpha_mode == AlphaMode::Mask && !(base.a >= m.alpha_cutoff))
            continue;
        ++counters.passed;
        const glm::vec3 world =
            b[0] * tr.v[0]->world + b[1] * tr.v[1]->world + b[2] * tr.v[2]->world;
        glm::vec3 normal = tr.face_normal;
        if (tr.has_normals) {
            normal = b[0] * tr.v[0]->normal + b[1] * tr.v[1]->normal + b[2] * tr.v[2]->normal;
            if (!t.front_facing)
                normal = -normal;  // glTF: back faces of double-sided materials flip the normal
        }
        const glm::vec3 rgb = shadeColor(ctx.shade, m, quad_uv[p], base, world, normal);
        frag.blend = m.alpha_mode == AlphaMode::Blend;
        frag.color = glm::vec4(rgb, frag.blend ? std::clamp(base.a, 0.0f, 1.0f) : 1.0f);
        frag.primitive_id = t.primitive_id;
        if (sink.wants_gbuffer)
            frag.g = surfaceSample(ctx.shade, m, quad_uv[p], base, normal);
        sink.write(idx, frag);
    }
}

template <class Sink>
void rasterizeTriangle(const RasterContext& ctx, const GeometryChunk& chunk, const SetupTri& t,
                       int32_t tile_x0, int32_t tile_y0, int32_t tile_x1, int32_t tile_y1,
                       Sink& sink, TileCounters& counters) {
    const GeometryState& geo = *ctx.geometry;
    const Draw& draw = geo.draws[t.draw];
    const Primitive& prim = ctx.shade.scene->meshes[draw.mesh].primitives[draw.primitive];
    TriangleRaster tr;
    tr.tri = &t;
    for (int k = 0; k < 3; ++k)
        tr.v[k] = &geo.vertex(chunk, t.vertex[k]);
    tr.material = &materialOf(*ctx.shade.scene, prim);
    makeEdges(t, tr.edges);
    tr.inv_area2 = 1.0 / double(t.area2);
    tr.has_normals = !prim.normals.empty();
    tr.has_colors = !prim.colors.empty();
    tr.face_normal = glm::cross(tr.v[1]->world - tr.v[0]->world, tr.v[2]->world - tr.v[0]->world);
    if (glm::dot(tr.face_normal, ctx.shade.eye - tr.v[0]->world) < 0.0f)
        tr.face_normal = -tr.face_normal;
    sink.beginTriangle(t);

    // Pixel range of this triangle in this tile, widened to whole quads.
    const int32_t x0 = std::max(t.min_x, tile_x0) & ~1, y0 = std::max(t.min_y, tile_y0) & ~1;
    const int32_t x1 = std::min(t.max_x, tile_x1), y1 = std::min(t.max_y, tile_y1);
    for (int32_t by = y0; by <= y1; by += kBlockSize - (by % kBlockSize)) {
        const int32_t by1 = std::min(by + kBlockSize - 1 - (by % kBlockSize), y1);
        for (int32_t bx = x0; bx <= x1; bx += kBlockSize - (bx % kBlockSize)) {
            const int32_t bx1 = std::min(bx + kBlockSize - 1 - (bx % kBlockSize), x1);
            // Block reject: some edge is negative at the block's most inside corner.
            bool reject = false;
            for (int k = 0; k < 3 && !reject; ++k) {
                const Edge& e = tr.edges[k];
                const int64_t px = e.a > 0 ? centre(bx1) : centre(bx);
                const int64_t py = e.b > 0 ? centre(by1) : centre(by);
                reject = e.at(px, py) + e.bias < 0;
            }
            if (reject)
                continue;
            for (int32_t qy = by; qy <= by1; qy += 2) {
                int64_t e[3];
                for (int k = 0; k < 3; ++k)
                    e[k] = tr.edges[k].at(centre(bx), centre(qy));
                for (int32_t qx = bx; qx <= bx1; qx += 2) {
                    shadeQuad(ctx, tr, qx, qy, e, sink, counters);
                    for (int k = 0; k < 3; ++k)
                        e[k] += 2 * tr.edges[k].a * kSubpixelOne;
                }
            }
        }
    }
}

}  // namespace

template <class Sink>
void rasterizeTile(const RasterContext& ctx, uint32_t tile, Sink& sink, TileCounters& counters) {
    const TileGrid& g = ctx.grid;
    const int32_t ts = int32_t(g.tile_size);
    const int32_t tx0 = int32_t(tile % g.tiles_x) * ts, ty0 = int32_t(tile / g.tiles_x) * ts;
    const int32_t tx1 = std::min(tx0 + ts, int32_t(g.width)) - 1;
    const int32_t ty1 = std::min(ty0 + ts, int32_t(g.height)) - 1;
    const GeometryState& geo = *ctx.geometry;
    for (size_t c = 0; c < geo.chunks.size(); ++c) {
        const ChunkBins& bins = (*ctx.bins)[c];
        const GeometryChunk& chunk = geo.chunks[c];
        for (uint32_t i = bins.offsets[tile]; i < bins.offsets[tile + 1]; ++i)
            rasterizeTriangle(ctx, chunk, chunk.tris[bins.items[i]], tx0, ty0, tx1, ty1, sink,
                              counters);
    }
}

template void rasterizeTile<FrameSink>(const RasterContext&, uint32_t, FrameSink&, TileCounters&);
template void rasterizeTile<LayerSink>(const RasterContext&, uint32_t, LayerSink&, TileCounters&);
template void rasterizeTile<ListSink>(const RasterContext&, uint32_t, ListSink&, TileCounters&);

}  // namespace raster
