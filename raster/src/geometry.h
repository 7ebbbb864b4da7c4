// Geometry stage: vertex transform, clipping in homogeneous space, culling, viewport transform
// and fixed-point snapping. Consumes a Scene and a View; produces screen-space triangles in
// submission order, split into fixed-size chunks that are processed in parallel and replayed in
// chunk order. All memory is owned by GeometryState and reused between frames.
//
// Fixed-point budget (docs/raster.md): positions are snapped to 1/256 pixel (8 sub-pixel bits).
// A guard band of kGuardBand viewport half-widths around the centre bounds every coordinate that
// reaches setup: with viewports up to kMaxViewport = 16384 pixels, |x|, |y| < 2.5 * 16384 px
// < 2^16 px, i.e. < 2^24 in fixed point. Edge deltas are < 2^25 and edge-function products
// < 2^50, so edge functions are evaluated in int64 exactly.
#pragma once

#include <raster/camera.h>
#include <raster/renderer.h>
#include <raster/scene.h>
#include <raster/task_pool.h>

#include <glm/mat3x3.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <cstdint>
#include <vector>

namespace raster {

constexpr int kSubpixelBits = 8;
constexpr int32_t kSubpixelOne = 1 << kSubpixelBits;
constexpr uint32_t kMaxViewport = 16384;
// Triangles are clipped only where they leave |ndc| <= kGuardBand (x and y).
constexpr float kGuardBand = 4.0f;
// Input triangles per geometry/binning chunk (Masked Occlusion Culling uses 1024).
constexpr uint32_t kTrianglesPerChunk = 2048;

// One (instance, primitive) pair: a draw call.
struct Draw {
    uint32_t instance = 0;
    uint32_t mesh = 0;
    uint32_t primitive = 0;
    uint32_t first_vertex = 0;     // into GeometryState::vertices
    uint64_t first_triangle = 0;   // submission index of its first triangle
    bool mirrored = false;         // negative determinant: winding flips
    bool double_sided = false;     // the material's: back faces are not culled
    glm::mat3 normal_matrix{1.0f}; // inverse transpose of the instance's upper 3x3
};

// A vertex after transform, with everything shading interpolates. Clipping makes new ones.
struct ShadeVertex {
    glm::vec4 clip;   // clip-space position
    glm::vec3 world;  // world-space position
    glm::vec3 normal; // world-space normal (not normalised after interpolation)
    glm::vec2 uv;
    glm::vec4 color;
};

// A vertex after the viewport transform: snapped position, stored depth and 1/w. Computed once
// per vertex for unclipped triangles, so triangles sharing a vertex share its snapped position.
struct ScreenVertex {
    int32_t x, y; // 24.8 fixed point pixels, y down
    float z;      // stored depth D
    float inv_w;
};

// Per-vertex clip codes: bit p set when outside plane p (near, far, left, right, bottom, top)
// of the view frustum (`frustum`) and of the guard band (`guard`); `finite` is false for
// NaN/Inf positions.
struct VertexCodes {
    uint8_t frustum;
    uint8_t guard;
    bool finite;
};

// A screen-space triangle ready for coverage. Vertices are ordered so that area2 > 0.
struct SetupTri {
    int32_t x[3], y[3];    // 24.8 fixed point pixels, y down
    int64_t area2;         // twice the signed area in fixed point^2, > 0
    float z[3];            // stored depth D per vertex (z/w)
    float inv_w[3];        // 1/w per vertex, for perspective-correct interpolation
    uint32_t vertex[3];    // ShadeVertex references: kClipped bit => chunk-local clipped vertex
    uint32_t draw;         // index into GeometryState::draws
    uint32_t primitive_id; // submission index of the source triangle over the whole frame
    float max_distance;    // largest view distance (w) of the source triangle's vertices
    int32_t min_x, min_y, max_x, max_y; // covered pixel bounds (inclusive), inside the viewport
    bool front_facing;                  // as seen by the viewer, for double-sided lighting
};

constexpr uint32_t kClippedVertex = 0x80000000u;

// Aligned to a cache line: neighbouring chunks are set up by different workers, and each
// triangle appended updates the chunk's vector ends and counts.
struct alignas(64) GeometryChunk {
    std::vector<SetupTri> tris;
    std::vector<ShadeVertex> clipped_vertices;
    uint64_t triangles_in = 0, triangles_culled = 0, triangles_clipped = 0;
};

struct GeometryState {
    std::vector<Draw> draws;
    std::vector<ShadeVertex> vertices; // transformed vertices of every draw
    std::vector<VertexCodes> codes;    // one per vertex
    std::vector<ScreenVertex> screen;  // one per vertex; valid where codes.guard == 0
    std::vector<GeometryChunk> chunks;
    glm::vec3 eye{0.0f}; // the eye shading uses (moved by the lens offset)
    // What does not depend on the view: the draws, and per vertex its world position, normal,
    // uv and colour (in `vertices`) and the world position's w (1 for an affine instance
    // transform of a finite position), from which a later view's clip position is computed
    // with the same bits. `world_scene` is the scene they were made for (nullptr while they
    // are being made).
    std::vector<float> world_w;
    uint64_t triangle_count = 0;
    const Scene* world_scene = nullptr;

    const ShadeVertex& vertex(const GeometryChunk& chunk, uint32_t ref) const {
        return (ref & kClippedVertex) ? chunk.clipped_vertices[ref & ~kClippedVertex]
                                      : vertices[ref];
    }
};

// Runs the geometry stage for one view; fills state.draws, state.vertices and state.chunks.
// With keep_world (state.world_scene == &scene, and the caller knows the scene is unchanged
// since), the view-independent part is kept and only the view's transform, clipping, culling
// and set-up are run: the same state, bit for bit, as without it.
void runGeometry(TaskPool& pool, const Scene& scene, const View& view, GeometryState& state,
                 bool keep_world = false);

} // namespace raster
