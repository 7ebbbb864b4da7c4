#include "tile_raster.h"

#include "quad_kernel.h"
#include "sinks.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <concepts>

namespace raster {

namespace {

static_assert(kQuadLanes == kTextureLanes, "the texture kernel samples a quad pair's lanes");

constexpr int32_t kBlockSize = 8; // hierarchical test: tile -> 8x8 block -> 2x2 quad -> pixel

// Per-triangle constants for the pixel loop.
struct TriangleRaster {
    const SetupTri* tri;
    const ShadeVertex* v[3];
    const Material* material;
    Edge edges[3];
    const Primitive* prim;
    // The quad kernel's input: everything but the edge values and the viewport lanes is the
    // triangle's, filled once; queueQuadPair sets those two per quad pair.
    QuadInput quad;
    // Pixel index of lane l relative to the quad pair's first pixel (the tile's, laneOffsets).
    const size_t* lane_offset;
    // The lookups the material makes: base colour (0) and emissive (1; not when its factor is 0).
    bool textured[2];
    const TextureRef* texture[2];
    // Both are made and the emissive one reads the base colour's coordinates and levels
    // (sameFootprint): its quad pairs are prepared once, the coordinates queued once.
    bool shared_lookup;
    // The vertex attributes and material constants the lanes share, filled when the first
    // lanes of the triangle pass the depth test (many small triangles never get there).
    bool frag_ready;
    FragmentTriangle frag;
};

void fillFragmentTriangle(const ShadeContext& shade, TriangleRaster& tr) {
    const SetupTri& t = *tr.tri;
    glm::vec3 face_normal =
        glm::cross(tr.v[1]->world - tr.v[0]->world, tr.v[2]->world - tr.v[0]->world);
    if (glm::dot(face_normal, shade.eye - tr.v[0]->world) < 0.0f)
        face_normal = -face_normal;
    FragmentTriangle& f = tr.frag;
    const Material& m = *tr.material;
    f.has_colors = !tr.prim->colors.empty();
    f.has_normals = !tr.prim->normals.empty();
    f.flip_normal = !t.front_facing;
    f.mask = m.alpha_mode == AlphaMode::Mask;
    f.blend = m.alpha_mode == AlphaMode::Blend;
    f.alpha_cutoff = m.alpha_cutoff;
    for (int c = 0; c < 4; ++c) {
        f.base_factor[c] = m.base_color_factor[c];
        for (int k = 0; k < 3; ++k)
            f.color[c][k] = tr.v[k]->color[c];
    }
    for (int c = 0; c < 3; ++c) {
        f.face_normal[c] = face_normal[c];
        f.emissive_factor[c] = m.emissive_factor[c];
        for (int k = 0; k < 3; ++k) {
            f.world[c][k] = tr.v[k]->world[c];
            f.normal[c][k] = tr.v[k]->normal[c];
        }
    }
    tr.frag_ready = true;
}

// Lit, non-BLEND lanes of a tile's fragments waiting for the lighting kernel, which shades two
// blocks of eight lanes in one call for about 1.4 times the cost of one block (its chains
// interleave, light_kernel.h). The blocks fill in queue order: the lanes of a fragment kernel
// call (shadeLanes) with at most kQueuedLanes lit lanes are packed lane by lane (a triangle's
// last few lanes), those of a call with more are written by the fragment kernel straight into
// the next whole block, its lanes in place. The kernel's lanes are independent, so neither changes
// a bit. A queued lane goes to the sink when it is queued (`queue`: the frame's depth, which
// the next triangle's depth test must see; a fragment list's node and key, in primitive order),
// its colour when the batch is shaded (`writeQueued`), in queue order, so a pixel queued twice
// still ends with its later triangle's colour. The batch is shaded when full, when the
// lighting constants change, before any colour written without it (unlit or BLEND lanes, which
// may land on a queued pixel) and at the end of the tile. Every sink stores a fragment in
// these two halves when its queuesLight() says so: the frame and the fragment lists always, the
// layers when each fragment goes to one layer (copies into several layers need the colour).

// Calls with at most this many lit lanes are packed into the light queue lane by lane.
constexpr uint32_t kQueuedLanes = 4;

struct LightBatch {
    static constexpr int kBlocks = 2;
    static constexpr int kLanes = kBlocks * kLightLanes;
    LightLanes block[kBlocks]{}; // zeroed once: the SIMD kernel reads every lane
    size_t handle[kLanes] = {};  // where each lane's colour goes (the sink's queue())
    float alpha[kLanes] = {};
    uint32_t queued = 0; // bit i: lane i (block i / 8, lane i % 8) holds a queued fragment
    LightMaterial material;
    int count = 0; // lanes [0, count) are filled or passed over

    LightLanes& blockOf(int lane) { return block[lane / kLightLanes]; }
};

template <class Sink> void shadeBatch(const RasterContext& ctx, LightBatch& batch, Sink& sink) {
    if (batch.count == 0)
        return;
    const float eye[3] = {ctx.shade.eye.x, ctx.shade.eye.y, ctx.shade.eye.z};
    const int blocks = (batch.count + kLightLanes - 1) / kLightLanes;
    ctx.shade.light_kernel(ctx.shade.lights, ctx.shade.light_count, batch.material, eye,
                           batch.block, blocks, batch.count - (blocks - 1) * kLightLanes);
    for (uint32_t rest = batch.queued; rest != 0; rest &= rest - 1) {
        const int i = std::countr_zero(rest), l = i % kLightLanes;
        const LightLanes& b = batch.blockOf(i);
        sink.writeQueued(batch.handle[i], {b.rgb[0][l], b.rgb[1][l], b.rgb[2][l], batch.alpha[i]});
    }
    batch.count = 0;
    batch.queued = 0;
}

// Makes `batch` take lanes of `material`: shades what it holds for another material first.
template <class Sink>
void useMaterial(const RasterContext& ctx, LightBatch& batch, const LightMaterial& material,
                 Sink& sink) {
    if (batch.count > 0 && (batch.material.metallic != material.metallic ||
                            batch.material.roughness != material.roughness))
        shadeBatch(ctx, batch, sink);
    batch.material = material;
}

// Lanes of the current triangle that passed the depth test, waiting for the texture, fragment
// and lighting kernels. A triangle's quad pairs leave a few lanes each (on average demo 5.2 of 8,
// ToyCar 2.8, dense 1.9: the edges of small triangles), and those kernels cost the same for one
// lane as for eight, so the lanes are packed here, in pair and lane order, and shaded eight at
// a time; the kernels' lanes are independent, so this changes no bit. The lanes are distinct
// pixels of one triangle, so shading them later in the triangle changes no depth test. The
// queue is shaded when full, before a quad whose lookups read other levels (one texture kernel
// call reads one selection) and at the end of the triangle, before the next one is tested.
struct FragmentQueue {
    int count = 0;
    // Zeroed once: the kernels read every lane (the lanes past `count` keep earlier values).
    alignas(32) float persp[3][kQuadLanes] = {};
    alignas(32) float z[kQuadLanes] = {};
    alignas(32) float distance[kQuadLanes] = {};
    size_t pixel[kQuadLanes] = {};
    // The base colour (0) and emissive (1) lookups: each lane's coordinates and mip weight, the
    // levels every queued lane reads, and the texels once sampled.
    TextureLanes texture[2] = {};
    LevelSelection sel[2];
};

// Lanes ready for the texture, fragment and lighting kernels: the queue's, or a quad pair's in
// place (lane arrays of kQuadLanes; texture[k] and sel[k] read only for the material's lookups).
struct FragmentLanes {
    const float (*persp)[kQuadLanes];
    const float* z;
    const float* distance;
    const size_t* pixel;
    TextureLanes* texture[2];
    const LevelSelection* sel[2];
};

// Shades the lanes set in `lanes`: their texels (the texture kernel), attributes, base colour and
// alpha test (the fragment kernel), then the lanes that pass are lit together (the lighting
// kernel) and handed to the sink, in lane order.
template <class Sink>
void shadeLanes(const RasterContext& ctx, TriangleRaster& tr, const FragmentLanes& f,
                uint32_t lanes, Sink& sink, LightBatch& batch, TileCounters& counters) {
    const SetupTri& t = *tr.tri;
    const Material& m = *tr.material;
    if (tr.shared_lookup) {
        TextureLanes& emissive = *f.texture[1];
        std::copy_n(f.texture[0]->u, kTextureLanes, emissive.u);
        std::copy_n(f.texture[0]->v, kTextureLanes, emissive.v);
        std::copy_n(f.texture[0]->weight, kTextureLanes, emissive.weight);
    }
    for (int k = 0; k < 2; ++k)
        if (tr.textured[k]) // the fragment kernel reads the emissive colour, not its alpha
            sampleLanes(ctx.shade, *tr.texture[k], *f.sel[k], lanes, k == 1, *f.texture[k]);
    const float(*base_texel)[kQuadLanes] = tr.textured[0] ? f.texture[0]->rgba : nullptr;
    const float(*emissive_texel)[kQuadLanes] = tr.textured[1] ? f.texture[1]->rgba : nullptr;

    if (!tr.frag_ready)
        fillFragmentTriangle(ctx.shade, tr);
    const bool unlit = isUnlit(ctx.shade, m);
    const bool blend = m.alpha_mode == AlphaMode::Blend;
    const bool queued = !unlit && !blend && sink.queuesLight();
    if (queued && laneCount(lanes) > kQueuedLanes) {
        // A whole block of the light queue, written in place by the fragment kernel.
        useMaterial(ctx, batch, {m.metallic_factor, m.roughness_factor}, sink);
        int start = (batch.count + kLightLanes - 1) / kLightLanes * kLightLanes;
        if (start == LightBatch::kLanes) {
            shadeBatch(ctx, batch, sink);
            start = 0;
        }
        const uint32_t passed =
            ctx.fragment_kernel(tr.frag, f.persp, base_texel, emissive_texel, lanes,
                                batch.blockOf(start), batch.alpha + start);
        if (passed == 0)
            return;
        counters.passed += laneCount(passed);
        for (uint32_t rest = passed; rest != 0; rest &= rest - 1) {
            const int l = std::countr_zero(rest);
            batch.handle[start + l] = sink.queue(f.pixel[l], f.z[l], t.primitive_id);
        }
        batch.queued |= passed << start;
        batch.count = start + kLightLanes;
        if (batch.count == LightBatch::kLanes)
            shadeBatch(ctx, batch, sink);
        return;
    }
    LightLanes light;
    alignas(32) float alpha[kQuadLanes];
    const uint32_t passed =
        ctx.fragment_kernel(tr.frag, f.persp, base_texel, emissive_texel, lanes, light, alpha);
    if (passed == 0)
        return;
    counters.passed += laneCount(passed);
    if (queued) {
        // At most kQueuedLanes lanes: packed into the light queue.
        useMaterial(ctx, batch, {m.metallic_factor, m.roughness_factor}, sink);
        for (uint32_t rest = passed; rest != 0; rest &= rest - 1) {
            const int l = std::countr_zero(rest);
            const int i = batch.count++, j = i % kLightLanes;
            batch.handle[i] = sink.queue(f.pixel[l], f.z[l], t.primitive_id);
            LightLanes& b = batch.blockOf(i);
            for (int c = 0; c < 3; ++c) {
                b.albedo[c][j] = light.albedo[c][l];
                b.emissive[c][j] = light.emissive[c][l];
                b.world[c][j] = light.world[c][l];
                b.normal[c][j] = light.normal[c][l];
            }
            batch.alpha[i] = alpha[l];
            batch.queued |= 1u << i;
            if (batch.count == LightBatch::kLanes)
                shadeBatch(ctx, batch, sink);
        }
        return;
    }
    shadeBatch(ctx, batch, sink); // queued colours land before these
    if (!unlit) {
        const float eye[3] = {ctx.shade.eye.x, ctx.shade.eye.y, ctx.shade.eye.z};
        ctx.shade.light_kernel(ctx.shade.lights, ctx.shade.light_count,
                               {m.metallic_factor, m.roughness_factor}, eye, &light, 1,
                               int(std::bit_width(passed)));
    }
    for (uint32_t rest = passed; rest != 0; rest &= rest - 1) {
        const int l = std::countr_zero(rest);
        Fragment frag;
        frag.z = f.z[l];
        frag.distance = f.distance[l];
        frag.blend = blend;
        frag.color.a = alpha[l];
        frag.primitive_id = t.primitive_id;
        for (int c = 0; c < 3; ++c)
            frag.color[c] = unlit ? light.albedo[c][l] + light.emissive[c][l] : light.rgb[c][l];
        if (sink.wants_gbuffer) {
            const glm::vec3 base(light.albedo[0][l], light.albedo[1][l], light.albedo[2][l]);
            const glm::vec3 emissive(light.emissive[0][l], light.emissive[1][l],
                                     light.emissive[2][l]);
            const glm::vec3 normal(light.normal[0][l], light.normal[1][l], light.normal[2][l]);
            frag.g = surfaceSample(ctx.shade, m, base, emissive, normal);
        }
        sink.write(f.pixel[l], frag);
    }
}

// Shades the queued lanes and empties the queue.
template <class Sink>
void shadeQueue(const RasterContext& ctx, TriangleRaster& tr, FragmentQueue& queue, Sink& sink,
                LightBatch& batch, TileCounters& counters) {
    if (queue.count == 0)
        return;
    const uint32_t lanes = (1u << queue.count) - 1;
    queue.count = 0;
    const FragmentLanes f{queue.persp,
                          queue.z,
                          queue.distance,
                          queue.pixel,
                          {&queue.texture[0], &queue.texture[1]},
                          {&queue.sel[0], &queue.sel[1]}};
    shadeLanes(ctx, tr, f, lanes, sink, batch, counters);
}

// Two 2x2 quads at (qx, qy) and (qx + 2, qy) (qx a multiple of 4, qy even): the quad kernel finds
// coverage, barycentrics and depth for the 8 pixels at once; the covered ones that pass the
// depth test join the fragment queue, with what their texture lookups need from the pair.
template <class Sink>
void queueQuadPair(const RasterContext& ctx, TriangleRaster& tr, int32_t qx, int32_t qy, Sink& sink,
                   FragmentQueue& queue, LightBatch& batch, TileCounters& counters) {
    QuadInput& in = tr.quad;
    for (int k = 0; k < 3; ++k)
        in.edge[k] = double(tr.edges[k].at(pixelCentre(qx), pixelCentre(qy)));
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
    const size_t first_pixel = size_t(qy) * ctx.grid.width + size_t(qx);
    // Early depth test of every covered lane: legal because this tile's owner is the only
    // writer of the pixel. Lanes are distinct pixels and nothing is written before all are
    // tested, so testing them all first is the same as one at a time.
    uint32_t tested = 0;
    for (uint32_t rest = q.mask; rest != 0; rest &= rest - 1) {
        const int l = std::countr_zero(rest);
        tested |= uint32_t(sink.test(first_pixel + tr.lane_offset[l], q.z[l], q.distance[l])) << l;
    }
    counters.covered += laneCount(q.mask);
    counters.rejected += laneCount(q.mask & ~tested);
    if (tested == 0)
        return;
    if constexpr (requires(Sink & s) { s.writeDepth(size_t{}, 0.0f); }) {
        // Depth only: every OPAQUE lane passes the alpha test (the fragment kernel keeps them
        // all), so the lanes that passed the depth test store their depth as shaded ones would.
        if (ctx.depth_only && m.alpha_mode == AlphaMode::Opaque) {
            for (uint32_t rest = tested; rest != 0; rest &= rest - 1) {
                const int l = std::countr_zero(rest);
                sink.writeDepth(first_pixel + tr.lane_offset[l], q.z[l]);
            }
            counters.passed += laneCount(tested);
            return;
        }
    }

    QuadPairLookup lookup[2]; // read only where the material makes the lookup
    // The lookups' levels and coordinates: the emissive one's are the base colour's when shared.
    const QuadPairLookup* look[2] = {&lookup[0], tr.shared_lookup ? &lookup[0] : &lookup[1]};
    if (tr.textured[0] || tr.textured[1]) {
        // Every lane is interpolated (helper pixels included) so each quad has coarse
        // derivatives, one pair per quad (as GPUs' ddx/ddy): sum_k persp_k uv_k, perspective-
        // correct, summed in vertex order.
        const glm::vec2 uv0 = tr.v[0]->uv, uv1 = tr.v[1]->uv, uv2 = tr.v[2]->uv;
        QuadPairUv pair_uv;
        for (int l = 0; l < kQuadLanes; ++l) {
            pair_uv.u[l] = q.persp[0][l] * uv0.x + q.persp[1][l] * uv1.x + q.persp[2][l] * uv2.x;
            pair_uv.v[l] = q.persp[0][l] * uv0.y + q.persp[1][l] * uv1.y + q.persp[2][l] * uv2.y;
        }
        for (int k = 0; k < 2; ++k)
            if (tr.textured[k] && !(k == 1 && tr.shared_lookup))
                prepareQuadPair(ctx.shade, *tr.texture[k], pair_uv, lookup[k]);
    }
    // A full pair whose quads read the same levels is shaded where it is, without the copies
    // into the queue (after the queue's lanes, which come before it). Measured against pairs of
    // six or more lanes in place, and none: demo 1.026x / 1.009x / 0.976x, ToyCar 1.069x /
    // 1.064x / 1.084x the time before the queue.
    if (tested == 0xffu && (!tr.textured[0] || sameLevels(look[0]->sel[0], look[0]->sel[1])) &&
        (!tr.textured[1] || sameLevels(look[1]->sel[0], look[1]->sel[1]))) {
        shadeQueue(ctx, tr, queue, sink, batch, counters);
        size_t pixel[kQuadLanes];
        for (int l = 0; l < kQuadLanes; ++l)
            pixel[l] = first_pixel + tr.lane_offset[l];
        const FragmentLanes f{q.persp,
                              q.z,
                              q.distance,
                              pixel,
                              {&lookup[0].lanes, &lookup[1].lanes},
                              {&look[0]->sel[0], &look[1]->sel[0]}};
        shadeLanes(ctx, tr, f, tested, sink, batch, counters);
        return;
    }
    for (int quad = 0; quad < 2; ++quad) {
        uint32_t rest = (tested >> (4 * quad)) & 0xfu;
        if (rest == 0)
            continue;
        bool same = true;
        for (int k = 0; k < 2; ++k)
            same = same && (!tr.textured[k] || sameLevels(look[k]->sel[quad], queue.sel[k]));
        if (!same)
            shadeQueue(ctx, tr, queue, sink, batch, counters);
        for (int k = 0; k < 2; ++k)
            if (tr.textured[k])
                queue.sel[k] = look[k]->sel[quad];
        for (; rest != 0; rest &= rest - 1) {
            const int l = 4 * quad + std::countr_zero(rest), i = queue.count++;
            queue.pixel[i] = first_pixel + tr.lane_offset[l];
            queue.z[i] = q.z[l];
            queue.distance[i] = q.distance[l];
            for (int k = 0; k < 3; ++k)
                queue.persp[k][i] = q.persp[k][l];
            for (int k = 0; k < 2; ++k)
                if (tr.textured[k] && !(k == 1 && tr.shared_lookup)) {
                    queue.texture[k].u[i] = lookup[k].lanes.u[l];
                    queue.texture[k].v[i] = lookup[k].lanes.v[l];
                    queue.texture[k].weight[i] = lookup[k].lanes.weight[l];
                }
            if (queue.count == kQuadLanes)
                shadeQueue(ctx, tr, queue, sink, batch, counters);
        }
    }
}

template <class Sink>
void rasterizeTriangle(const RasterContext& ctx, const GeometryChunk& chunk, const SetupTri& t,
                       int32_t tile_x0, int32_t tile_y0, int32_t tile_x1, int32_t tile_y1,
                       const size_t* lane_offset, Sink& sink, FragmentQueue& queue,
                       LightBatch& batch, TileCounters& counters) {
    const GeometryState& geo = *ctx.geometry;
    const Draw& draw = geo.draws[t.draw];
    const Primitive& prim = ctx.shade.scene->meshes[draw.mesh].primitives[draw.primitive];
    TriangleRaster tr;
    tr.tri = &t;
    for (int k = 0; k < 3; ++k)
        tr.v[k] = &geo.vertex(chunk, t.vertex[k]);
    tr.material = &materialOf(*ctx.shade.scene, prim);
    makeEdges(t, tr.edges);
    for (int k = 0; k < 3; ++k) {
        const Edge& e = tr.edges[k];
        tr.quad.step_x[k] = double(e.a * kSubpixelOne);
        tr.quad.step_y[k] = double(e.b * kSubpixelOne);
        tr.quad.bias[k] = double(e.bias);
        tr.quad.inv_w[k] = t.inv_w[k];
        tr.quad.z[k] = t.z[k];
    }
    tr.quad.inv_area2 = 1.0 / double(t.area2);
    tr.lane_offset = lane_offset;
    tr.prim = &prim;
    tr.frag_ready = false;
    const Material& m = *tr.material;
    tr.textured[0] = m.base_color_texture.image >= 0;
    tr.textured[1] = m.emissive_texture.image >= 0 && m.emissive_factor != glm::vec3(0.0f);
    tr.texture[0] = &m.base_color_texture;
    tr.texture[1] = &m.emissive_texture;
    tr.shared_lookup = tr.textured[0] && tr.textured[1] &&
                       sameFootprint(*ctx.shade.scene, m.base_color_texture, m.emissive_texture);
    sink.beginTriangle(t, tr.material->alpha_mode == AlphaMode::Blend);

    // Pixel range of this triangle in this tile, widened to whole quad pairs.
    const int32_t x0 = std::max(t.min_x, tile_x0) & ~3, y0 = std::max(t.min_y, tile_y0) & ~1;
    const int32_t x1 = std::min(t.max_x, tile_x1), y1 = std::min(t.max_y, tile_y1);
    for (int32_t by = y0; by <= y1; by += kBlockSize - (by % kBlockSize)) {
        const int32_t by1 = std::min(by + kBlockSize - 1 - (by % kBlockSize), y1);
        for (int32_t bx = x0; bx <= x1; bx += kBlockSize - (bx % kBlockSize)) {
            const int32_t bx1 = std::min(bx + kBlockSize - 1 - (bx % kBlockSize), x1);
            // Block reject: some edge is negative at the block's most inside corner.
            if (!rectMayOverlap(tr.edges, bx, by, bx1, by1))
                continue;
            for (int32_t qy = by; qy <= by1; qy += 2)
                for (int32_t qx = bx; qx <= bx1; qx += 4)
                    queueQuadPair(ctx, tr, qx, qy, sink, queue, batch, counters);
        }
    }
    shadeQueue(ctx, tr, queue, sink, batch, counters);
}

template <class Sink>
void rasterizeTileImpl(const RasterContext& ctx, uint32_t tile, Sink& sink,
                       TileCounters& counters) {
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
    FragmentQueue queue;
    LightBatch batch;
    // Pixel index of lane l relative to a quad pair's first pixel (lane = quad*4 + dy*2 + dx).
    size_t lane_offset[kQuadLanes];
    for (int l = 0; l < kQuadLanes; ++l)
        lane_offset[l] = size_t((l >> 2) * 2 + (l & 1)) + size_t((l >> 1) & 1) * g.width;
    const int passes = ctx.blend_last ? 2 : 1;
    for (int pass = 0; pass < passes; ++pass)
        for (size_t c = 0; c < geo.chunks.size(); ++c) {
            const ChunkBins& bins = (*ctx.bins)[c];
            const GeometryChunk& chunk = geo.chunks[c];
            const uint32_t end = bins.offsets[tile + 1];
            for (uint32_t i = bins.offsets[tile]; i < end; ++i) {
                // A tile's triangles are scattered over its chunks, which outgrow the cache in
                // scenes of 100k triangles (ToyCar: half of this loop's own time was the first
                // load of each record): the record after next is fetched while this one is drawn.
                if (i + 2 < end) {
                    const char* next =
                        reinterpret_cast<const char*>(&chunk.tris[bins.items[i + 2]]);
                    __builtin_prefetch(next);
                    __builtin_prefetch(next + sizeof(SetupTri) - 1);
                }
                const SetupTri& t = chunk.tris[bins.items[i]];
                if (ctx.blend_last && isBlend(t) != (pass == 1))
                    continue;
                rasterizeTriangle(ctx, chunk, t, tx0, ty0, tx1, ty1, lane_offset, sink, queue,
                                  batch, local);
            }
        }
    shadeBatch(ctx, batch, sink);
    counters.covered += local.covered;
    counters.passed += local.passed;
    counters.rejected += local.rejected;
}

// rasterizeTileImpl compiled twice, for the baseline x86-64 and for AVX2 (multiview's traceTile
// does the same): `flatten` inlines what it calls from this file into each copy. The kernels stay
// behind their pointers; what the AVX2 copy changes is the code around them (lane loops 8 wide,
// blends for selects). No FMA and no reassociation, so the same bits.
template <class Sink>
__attribute__((flatten)) void rasterizeTileBaseline(const RasterContext& ctx, uint32_t tile,
                                                    Sink& sink, TileCounters& counters) {
    rasterizeTileImpl(ctx, tile, sink, counters);
}

#if defined(__x86_64__) && !defined(FOCAL_NO_SIMD)
template <class Sink>
__attribute__((flatten, target("avx2,no-fma"))) void
rasterizeTileAvx2(const RasterContext& ctx, uint32_t tile, Sink& sink, TileCounters& counters) {
    rasterizeTileImpl(ctx, tile, sink, counters);
}
#endif

} // namespace

template <class Sink>
void rasterizeTile(const RasterContext& ctx, uint32_t tile, Sink& sink, TileCounters& counters) {
#if defined(__x86_64__) && !defined(FOCAL_NO_SIMD)
    if (ctx.avx2) {
        rasterizeTileAvx2(ctx, tile, sink, counters);
        return;
    }
#endif
    rasterizeTileBaseline(ctx, tile, sink, counters);
}

template void rasterizeTile<FrameSink>(const RasterContext&, uint32_t, FrameSink&, TileCounters&);
template void rasterizeTile<LayerSink>(const RasterContext&, uint32_t, LayerSink&, TileCounters&);
template void rasterizeTile<ListSink>(const RasterContext&, uint32_t, ListSink&, TileCounters&);

} // namespace raster
