#include "geometry.h"

#include "binning.h"

#include <raster/check.h>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>

#include <algorithm>
#include <cmath>

#if defined(__x86_64__)
#include <xmmintrin.h>
#endif

namespace raster {

namespace {

constexpr uint32_t kVerticesPerBlock = 4096;

// setupTriangle tests the pixel centres of bounding boxes up to this many pixels.
constexpr int64_t kCoverageTestPixels = 4;

// Clip planes as signed distances (inside >= 0) in homogeneous space.
enum Plane : uint32_t { kNear, kFar, kLeft, kRight, kBottom, kTop, kPlaneCount };

float planeDistance(const glm::vec4& c, uint32_t plane, float k) {
    switch (plane) {
    case kNear: // D = z/w >= -1 (camera.h)
        return c.z + c.w;
    case kFar: // D <= 0
        return -c.z;
    case kLeft:
        return c.x + k * c.w;
    case kRight:
        return k * c.w - c.x;
    case kBottom:
        return c.y + k * c.w;
    default:
        return k * c.w - c.y;
    }
}

// Bit p set: the vertex is outside plane p of the box |x|,|y| <= k*w, -w <= z (<= 0).
uint32_t outcode(const glm::vec4& c, float k, bool finite_far) {
    uint32_t code = 0;
    for (uint32_t p = 0; p < kPlaneCount; ++p) {
        if (p == kFar && !finite_far)
            continue;
        if (!(planeDistance(c, p, k) >= 0.0f))
            code |= 1u << p;
    }
    return code;
}

ShadeVertex lerp(const ShadeVertex& a, const ShadeVertex& b, float t) {
    ShadeVertex v;
    v.clip = a.clip + t * (b.clip - a.clip);
    v.world = a.world + t * (b.world - a.world);
    v.normal = a.normal + t * (b.normal - a.normal);
    v.uv = a.uv + t * (b.uv - a.uv);
    v.color = a.color + t * (b.color - a.color);
    return v;
}

// Sutherland-Hodgman against the planes in `planes`. The intersection is always computed from
// the inside vertex, so an edge shared by two triangles is cut at the same point both times.
int clipPolygon(ShadeVertex* poly, int n, ShadeVertex* scratch, uint32_t planes, float k) {
    for (uint32_t p = 0; p < kPlaneCount && n > 0; ++p) {
        if (!(planes & (1u << p)))
            continue;
        int m = 0;
        for (int i = 0; i < n; ++i) {
            const ShadeVertex& a = poly[i];
            const ShadeVertex& b = poly[(i + 1) % n];
            const float da = planeDistance(a.clip, p, k);
            const float db = planeDistance(b.clip, p, k);
            if (da >= 0.0f)
                scratch[m++] = a;
            if ((da >= 0.0f) != (db >= 0.0f))
                scratch[m++] = da >= 0.0f ? lerp(a, b, da / (da - db)) : lerp(b, a, db / (db - da));
        }
        std::copy(scratch, scratch + m, poly);
        n = m;
    }
    return n;
}

// std::lrint without the libm call GCC emits for it (it inlines lrint only under
// -fno-math-errno): on x86-64, glibc's lrintf is this one instruction, cvtss2si to a 64-bit
// register, rounding to nearest even in the default mode; the same value for every input.
long roundToLong(float x) {
#if defined(__x86_64__)
    return _mm_cvtss_si64(_mm_set_ss(x));
#else
    return std::lrint(x);
#endif
}

ScreenVertex toScreen(const glm::vec4& clip, float half_w, float half_h) {
    const float inv_w = 1.0f / clip.w;
    const float px = (clip.x * inv_w + 1.0f) * half_w;
    const float py = (1.0f - clip.y * inv_w) * half_h;
    return {int32_t(roundToLong(px * float(kSubpixelOne))),
            int32_t(roundToLong(py * float(kSubpixelOne))), clip.z * inv_w, inv_w};
}

int32_t ceilDiv(int64_t a, int64_t b) {
    return int32_t(a >= 0 ? (a + b - 1) / b : -((-a) / b));
}
int32_t floorDiv(int64_t a, int64_t b) {
    return int32_t(a >= 0 ? a / b : -((-a + b - 1) / b));
}

struct ChunkContext {
    const Scene& scene;
    const View& view;
    GeometryState& state;
    float half_w, half_h;
    bool finite_far;
};

// Snaps, culls and appends one triangle whose vertices are all inside the guard band.
void setupTriangle(const ChunkContext& ctx, GeometryChunk& chunk, const Draw& draw,
                   uint32_t triangle, float max_distance, const ScreenVertex s[3],
                   const uint32_t ref[3]) {
    int64_t area2 =
        int64_t(s[1].x - s[0].x) * (s[2].y - s[0].y) - int64_t(s[1].y - s[0].y) * (s[2].x - s[0].x);
    if (area2 == 0) {
        ++chunk.triangles_culled;
        return;
    }
    // y points down on screen, so counter-clockwise in NDC (glTF's front face) has area2 < 0.
    const bool front_facing = (area2 < 0) != draw.mirrored;
    if (!front_facing && !draw.double_sided) {
        ++chunk.triangles_culled;
        return;
    }
    int order[3] = {0, 1, 2};
    if (area2 < 0) {
        std::swap(order[1], order[2]);
        area2 = -area2;
    }
    SetupTri t;
    int32_t min_x = INT32_MAX, min_y = INT32_MAX, max_x = INT32_MIN, max_y = INT32_MIN;
    for (int i = 0; i < 3; ++i) {
        const ScreenVertex& sv = s[order[i]];
        t.x[i] = sv.x;
        t.y[i] = sv.y;
        t.z[i] = sv.z;
        t.inv_w[i] = sv.inv_w;
        t.vertex[i] = ref[order[i]];
        min_x = std::min(min_x, sv.x), max_x = std::max(max_x, sv.x);
        min_y = std::min(min_y, sv.y), max_y = std::max(max_y, sv.y);
    }
    // Pixel i is sampled at i + 1/2: the pixels whose centres lie inside the bounding box.
    const int32_t half = kSubpixelOne / 2;
    t.min_x = std::max(ceilDiv(int64_t(min_x) - half, kSubpixelOne), 0);
    t.min_y = std::max(ceilDiv(int64_t(min_y) - half, kSubpixelOne), 0);
    t.max_x = std::min(floorDiv(int64_t(max_x) - half, kSubpixelOne), int32_t(ctx.view.width) - 1);
    t.max_y = std::min(floorDiv(int64_t(max_y) - half, kSubpixelOne), int32_t(ctx.view.height) - 1);
    if (t.min_x > t.max_x || t.min_y > t.max_y) {
        ++chunk.triangles_culled;
        return;
    }
    // A small triangle (most of a dense mesh's) often covers no pixel centre although its box
    // holds some: the box's few centres are tested with the tile raster's exact edge functions
    // and fill rule, and a triangle that covers none is culled here, so binning and the raster
    // never see it (they would find no covered sample: the same image).
    if (int64_t(t.max_x - t.min_x + 1) * (t.max_y - t.min_y + 1) <= kCoverageTestPixels) {
        Edge edges[3];
        makeEdges(t, edges);
        bool covers = false;
        for (int32_t py = t.min_y; py <= t.max_y && !covers; ++py)
            for (int32_t px = t.min_x; px <= t.max_x && !covers; ++px)
                covers = rectMayOverlap(edges, px, py, px, py);
        if (!covers) {
            ++chunk.triangles_culled;
            return;
        }
    }
    t.area2 = area2;
    t.draw = uint32_t(&draw - ctx.state.draws.data());
    t.primitive_id = uint32_t(draw.first_triangle + triangle);
    t.max_distance = max_distance;
    t.front_facing = front_facing;
    chunk.tris.push_back(t);
}

void processTriangle(const ChunkContext& ctx, GeometryChunk& chunk, const Draw& draw,
                     uint32_t triangle) {
    const Primitive& prim = ctx.scene.meshes[draw.mesh].primitives[draw.primitive];
    uint32_t ref[3];
    const ShadeVertex* v[3];
    const VertexCodes* code[3];
    for (int i = 0; i < 3; ++i) {
        ref[i] = draw.first_vertex + prim.indices[size_t(triangle) * 3 + size_t(i)];
        v[i] = &ctx.state.vertices[ref[i]];
        code[i] = &ctx.state.codes[ref[i]];
    }
    ++chunk.triangles_in;
    // Outside one frustum plane entirely (the view frustum, k = 1): nothing to draw.
    if (!(code[0]->finite && code[1]->finite && code[2]->finite) ||
        (code[0]->frustum & code[1]->frustum & code[2]->frustum) != 0) {
        ++chunk.triangles_culled;
        return;
    }
    const float max_distance = std::max({v[0]->clip.w, v[1]->clip.w, v[2]->clip.w});
    const uint32_t crossing = uint32_t(code[0]->guard | code[1]->guard | code[2]->guard);
    if (crossing == 0) {
        const ScreenVertex s[3] = {ctx.state.screen[ref[0]], ctx.state.screen[ref[1]],
                                   ctx.state.screen[ref[2]]};
        setupTriangle(ctx, chunk, draw, triangle, max_distance, s, ref);
        return;
    }
    // True clipping: only against the planes this triangle crosses (near/far, guard band).
    ++chunk.triangles_clipped;
    ShadeVertex poly[3 + kPlaneCount], scratch[3 + kPlaneCount];
    for (int i = 0; i < 3; ++i)
        poly[i] = *v[i];
    const int n = clipPolygon(poly, 3, scratch, crossing, kGuardBand);
    if (n < 3) {
        ++chunk.triangles_culled;
        return;
    }
    const uint32_t base = uint32_t(chunk.clipped_vertices.size());
    chunk.clipped_vertices.insert(chunk.clipped_vertices.end(), poly, poly + n);
    for (int i = 1; i + 1 < n; ++i) {
        const uint32_t fan_ref[3] = {base | kClippedVertex, (base + uint32_t(i)) | kClippedVertex,
                                     (base + uint32_t(i) + 1) | kClippedVertex};
        const ScreenVertex fan[3] = {toScreen(poly[0].clip, ctx.half_w, ctx.half_h),
                                     toScreen(poly[i].clip, ctx.half_w, ctx.half_h),
                                     toScreen(poly[i + 1].clip, ctx.half_w, ctx.half_h)};
        setupTriangle(ctx, chunk, draw, triangle, max_distance, fan, fan_ref);
    }
}

} // namespace

void runGeometry(TaskPool& pool, const Scene& scene, const View& view, GeometryState& state,
                 bool keep_world) {
    FOCAL_CHECK(!keep_world || state.world_scene == &scene);
    if (!keep_world) {
        state.world_scene = nullptr; // until the vertex pass below has run
        // List the draws in submission order: instances, then their primitives.
        state.draws.clear();
        uint32_t vertex_count = 0;
        uint64_t triangle_count = 0;
        for (uint32_t i = 0; i < scene.instances.size(); ++i) {
            const Instance& inst = scene.instances[i];
            const Mesh& mesh = scene.meshes[inst.mesh];
            const glm::mat3 linear(inst.world);
            const bool mirrored = glm::determinant(linear) < 0.0f;
            const glm::mat3 normal_matrix = glm::transpose(glm::inverse(linear));
            for (uint32_t p = 0; p < mesh.primitives.size(); ++p) {
                const Primitive& prim = mesh.primitives[p];
                if (prim.indices.size() < 3)
                    continue;
                state.draws.push_back({i, inst.mesh, p, vertex_count, triangle_count, mirrored,
                                       materialOf(scene, prim).double_sided, normal_matrix});
                vertex_count += uint32_t(prim.positions.size());
                triangle_count += prim.indices.size() / 3;
            }
        }
        state.vertices.resize(vertex_count);
        state.world_w.resize(vertex_count);
        state.triangle_count = triangle_count;
    }
    const uint32_t vertex_count = uint32_t(state.vertices.size());
    const uint64_t triangle_count = state.triangle_count;
    state.eye = view.eye + view.lens_offset.x * view.right + view.lens_offset.y * view.up;

    // Vertex transform, clip codes and viewport transform, in blocks of vertices.
    state.codes.resize(vertex_count);
    state.screen.resize(vertex_count);
    const float half_w = 0.5f * float(view.width), half_h = 0.5f * float(view.height);
    const bool finite_far = view.zfar > 0.0f;
    const glm::mat4 view_proj = projectionMatrix(view) * viewMatrix(view);
    const uint32_t blocks = (vertex_count + kVerticesPerBlock - 1) / kVerticesPerBlock;
    pool.parallelFor(blocks, [&](uint32_t block, uint32_t) {
        const uint32_t begin = block * kVerticesPerBlock;
        const uint32_t end = std::min(begin + kVerticesPerBlock, vertex_count);
        auto it = std::upper_bound(state.draws.begin(), state.draws.end(), begin,
                                   [](uint32_t v, const Draw& d) { return v < d.first_vertex; });
        size_t d = size_t(it - state.draws.begin()) - 1;
        for (uint32_t vi = begin; vi < end; ++vi) {
            ShadeVertex& out = state.vertices[vi];
            if (keep_world) {
                out.clip = view_proj * glm::vec4(out.world, state.world_w[vi]);
            } else {
                while (d + 1 < state.draws.size() && state.draws[d + 1].first_vertex <= vi)
                    ++d;
                const Draw& draw = state.draws[d];
                const Instance& inst = scene.instances[draw.instance];
                const Primitive& prim = scene.meshes[draw.mesh].primitives[draw.primitive];
                const uint32_t local = vi - draw.first_vertex;
                const glm::vec4 world = inst.world * glm::vec4(prim.positions[local], 1.0f);
                out.world = glm::vec3(world);
                state.world_w[vi] = world.w;
                out.clip = view_proj * world;
                out.normal = prim.normals.empty() ? glm::vec3(0.0f)
                                                  : draw.normal_matrix * prim.normals[local];
                out.uv = prim.texcoords0.empty() ? glm::vec2(0.0f) : prim.texcoords0[local];
                out.color = prim.colors.empty() ? glm::vec4(1.0f) : prim.colors[local];
            }
            VertexCodes& code = state.codes[vi];
            const glm::vec4& c = out.clip;
            code.finite = std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.z) &&
                          std::isfinite(c.w);
            code.frustum = uint8_t(outcode(c, 1.0f, finite_far));
            code.guard = uint8_t(outcode(c, kGuardBand, finite_far));
            if (code.finite && code.guard == 0)
                state.screen[vi] = toScreen(c, half_w, half_h);
        }
    });
    state.world_scene = &scene;

    // Assemble, clip, cull and set up, in chunks of kTrianglesPerChunk source triangles.
    const uint32_t chunk_count =
        uint32_t((triangle_count + kTrianglesPerChunk - 1) / kTrianglesPerChunk);
    state.chunks.resize(chunk_count);
    const ChunkContext ctx{scene, view, state, half_w, half_h, finite_far};
    pool.parallelFor(chunk_count, [&](uint32_t c, uint32_t) {
        GeometryChunk& chunk = state.chunks[c];
        chunk.tris.clear();
        chunk.clipped_vertices.clear();
        chunk.triangles_in = chunk.triangles_culled = chunk.triangles_clipped = 0;
        const uint64_t begin = uint64_t(c) * kTrianglesPerChunk;
        const uint64_t end = std::min(begin + kTrianglesPerChunk, triangle_count);
        auto it = std::upper_bound(state.draws.begin(), state.draws.end(), begin,
                                   [](uint64_t t, const Draw& d) { return t < d.first_triangle; });
        size_t d = size_t(it - state.draws.begin()) - 1;
        for (uint64_t t = begin; t < end; ++t) {
            while (d + 1 < state.draws.size() && state.draws[d + 1].first_triangle <= t)
                ++d;
            const Draw& draw = state.draws[d];
            processTriangle(ctx, chunk, draw, uint32_t(t - draw.first_triangle));
        }
    });
}

} // namespace raster
