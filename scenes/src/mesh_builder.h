// Mesh and scene building blocks shared by the built-in scene generators (private to scenes/).
// Consumes plain parameters; appends triangles to a caller-owned raster::Primitive or entries to
// a caller-owned raster::Scene. Every closed shape is watertight (vertices on a shared edge are
// computed from the same expression, so they are bit-identical) and wound counter-clockwise seen
// from outside (glTF front face). Only sin/cos/sqrt are used, so the bytes match on any platform.
#pragma once

#include <raster/hash.h>
#include <raster/scene.h>

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include <cstdint>
#include <string>

namespace scenes::detail {

inline constexpr float kPi = 3.14159265358979f;

// Deterministic integer hash; no RNG state anywhere.
using raster::hash32;
// A float in [0, 1) that is a pure function of (key, stream): 24 hash bits, exactly representable.
float hashUnit(uint32_t key, uint32_t stream);
// hashUnit mapped to [lo, hi).
float hashRange(uint32_t key, uint32_t stream, float lo, float hi);

// sin/cos of an angle given in radians, evaluated in double and rounded once to float.
float sinf64(float radians);
float cosf64(float radians);

// --- Geometry: append to `prim` (positions, normals, texcoords0; colors only if already used).

// A quad p0 p1 p2 p3, counter-clockwise seen from the side `normal` points to. uv: p0 gets
// (0, uv_max.y), p1 (uv_max.x, uv_max.y), p2 (uv_max.x, 0), p3 (0, 0) (image row 0 is v = 0).
void appendQuad(raster::Primitive& prim, glm::vec3 p0, glm::vec3 p1, glm::vec3 p2, glm::vec3 p3,
                glm::vec3 normal, glm::vec2 uv_max = {1.0f, 1.0f});

// A flat grid of nu x nv cells spanning origin + [0,1]*edge_u + [0,1]*edge_v, facing
// cross(edge_u, edge_v); uv runs over [0, uv_max] (v flipped so the image is upright).
void appendGrid(raster::Primitive& prim, glm::vec3 origin, glm::vec3 edge_u, glm::vec3 edge_v,
                uint32_t nu, uint32_t nv, glm::vec2 uv_max = {1.0f, 1.0f});

// An axis-aligned box (closed, flat-shaded: 24 vertices, 12 triangles); each face gets uv
// [0, uv_scale].
void appendBox(raster::Primitive& prim, glm::vec3 center, glm::vec3 half_extent,
               float uv_scale = 1.0f);

// A UV sphere (closed): `segments` around +Y, `rings` from pole to pole (>= 3 and >= 2).
// u = longitude / 2pi (starting at +Z, towards +X), v = 0 at the north pole.
void appendSphere(raster::Primitive& prim, glm::vec3 center, float radius, uint32_t segments,
                  uint32_t rings);

// A tapered cylinder (cone frustum) from `a` (radius ra) to `b` (radius rb); closed when `caps`.
void appendCylinder(raster::Primitive& prim, glm::vec3 a, glm::vec3 b, float ra, float rb,
                    uint32_t segments, bool caps);

// A torus around +Y through `center` (closed): major radius R, minor radius r.
void appendTorus(raster::Primitive& prim, glm::vec3 center, float major_radius, float minor_radius,
                 uint32_t major_segments, uint32_t minor_segments);

// A flat gear of `teeth` trapezoidal teeth around a round bore, centred on the origin in the xy
// plane (front face +Z, thickness along Z; place it with an instance matrix). Flat-shaded.
void appendGear(raster::Primitive& prim, uint32_t teeth, float root_radius, float tip_radius,
                float bore_radius, float thickness);

// A zero-thickness sheet in the xy plane (z = 0, facing +Z; give it a double-sided material) of
// nx x ny square cells of side `pitch`, from `origin` (lower-left corner) towards +X and +Y, each
// with a round hole of `hole_radius` (< pitch / 2) drawn as an octagon. Cells share their edges
// bit for bit, so the sheet is watertight.
void appendPerforatedPlate(raster::Primitive& prim, glm::vec3 origin, uint32_t nx, uint32_t ny,
                           float pitch, float hole_radius);

// A leaf quad: stem at `base`, blade of length `size` along `along`, half as wide along
// `across`, facing cross(across, along).
void appendLeaf(raster::Primitive& prim, glm::vec3 base, glm::vec3 along, glm::vec3 across,
                float size, glm::vec4 tint);

// Fills prim.colors with `color` for every vertex from `first_vertex` on (creating the array,
// white-filled, if it was empty).
void paintVertices(raster::Primitive& prim, uint32_t first_vertex, glm::vec4 color);

// --- Scene entries. Each returns the index of what it added.

int32_t addMaterial(raster::Scene& scene, raster::Material material);
// Adds the image after building its mip chain.
int32_t addImage(raster::Scene& scene, raster::Image image);
int32_t addSampler(raster::Scene& scene, raster::Sampler sampler);
// A sampler with the default (linear, mipmapped) filters that clamps s and t to the edge.
int32_t addClampedSampler(raster::Scene& scene);
// A one-primitive mesh; `prim.material` must already be set.
uint32_t addMesh(raster::Scene& scene, std::string name, raster::Primitive prim);
void addInstance(raster::Scene& scene, uint32_t mesh, const glm::mat4& world = glm::mat4(1.0f));
// A sign facing +z: `image` on the rectangle [lo, hi] (x, y) at depth z with a "sign" material
// (`sampler`, `roughness`), added as image, material, mesh `mesh_name` and one instance.
void addSign(raster::Scene& scene, std::string mesh_name, raster::Image image, int32_t sampler,
             float roughness, glm::vec2 lo, glm::vec2 hi, float z);

// Common materials (linear colours; metallic 0 unless said otherwise).
raster::Material matte(std::string name, glm::vec3 color, float roughness = 0.8f);
raster::Material textured(std::string name, int32_t image, int32_t sampler, float roughness = 0.8f);
// A leaf cut out of `image` by its alpha (MASK, cutoff 0.5), double-sided, roughness 0.7.
raster::Material maskedLeaf(int32_t image, int32_t sampler);

// A glTF camera at `eye` looking at `target` (its world matrix maps -Z to the view axis).
raster::Camera lookAtCamera(std::string name, glm::vec3 eye, glm::vec3 target, float yfov,
                            float znear, float zfar, glm::vec3 up = {0.0f, 1.0f, 0.0f});
// Distance along the camera's view axis to `point` (what LensHint::focus_distance measures).
float viewDepth(const raster::Camera& camera, glm::vec3 point);

raster::Light directionalLight(std::string name, glm::vec3 direction, glm::vec3 color,
                               float intensity);
raster::Light pointLight(std::string name, glm::vec3 position, glm::vec3 color, float intensity,
                         float range = 0.0f);

} // namespace scenes::detail
