// Output mergers ("sinks") for the tile raster: what happens to a shaded fragment.
//  - FrameSink: the ordinary framebuffer (depth test LESS, over-blending for BLEND).
//  - LayerSink: layered rendering, Lee et al. 2009 §4.2 (one depth buffer per layer).
//  - ListSink: per-pixel fragment linked lists, Yang et al. 2010 / Selgrad et al. 2015 §4.
// A sink only touches pixels of the tile being rasterized, so one instance per tile is safe.
#pragma once

#include "geometry.h"
#include "tile_raster.h"

#include <raster/camera.h>
#include <raster/fragment_lists.h>
#include <raster/frame.h>
#include <raster/layered_target.h>

#include <cstdint>
#include <vector>

namespace raster {

// Over operator for a BLEND fragment onto the stored colour (alpha accumulates coverage).
inline glm::vec4 blendOver(glm::vec4 src, glm::vec4 dst) {
    const float a = src.a;
    return {src.r * a + dst.r * (1.0f - a), src.g * a + dst.g * (1.0f - a),
            src.b * a + dst.b * (1.0f - a), a + dst.a * (1.0f - a)};
}

struct FrameSink {
    Frame& frame;
    const DepthBuffer* peel = nullptr; // depth peeling: keep only fragments behind this
    static constexpr bool wants_gbuffer = false;

    void beginTriangle(const SetupTri&, bool) {}
    bool test(size_t pixel, float z, float) const {
        const float stored = frame.depth.quantize(z);
        return stored < frame.depth.load(pixel) && (!peel || stored > peel->load(pixel));
    }
    // RenderOptions::depth_only: an unshaded OPAQUE fragment stores only its depth.
    void writeDepth(size_t pixel, float z) { frame.depth.store(pixel, z); }
    // The two halves of write for a lit, non-BLEND fragment, stored apart by the tile raster's
    // light queue: queue() stores what the next fragments' tests read (here the depth) and
    // says where the colour goes, writeQueued() stores the colour once it is shaded.
    bool queuesLight() const { return true; }
    size_t queue(size_t pixel, float z, uint32_t) {
        writeDepth(pixel, z);
        return pixel;
    }
    void writeQueued(size_t pixel, glm::vec4 c) {
        float* dst = &frame.color[pixel * 4];
        dst[0] = c.r, dst[1] = c.g, dst[2] = c.b, dst[3] = c.a;
    }
    void write(size_t pixel, const Fragment& f) {
        float* dst = &frame.color[pixel * 4];
        const glm::vec4 c =
            f.blend ? blendOver(f.color, glm::vec4(dst[0], dst[1], dst[2], dst[3])) : f.color;
        dst[0] = c.r, dst[1] = c.g, dst[2] = c.b, dst[3] = c.a;
        if (!f.blend)
            frame.depth.store(pixel, f.z);
        else if (frame.transparent_depth.quantize(f.z) < frame.transparent_depth.load(pixel))
            frame.transparent_depth.store(pixel, f.z);
    }
};

struct LayerSink {
    LayeredTarget& target;
    const std::vector<LayerInterval>& intervals; // overlapped, one per layer
    bool wants_gbuffer = false;
    uint32_t triangle_layer = 0; // MaxVertexDepth routing: the current triangle's layer
    bool blend_triangle = false;

    // BLEND fragments go, one by one, to the transparent plane of the one layer whose own
    // (not overlapped) interval holds them: each pane is in exactly one plane, so a ray blends
    // it once, and no copy pass is needed for those planes.
    void beginTriangle(const SetupTri& t, bool blend) {
        blend_triangle = blend;
        if (!blend && target.desc.routing == LayerRouting::MaxVertexDepth)
            triangle_layer = layerOf(target.desc, t.max_distance);
    }
    bool passes(uint32_t layer, size_t pixel, float z) const {
        const size_t i = target.index(layer, pixel);
        return target.depth.quantize(z) < target.depth.load(i);
    }
    bool holds(uint32_t layer, float distance) const {
        return distance >= intervals[layer].near_d && distance < intervals[layer].far_d;
    }
    bool test(size_t pixel, float z, float distance) const {
        if (blend_triangle)
            return passes(layerOf(target.desc, distance), pixel, z);
        if (target.desc.routing == LayerRouting::MaxVertexDepth)
            return passes(triangle_layer, pixel, z);
        for (uint32_t l = 0; l < target.layer_count; ++l)
            if (holds(l, distance) && passes(l, pixel, z))
                return true;
        return false;
    }
    void writeLayer(uint32_t layer, size_t pixel, const Fragment& f) {
        const size_t i = target.index(layer, pixel);
        if (f.blend) { // the transparent plane: over in primitive order, nearest depth
            target.transparent_color.store(i, blendOver(f.color, target.transparent_color.load(i)));
            if (target.transparent_depth.quantize(f.z) < target.transparent_depth.load(i))
                target.transparent_depth.store(i, f.z);
            if (wants_gbuffer) { // the new top pane
                target.transparent_gbuffer[i] = f.g;
                target.transparent_top_alpha[i] = f.color.a;
            }
            return;
        }
        target.color.store(i, f.color);
        target.depth.store(i, f.z);
        if (wants_gbuffer)
            target.gbuffer[i] = f.g;
    }
    // The light queue's halves of write (FrameSink) for a sink whose lit, non-BLEND fragments
    // each go to one layer: MaxVertexDepth routing (the overlapped copies are made after the
    // tile) and no G-buffer (the queue does not carry the fragment's sample). queue() stores the
    // depth in the triangle's layer and says where the colour goes.
    bool queuesLight() const {
        return target.desc.routing == LayerRouting::MaxVertexDepth && !wants_gbuffer;
    }
    size_t queue(size_t pixel, float z, uint32_t) {
        const size_t i = target.index(triangle_layer, pixel);
        target.depth.store(i, z);
        return i;
    }
    void writeQueued(size_t i, glm::vec4 c) { target.color.store(i, c); }
    void write(size_t pixel, const Fragment& f) {
        if (f.blend) {
            writeLayer(layerOf(target.desc, f.distance), pixel, f);
            return;
        }
        if (target.desc.routing == LayerRouting::MaxVertexDepth) {
            writeLayer(triangle_layer, pixel, f);
            return;
        }
        for (uint32_t l = 0; l < target.layer_count; ++l)
            if (holds(l, f.distance) && passes(l, pixel, f.z))
                writeLayer(l, pixel, f);
    }
};

// One collected fragment: a node of a per-pixel linked list.
struct FragmentNode {
    glm::vec4 color; // RGB + opacity, full precision until the resolve stores the chosen format
    float z;
    uint32_t primitive_id;
    uint32_t next; // index of the next node in this tile's pool, kNoNode at the tail
};
constexpr uint32_t kNoNode = 0xffffffffu;

// Collects into the tile's own node pool (appending at the list head, as an atomic exchange on
// the GPU does); pools are concatenated in tile order afterwards, so node order is deterministic.
//
// Early rejection (when `nearest` is set, for a cap of N fragments per pixel): the sink keeps the
// k smallest keys written to each pixel so far and rejects, before shading, a fragment that the
// resolve would drop whatever arrives later.
//  - Without hidden fragments (FragmentListDesc::hidden_epsilon = 0): k = N keys, the stored
//    depths; a fragment beyond the N-th is rejected. Exact whatever the arrival order: N
//    fragments strictly nearer sort before it.
//  - With them (`hidden_scale` = 1 + ε, ε > 0): k >= N keys, the view distances; a fragment is
//    rejected when N of the nearer keys are spaced by more than the factor 1 + ε. Each of those N
//    is either kept by the resolve or hidden by a kept opaque fragment in front of it, and no
//    kept fragment hides two of them (its window d_o..d_o(1 + ε) holds at most one), so N kept
//    fragments sort before it. The k nearest are a subset of the pixel's fragments, so the test
//    only ever under-counts: it may keep a fragment the resolve drops, never the reverse.
struct ListSink {
    std::vector<uint32_t>& head;     // per pixel: first node (tile-local index) or kNoNode
    std::vector<FragmentNode>& pool; // this tile's nodes
    // Per pixel of the tile (row-major, tile_size wide), k key slots, the first used[] of them
    // in use, in ascending order (the slots behind are unused, as +inf keys would be); null
    // when early rejection is off.
    float* nearest = nullptr;
    uint8_t* used = nullptr;
    uint32_t k = 0;
    uint32_t cap = 0;           // N
    float hidden_scale = 0.0f;  // 1 + ε with hidden fragments, else 0 (the keys are depths)
    const View* view = nullptr; // for the distances of the keys with hidden fragments
    uint32_t frame_width = 0, tile_x0 = 0, tile_y0 = 0, tile_size = 0;
    static constexpr bool wants_gbuffer = false;

    // The pixel's index in the tile (nearest holds k keys, used one count per index).
    size_t tilePixel(size_t pixel) const {
        const size_t x = pixel % frame_width, y = pixel / frame_width;
        return (y - tile_y0) * tile_size + (x - tile_x0);
    }
    float keyOf(float z) const { return hidden_scale > 0.0f ? distanceFromDepth(*view, z) : z; }
    void beginTriangle(const SetupTri&, bool) {}
    bool test(size_t pixel, float z, float) const {
        if (!nearest)
            return true;
        const size_t t = tilePixel(pixel);
        const float* keys = nearest + t * k;
        const uint32_t n = used[t];
        if (!(hidden_scale > 0.0f))
            return n < k || !(z > keys[k - 1]);
        const float d = keyOf(z);
        uint32_t spaced = 0;
        float last = 0.0f;
        for (uint32_t i = 0; i < n && keys[i] < d; ++i)
            if (spaced == 0 || keys[i] > last * hidden_scale) {
                last = keys[i];
                if (++spaced == cap)
                    return false;
            }
        return true;
    }
    void write(size_t pixel, const Fragment& f) { writeNode(pixel, f.color, f.z, f.primitive_id); }
    // The light queue's halves of write (FrameSink): the node and its key at once, in
    // primitive order, its colour when shaded (node order is what decides; colours are read
    // only by the resolve, after the tile).
    bool queuesLight() const { return true; }
    size_t queue(size_t pixel, float z, uint32_t primitive_id) {
        writeNode(pixel, glm::vec4(0.0f), z, primitive_id);
        return pool.size() - 1;
    }
    void writeQueued(size_t node, glm::vec4 c) { pool[node].color = c; }
    void writeNode(size_t pixel, glm::vec4 color, float z, uint32_t primitive_id) {
        pool.push_back({color, z, primitive_id, head[pixel]});
        head[pixel] = uint32_t(pool.size() - 1);
        // Early rejection: the key joins the pixel's ascending keys (of k + 1, the largest goes).
        if (nearest) {
            const size_t t = tilePixel(pixel);
            float* d = nearest + t * k;
            const uint32_t n = used[t];
            const float key = keyOf(z);
            // An unused slot counts as +inf: a +inf or NaN key is never stored.
            if (key < (n < k ? INFINITY : d[k - 1])) {
                uint32_t i = n < k ? n : k - 1; // shift only the keys in use
                for (; i > 0 && d[i - 1] > key; --i)
                    d[i] = d[i - 1];
                d[i] = key;
                used[t] = uint8_t(n < k ? n + 1 : k);
            }
        }
    }
};

} // namespace raster
