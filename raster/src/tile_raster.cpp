#include "tile_raster.h"

#include "quad_kernel.h"
#include "sinks.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>

namespace raster {

namespace {

static_assert(kQuadLanes == kTextureLanes, "the texture kernel samples a quad pair's lanes");

constexpr int32_t kBlockSize = 8; // hierarchical test: tile -> 8x8 block -> 2x2 quad -> pixel

int64_t centre(int64_t i) {
    return i * kSubpixelOne + kSubpixelOne / 2;
}

// Per-triangle constants for the pixel loop.
struct TriangleRaster {
    const SetupTri* tri;
    const ShadeVertex* v[3];
    const Material* material;
    Edge edges[3];
    double inv_area2;
    glm::vec3 face_normal; // faces the eye; used when the primitive has no normals
    bool has_normals;
    bool has_colors; // without vertex colours the colour is exactly white
};

glm::vec2 interpolateUv(const TriangleRaster& tr, const QuadOutput& q, int l) {
    return q.persp[0][l] * tr.v[0]->uv + q.persp[1][l] * tr.v[1]->uv + q.persp[2][l] * tr.v[2]->uv;
}

// Two 2x2 quads at (qx, qy) and (qx + 2, qy) (qx a multiple of 4, qy even): the quad kernel finds
// coverage, barycentrics and depth for the 8 pixels at once; the covered ones are then shaded and
// handed to the sink one by one, in lane order.
template <class Sink>
void shadeQuadPair(const RasterContext& ctx, const TriangleRaster& tr, int32_t qx, int32_t qy,
                   Sink& sink, TileCounters& counters) {
    const SetupTri& t = *tr.tri;
    QuadInput in;
    for (int k = 0; k < 3; ++k) {
        const Edge& e = tr.edges[k];
        in.edge[k] = double(e.at(centre(qx), centre(qy)));
        in.step_x[k] = double(e.a * kSubpixelOne);
        in.step_y[k] = double(e.b * kSubpixelOne);
        in.bias[k] = double(e.bias);
        in.inv_w[k] = t.inv_w[k];
        in.z[k] = t.z[k];
    }
    in.inv_area2 = tr.inv_area2;
    in.valid = 0xffu;
    if (qx + 3 >= int32_t(ctx.grid.width) || qy + 1 >= int32_t(ctx.grid.height)) {
        in.valid = 0; // on the right or bottom border of the viewport
        for (int l = 0; l < kQuadLanes; ++l) {
            const int32_t x = qx + (l >> 2) * 2 + (l & 1), y = qy + ((l >> 1) & 1);
            in.valid |= uint32_t(x < int32_t(ctx.grid.width) && y < int32_t(ctx.grid.height)) << l;
        }
    }
    QuadOutput q;
    ctx.kernel(in, q);
    if (q.mask == 0)
        return;

    const Material& m = *tr.material;
    const bool textured = m.base_color_texture.image >= 0 || m.emissive_texture.image >= 0;
    QuadPairUv pair_uv{};
    if (textured) {
        // Every lane is interpolated (helper pixels included) so each quad has coarse
        // derivatives, one pair per quad (as GPUs' ddx/ddy).
        for (int l = 0; l < kQuadLanes; ++l)
            pair_uv.uv[l] = interpolateUv(tr, q, l);
        for (int quad = 0; quad < 2; ++quad) {
            const glm::vec2* uv = &pair_uv.uv[4 * quad];
            pair_uv.duv_dx[quad] = uv[1] - uv[0];
            pair_uv.duv_dy[quad] = uv[2] - uv[0];
        }
    }

    // Early depth test of every covered lane: legal because this tile's owner is the only
    // writer of the pixel. Lanes are distinct pixels and nothing is written before all are
    // tested, so testing them all first is the same as one at a time.
    uint32_t tested = 0;
    for (int l = 0; l < kQuadLanes; ++l) {
        if (!(q.mask & (1u << l)))
            continue;
        ++counters.covered;
        const int32_t x = qx + (l >> 2) * 2 + (l & 1), y = qy + ((l >> 1) & 1);
        const size_t idx = size_t(y) * ctx.grid.width + size_t(x);
        if (sink.test(idx, q.z[l], q.distance[l]))
            tested |= 1u << l;
        else
            ++counters.rejected;
    }
    if (tested == 0)
        return;

    // The textures at the lanes that passed, together (the texture kernel).
    const bool base_textured = m.base_color_texture.image >= 0;
    const bool emissive_textured =
        m.emissive_texture.image >= 0 && m.emissive_factor != glm::vec3(0.0f);
    float base_texel[4][kTextureLanes], emissive_texel[4][kTextureLanes];
    if (base_textured)
        sampleQuadPair(ctx.shade, m.base_color_texture, pair_uv, tested, base_texel);
    if (emissive_textured)
        sampleQuadPair(ctx.shade, m.emissive_texture, pair_uv, tested, emissive_texel);

    // Per lane that passed: base colour (factor x vertex colour x texture), alpha test.
    const bool blend = m.alpha_mode == AlphaMode::Blend;
    float alpha[kQuadLanes];
    int lane_of[kQuadLanes];
    glm::vec3 normals[kQuadLanes];
    int active = 0;
    LightLanes light;
    for (int l = 0; l < kQuadLanes; ++l) {
        if (!(tested & (1u << l)))
            continue;
        const float b[3] = {q.persp[0][l], q.persp[1][l], q.persp[2][l]};
        const glm::vec4 vcolor =
            tr.has_colors ? b[0] * tr.v[0]->color + b[1] * tr.v[1]->color + b[2] * tr.v[2]->color
                          : glm::vec4(1.0f);
        glm::vec4 base = m.base_color_factor * vcolor;
        if (base_textured)
            base *=
                glm::vec4(base_texel[0][l], base_texel[1][l], base_texel[2][l], base_texel[3][l]);
        if (m.alpha_mode == AlphaMode::Mask && !(base.a >= m.alpha_cutoff))
            continue;
        // A BLEND fragment of opacity 0 changes nothing: dropped like a masked one, so it takes
        // no fragment-list slot and no transparent depth.
        if (blend && !(base.a > 0.0f))
            continue;
        ++counters.passed;
        const glm::vec3 world =
            b[0] * tr.v[0]->world + b[1] * tr.v[1]->world + b[2] * tr.v[2]->world;
        glm::vec3 normal = tr.face_normal;
        if (tr.has_normals) {
            normal = b[0] * tr.v[0]->normal + b[1] * tr.v[1]->normal + b[2] * tr.v[2]->normal;
            if (!t.front_facing)
                normal = -normal; // glTF: back faces of double-sided materials flip the normal
        }
        glm::vec3 emissive = m.emissive_factor;
        if (emissive_textured)
            emissive *= glm::vec3(emissive_texel[0][l], emissive_texel[1][l], emissive_texel[2][l]);
        for (int c = 0; c < 3; ++c) {
            light.albedo[c][active] = base[c];
            light.emissive[c][active] = emissive[c];
            light.world[c][active] = world[c];
            light.normal[c][active] = normal[c];
        }
        alpha[active] = blend ? std::clamp(base.a, 0.0f, 1.0f) : 1.0f;
        normals[active] = normal;
        lane_of[active++] = l;
    }
    if (active == 0)
        return;

    // Shade the surviving lanes together (the lighting kernel), then hand them to the sink.
    const bool unlit = isUnlit(ctx.shade, m);
    if (!unlit) {
        const float eye[3] = {ctx.shade.eye.x, ctx.shade.eye.y, ctx.shade.eye.z};
        ctx.shade.light_kernel(ctx.shade.lights, ctx.shade.light_count,
                               {m.metallic_factor, m.roughness_factor}, eye, light, active);
    }
    for (int i = 0; i < active; ++i) {
        const int l = lane_of[i];
        const int32_t x = qx + (l >> 2) * 2 + (l & 1), y = qy + ((l >> 1) & 1);
        Fragment frag;
        frag.z = q.z[l];
        frag.distance = q.distance[l];
        frag.blend = blend;
        frag.color.a = alpha[i];
        frag.primitive_id = t.primitive_id;
        for (int c = 0; c < 3; ++c)
            frag.color[c] = unlit ? light.albedo[c][i] + light.emissive[c][i] : light.rgb[c][i];
        if (sink.wants_gbuffer) {
            const glm::vec3 base(light.albedo[0][i], light.albedo[1][i], light.albedo[2][i]);
            const glm::vec3 emissive(light.emissive[0][i], light.emissive[1][i],
                                     light.emissive[2][i]);
            frag.g = surfaceSample(ctx.shade, m, base, emissive, normals[i]);
        }
        sink.write(size_t(y) * ctx.grid.width + size_t(x), frag);
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
    sink.beginTriangle(t, tr.material->alpha_mode == AlphaMode::Blend);

    // Pixel range of this triangle in this tile, widened to whole quad pairs.
    const int32_t x0 = std::max(t.min_x, tile_x0) & ~3, y0 = std::max(t.min_y, tile_y0) & ~1;
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
            for (int32_t qy = by; qy <= by1; qy += 2)
                for (int32_t qx = bx; qx <= bx1; qx += 4)
                    shadeQuadPair(ctx, tr, qx, qy, sink, counters);
        }
    }
}

} // namespace

template <class Sink>
void rasterizeTile(const RasterContext& ctx, uint32_t tile, Sink& sink, TileCounters& counters) {
    const TileGrid& g = ctx.grid;
    const int32_t ts = int32_t(g.tile_size);
    const int32_t tx0 = int32_t(tile % g.tiles_x) * ts, ty0 = int32_t(tile / g.tiles_x) * ts;
    const int32_t tx1 = std::min(tx0 + ts, int32_t(g.width)) - 1;
    const int32_t ty1 = std::min(ty0 + ts, int32_t(g.height)) - 1;
    const GeometryState& geo = *ctx.geometry;
    // BLEND triangles go after every OPAQUE and MASK one, as renderers draw them: they write no
    // depth, so an opaque surface behind a pane drawn later would otherwise overwrite the pane.
    // Each pass keeps primitive order.
    auto isBlend = [&](const SetupTri& t) {
        const Draw& draw = geo.draws[t.draw];
        const Primitive& prim = ctx.shade.scene->meshes[draw.mesh].primitives[draw.primitive];
        return materialOf(*ctx.shade.scene, prim).alpha_mode == AlphaMode::Blend;
    };
    // Counted on the stack and added once: neighbouring tiles' counters share cache lines, and
    // the workers usually raster neighbouring tiles (false sharing on every fragment).
    TileCounters local;
    const int passes = ctx.blend_last ? 2 : 1;
    for (int pass = 0; pass < passes; ++pass)
        for (size_t c = 0; c < geo.chunks.size(); ++c) {
            const ChunkBins& bins = (*ctx.bins)[c];
            const GeometryChunk& chunk = geo.chunks[c];
            for (uint32_t i = bins.offsets[tile]; i < bins.offsets[tile + 1]; ++i) {
                const SetupTri& t = chunk.tris[bins.items[i]];
                if (ctx.blend_last && isBlend(t) != (pass == 1))
                    continue;
                rasterizeTriangle(ctx, chunk, t, tx0, ty0, tx1, ty1, sink, local);
            }
        }
    counters.covered += local.covered;
    counters.passed += local.passed;
    counters.rejected += local.rejected;
}

template void rasterizeTile<FrameSink>(const RasterContext&, uint32_t, FrameSink&, TileCounters&);
template void rasterizeTile<LayerSink>(const RasterContext&, uint32_t, LayerSink&, TileCounters&);
template void rasterizeTile<ListSink>(const RasterContext&, uint32_t, ListSink&, TileCounters&);

} // namespace raster
