#include "mesh_builder.h"

#include <raster/check.h>

#include <glm/geometric.hpp>

#include <cmath>
#include <utility>
#include <vector>

namespace scenes::detail {
namespace {

uint32_t vertexCount(const raster::Primitive& prim) {
    return static_cast<uint32_t>(prim.positions.size());
}

void pushVertex(raster::Primitive& prim, glm::vec3 p, glm::vec3 n, glm::vec2 uv) {
    prim.positions.push_back(p);
    prim.normals.push_back(n);
    prim.texcoords0.push_back(uv);
    if (!prim.colors.empty())
        prim.colors.emplace_back(1.0f);
}

void pushTriangle(raster::Primitive& prim, uint32_t a, uint32_t b, uint32_t c) {
    prim.indices.push_back(a);
    prim.indices.push_back(b);
    prim.indices.push_back(c);
}

// Triangles for a (rows+1) x (cols+1) vertex lattice starting at `base`, row-major, where rows
// run "down" and columns "right" as seen from the front side.
void pushLattice(raster::Primitive& prim, uint32_t base, uint32_t rows, uint32_t cols) {
    const uint32_t stride = cols + 1;
    for (uint32_t i = 0; i < rows; ++i) {
        for (uint32_t j = 0; j < cols; ++j) {
            const uint32_t a = base + i * stride + j; // top left
            const uint32_t b = a + 1;                 // top right
            const uint32_t c = a + stride;            // bottom left
            const uint32_t d = c + 1;                 // bottom right
            pushTriangle(prim, a, c, d);
            pushTriangle(prim, a, d, b);
        }
    }
}

float fraction(uint32_t i, uint32_t n) {
    return static_cast<float>(i) / static_cast<float>(n);
}

} // namespace

float hashUnit(uint32_t key, uint32_t stream) {
    const uint32_t h = hash32(key ^ hash32(stream + 0x9e3779b9U));
    return static_cast<float>(h >> 8) * (1.0f / 16777216.0f);
}

float hashRange(uint32_t key, uint32_t stream, float lo, float hi) {
    return lo + (hi - lo) * hashUnit(key, stream);
}

float sinf64(float radians) {
    return static_cast<float>(std::sin(static_cast<double>(radians)));
}
float cosf64(float radians) {
    return static_cast<float>(std::cos(static_cast<double>(radians)));
}

void appendQuad(raster::Primitive& prim, glm::vec3 p0, glm::vec3 p1, glm::vec3 p2, glm::vec3 p3,
                glm::vec3 normal, glm::vec2 uv_max) {
    const uint32_t base = vertexCount(prim);
    pushVertex(prim, p0, normal, {0.0f, uv_max.y});
    pushVertex(prim, p1, normal, {uv_max.x, uv_max.y});
    pushVertex(prim, p2, normal, {uv_max.x, 0.0f});
    pushVertex(prim, p3, normal, {0.0f, 0.0f});
    pushTriangle(prim, base, base + 1, base + 2);
    pushTriangle(prim, base, base + 2, base + 3);
}

void appendGrid(raster::Primitive& prim, glm::vec3 origin, glm::vec3 edge_u, glm::vec3 edge_v,
                uint32_t nu, uint32_t nv, glm::vec2 uv_max) {
    FOCAL_CHECK(nu >= 1 && nv >= 1);
    const glm::vec3 normal = glm::normalize(glm::cross(edge_u, edge_v));
    const uint32_t base = vertexCount(prim);
    // Rows go from the far edge (origin + edge_v) down to origin, so the lattice's "down" and
    // "right" match the front view and the texture is upright.
    for (uint32_t i = 0; i <= nv; ++i) {
        const float t = fraction(nv - i, nv);
        for (uint32_t j = 0; j <= nu; ++j) {
            const float s = fraction(j, nu);
            const glm::vec3 p = origin + s * edge_u + t * edge_v;
            pushVertex(prim, p, normal, {s * uv_max.x, (1.0f - t) * uv_max.y});
        }
    }
    pushLattice(prim, base, nv, nu);
}

void appendBox(raster::Primitive& prim, glm::vec3 center, glm::vec3 half_extent, float uv_scale) {
    // The 8 corners are computed once so shared edges are bit-identical.
    const glm::vec3 lo = center - half_extent;
    const glm::vec3 hi = center + half_extent;
    auto corner = [&](int x, int y, int z) {
        return glm::vec3(x ? hi.x : lo.x, y ? hi.y : lo.y, z ? hi.z : lo.z);
    };
    const glm::vec2 uv{uv_scale, uv_scale};
    appendQuad(prim, corner(1, 0, 1), corner(1, 0, 0), corner(1, 1, 0), corner(1, 1, 1), {1, 0, 0},
               uv);
    appendQuad(prim, corner(0, 0, 0), corner(0, 0, 1), corner(0, 1, 1), corner(0, 1, 0), {-1, 0, 0},
               uv);
    appendQuad(prim, corner(0, 1, 1), corner(1, 1, 1), corner(1, 1, 0), corner(0, 1, 0), {0, 1, 0},
               uv);
    appendQuad(prim, corner(0, 0, 0), corner(1, 0, 0), corner(1, 0, 1), corner(0, 0, 1), {0, -1, 0},
               uv);
    appendQuad(prim, corner(0, 0, 1), corner(1, 0, 1), corner(1, 1, 1), corner(0, 1, 1), {0, 0, 1},
               uv);
    appendQuad(prim, corner(1, 0, 0), corner(0, 0, 0), corner(0, 1, 0), corner(1, 1, 0), {0, 0, -1},
               uv);
}

void appendSphere(raster::Primitive& prim, glm::vec3 center, float radius, uint32_t segments,
                  uint32_t rings) {
    FOCAL_CHECK(segments >= 3 && rings >= 2);
    const uint32_t base = vertexCount(prim);
    // Lattice rows 0..rings (north to south pole), columns 0..segments (the seam is duplicated
    // for uv; column `segments` reuses the angle of column 0, so positions match bit for bit).
    for (uint32_t i = 0; i <= rings; ++i) {
        const float theta = kPi * fraction(i, rings);
        float st = sinf64(theta);
        float ct = cosf64(theta);
        if (i == 0 || i == rings) {
            st = 0.0f;
            ct = i == 0 ? 1.0f : -1.0f;
        }
        for (uint32_t j = 0; j <= segments; ++j) {
            const float phi = 2.0f * kPi * fraction(j % segments, segments);
            const glm::vec3 n{st * sinf64(phi), ct, st * cosf64(phi)};
            pushVertex(prim, center + radius * n, n, {fraction(j, segments), fraction(i, rings)});
        }
    }
    // The quads touching a pole are triangles: keep only their non-degenerate half.
    const uint32_t stride = segments + 1;
    for (uint32_t i = 0; i < rings; ++i) {
        for (uint32_t j = 0; j < segments; ++j) {
            const uint32_t a = base + i * stride + j;
            const uint32_t b = a + 1;
            const uint32_t c = a + stride;
            const uint32_t d = c + 1;
            if (i + 1 < rings)
                pushTriangle(prim, a, c, d);
            if (i > 0)
                pushTriangle(prim, a, d, b);
        }
    }
}

void appendCylinder(raster::Primitive& prim, glm::vec3 a, glm::vec3 b, float ra, float rb,
                    uint32_t segments, bool caps) {
    FOCAL_CHECK(segments >= 3);
    const glm::vec3 axis_vec = b - a;
    const float length = glm::length(axis_vec);
    FOCAL_CHECK(length > 0.0f);
    const glm::vec3 axis = axis_vec / length;
    // Right-handed basis (u, v, axis): angle grows counter-clockwise seen from b.
    const glm::vec3 helper =
        std::fabs(axis.y) < 0.9f ? glm::vec3(0.0f, 1.0f, 0.0f) : glm::vec3(1.0f, 0.0f, 0.0f);
    const glm::vec3 u = glm::normalize(glm::cross(helper, axis));
    const glm::vec3 v = glm::cross(axis, u);
    const float slope = (ra - rb) / length; // the side normal tilts towards the narrow end

    std::vector<glm::vec3> radial(segments);
    for (uint32_t j = 0; j < segments; ++j) {
        const float phi = 2.0f * kPi * fraction(j, segments);
        radial[j] = cosf64(phi) * u + sinf64(phi) * v;
    }
    // Side: row 0 at b (top), row 1 at a; columns run with the angle (to the right seen from
    // outside).
    const uint32_t side = vertexCount(prim);
    for (uint32_t i = 0; i < 2; ++i) {
        const glm::vec3 end = i == 0 ? b : a;
        const float r = i == 0 ? rb : ra;
        for (uint32_t j = 0; j <= segments; ++j) {
            const glm::vec3 dir = radial[j % segments];
            pushVertex(prim, end + r * dir, glm::normalize(dir + slope * axis),
                       {fraction(j, segments), static_cast<float>(i)});
        }
    }
    pushLattice(prim, side, 1, segments);
    if (!caps)
        return;
    for (uint32_t i = 0; i < 2; ++i) {
        const glm::vec3 end = i == 0 ? b : a;
        const float r = i == 0 ? rb : ra;
        const glm::vec3 n = i == 0 ? axis : -axis;
        const uint32_t center = vertexCount(prim);
        pushVertex(prim, end, n, {0.5f, 0.5f});
        for (uint32_t j = 0; j < segments; ++j) {
            const glm::vec3 dir = radial[j];
            pushVertex(prim, end + r * dir, n,
                       {0.5f + 0.5f * glm::dot(dir, u), 0.5f - 0.5f * glm::dot(dir, v)});
        }
        for (uint32_t j = 0; j < segments; ++j) {
            const uint32_t p = center + 1 + j;
            const uint32_t q = center + 1 + (j + 1) % segments;
            if (i == 0)
                pushTriangle(prim, center, p, q);
            else
                pushTriangle(prim, center, q, p);
        }
    }
}

void appendTorus(raster::Primitive& prim, glm::vec3 center, float major_radius, float minor_radius,
                 uint32_t major_segments, uint32_t minor_segments) {
    FOCAL_CHECK(major_segments >= 3 && minor_segments >= 3);
    const uint32_t base = vertexCount(prim);
    // Rows: angle psi around the tube, growing downwards seen from outside; columns: angle phi
    // around +Y, growing to the right seen from outside (from +Z towards +X).
    for (uint32_t i = 0; i <= minor_segments; ++i) {
        const float psi = 2.0f * kPi * fraction(i % minor_segments, minor_segments);
        const float cp = cosf64(psi);
        const float sp = sinf64(psi);
        for (uint32_t j = 0; j <= major_segments; ++j) {
            const float phi = 2.0f * kPi * fraction(j % major_segments, major_segments);
            const glm::vec3 radial{sinf64(phi), 0.0f, cosf64(phi)};
            const glm::vec3 n = cp * radial - glm::vec3(0.0f, sp, 0.0f);
            const glm::vec3 p = center + major_radius * radial + minor_radius * n;
            pushVertex(prim, p, n, {fraction(j, major_segments), fraction(i, minor_segments)});
        }
    }
    pushLattice(prim, base, minor_segments, major_segments);
}

void appendGear(raster::Primitive& prim, uint32_t teeth, float root_radius, float tip_radius,
                float bore_radius, float thickness) {
    FOCAL_CHECK(teeth >= 3 && bore_radius > 0.0f && bore_radius < root_radius &&
                root_radius < tip_radius && thickness > 0.0f);
    // Per tooth four profile points: root, tip, tip, root at these fractions of its pitch; the
    // root arc runs from 0.8 to the next tooth's 0.
    constexpr float kProfile[4] = {0.0f, 0.3f, 0.5f, 0.8f};
    const uint32_t n = 4 * teeth;
    std::vector<glm::vec2> outer(n), inner(n);
    for (uint32_t i = 0; i < n; ++i) {
        const float angle =
            2.0f * kPi * (static_cast<float>(i / 4) + kProfile[i % 4]) / static_cast<float>(teeth);
        const glm::vec2 dir{cosf64(angle), sinf64(angle)};
        const bool tip = i % 4 == 1 || i % 4 == 2;
        outer[i] = (tip ? tip_radius : root_radius) * dir;
        inner[i] = bore_radius * dir;
    }
    const float h = 0.5f * thickness;
    auto at = [](glm::vec2 p, float z) { return glm::vec3(p, z); };
    for (uint32_t i = 0; i < n; ++i) {
        const uint32_t j = (i + 1) % n;
        // Faces: annular sectors, counter-clockwise seen from +Z (front) and -Z (back).
        appendQuad(prim, at(inner[i], h), at(outer[i], h), at(outer[j], h), at(inner[j], h),
                   {0.0f, 0.0f, 1.0f});
        appendQuad(prim, at(inner[j], -h), at(outer[j], -h), at(outer[i], -h), at(inner[i], -h),
                   {0.0f, 0.0f, -1.0f});
        // Outer wall (normal away from the axis) and bore wall (normal towards it).
        const glm::vec2 d = outer[j] - outer[i];
        const glm::vec3 out_n = glm::normalize(glm::vec3(d.y, -d.x, 0.0f));
        appendQuad(prim, at(outer[i], -h), at(outer[j], -h), at(outer[j], h), at(outer[i], h),
                   out_n);
        const glm::vec2 e = inner[j] - inner[i];
        const glm::vec3 in_n = glm::normalize(glm::vec3(-e.y, e.x, 0.0f));
        appendQuad(prim, at(inner[j], -h), at(inner[i], -h), at(inner[i], h), at(inner[j], h),
                   in_n);
    }
}

void appendPerforatedPlate(raster::Primitive& prim, glm::vec3 origin, uint32_t nx, uint32_t ny,
                           float pitch, float hole_radius) {
    FOCAL_CHECK(nx >= 1 && ny >= 1 && hole_radius > 0.0f && hole_radius < 0.5f * pitch);
    // 8 directions from a cell's centre, 45 degrees apart: on the cell's square they land on
    // its corners and the middles of its edges.
    constexpr uint32_t kSegments = 8;
    constexpr float kSquare[kSegments][2] = {{1, 0},  {1, 1},   {0, 1},  {-1, 1},
                                             {-1, 0}, {-1, -1}, {0, -1}, {1, -1}};
    const glm::vec3 normal{0.0f, 0.0f, 1.0f};
    for (uint32_t cy = 0; cy < ny; ++cy) {
        for (uint32_t cx = 0; cx < nx; ++cx) {
            // Edges from the grid lines, so neighbouring cells compute the same coordinates.
            const float x0 = origin.x + pitch * static_cast<float>(cx);
            const float x1 = origin.x + pitch * static_cast<float>(cx + 1);
            const float y0 = origin.y + pitch * static_cast<float>(cy);
            const float y1 = origin.y + pitch * static_cast<float>(cy + 1);
            const float xc = origin.x + pitch * (static_cast<float>(cx) + 0.5f);
            const float yc = origin.y + pitch * (static_cast<float>(cy) + 0.5f);
            auto onSquare = [&](uint32_t k) {
                const float ux = kSquare[k][0], uy = kSquare[k][1];
                const float x = ux > 0.0f ? x1 : ux < 0.0f ? x0 : xc;
                const float y = uy > 0.0f ? y1 : uy < 0.0f ? y0 : yc;
                return glm::vec3(x, y, origin.z);
            };
            auto onHole = [&](uint32_t k) {
                const float angle = 2.0f * kPi * fraction(k, kSegments);
                return glm::vec3(xc + hole_radius * cosf64(angle), yc + hole_radius * sinf64(angle),
                                 origin.z);
            };
            for (uint32_t k = 0; k < kSegments; ++k) {
                const uint32_t k1 = (k + 1) % kSegments;
                appendQuad(prim, onHole(k), onSquare(k), onSquare(k1), onHole(k1), normal);
            }
        }
    }
}

void appendLeaf(raster::Primitive& prim, glm::vec3 base, glm::vec3 along, glm::vec3 across,
                float size, glm::vec4 tint) {
    const uint32_t first = vertexCount(prim);
    const glm::vec3 half_w = 0.5f * size * across;
    const glm::vec3 len = size * along;
    appendQuad(prim, base - half_w, base + half_w, base + half_w + len, base - half_w + len,
               glm::normalize(glm::cross(across, along)));
    paintVertices(prim, first, tint);
}

void paintVertices(raster::Primitive& prim, uint32_t first_vertex, glm::vec4 color) {
    if (prim.colors.empty())
        prim.colors.assign(prim.positions.size(), glm::vec4(1.0f));
    for (size_t i = first_vertex; i < prim.colors.size(); ++i)
        prim.colors[i] = color;
}

int32_t addMaterial(raster::Scene& scene, raster::Material material) {
    scene.materials.push_back(std::move(material));
    return static_cast<int32_t>(scene.materials.size() - 1);
}

int32_t addImage(raster::Scene& scene, raster::Image image) {
    raster::buildMipChain(image);
    scene.images.push_back(std::move(image));
    return static_cast<int32_t>(scene.images.size() - 1);
}

int32_t addSampler(raster::Scene& scene, raster::Sampler sampler) {
    scene.samplers.push_back(sampler);
    return static_cast<int32_t>(scene.samplers.size() - 1);
}

int32_t addClampedSampler(raster::Scene& scene) {
    raster::Sampler clamp;
    clamp.wrap_s = raster::Wrap::ClampToEdge;
    clamp.wrap_t = raster::Wrap::ClampToEdge;
    return addSampler(scene, clamp);
}

void addSign(raster::Scene& scene, std::string mesh_name, raster::Image image, int32_t sampler,
             float roughness, glm::vec2 lo, glm::vec2 hi, float z) {
    const int32_t texture = addImage(scene, std::move(image));
    raster::Primitive quad;
    quad.material = addMaterial(scene, textured("sign", texture, sampler, roughness));
    appendQuad(quad, {lo.x, lo.y, z}, {hi.x, lo.y, z}, {hi.x, hi.y, z}, {lo.x, hi.y, z},
               {0.0f, 0.0f, 1.0f});
    addInstance(scene, addMesh(scene, std::move(mesh_name), std::move(quad)));
}

uint32_t addMesh(raster::Scene& scene, std::string name, raster::Primitive prim) {
    raster::Mesh mesh;
    mesh.name = std::move(name);
    mesh.primitives.push_back(std::move(prim));
    scene.meshes.push_back(std::move(mesh));
    return static_cast<uint32_t>(scene.meshes.size() - 1);
}

void addInstance(raster::Scene& scene, uint32_t mesh, const glm::mat4& world) {
    scene.instances.push_back({mesh, world});
}

raster::Material matte(std::string name, glm::vec3 color, float roughness) {
    raster::Material m;
    m.name = std::move(name);
    m.base_color_factor = glm::vec4(color, 1.0f);
    m.metallic_factor = 0.0f;
    m.roughness_factor = roughness;
    return m;
}

raster::Material textured(std::string name, int32_t image, int32_t sampler, float roughness) {
    raster::Material m = matte(std::move(name), glm::vec3(1.0f), roughness);
    m.base_color_texture.image = image;
    m.base_color_texture.sampler = sampler;
    return m;
}

raster::Material maskedLeaf(int32_t image, int32_t sampler) {
    raster::Material leaf = textured("leaf", image, sampler, 0.7f);
    leaf.alpha_mode = raster::AlphaMode::Mask;
    leaf.alpha_cutoff = 0.5f;
    leaf.double_sided = true;
    return leaf;
}

raster::Camera lookAtCamera(std::string name, glm::vec3 eye, glm::vec3 target, float yfov,
                            float znear, float zfar, glm::vec3 up) {
    const glm::vec3 forward = glm::normalize(target - eye);
    const glm::vec3 right = glm::normalize(glm::cross(forward, up));
    const glm::vec3 true_up = glm::cross(right, forward);
    raster::Camera camera;
    camera.name = std::move(name);
    camera.world = glm::mat4(glm::vec4(right, 0.0f), glm::vec4(true_up, 0.0f),
                             glm::vec4(-forward, 0.0f), glm::vec4(eye, 1.0f));
    camera.yfov = yfov;
    camera.znear = znear;
    camera.zfar = zfar;
    return camera;
}

float viewDepth(const raster::Camera& camera, glm::vec3 point) {
    const glm::vec3 eye{camera.world[3]};
    const glm::vec3 forward = -glm::vec3(camera.world[2]);
    return glm::dot(point - eye, forward);
}

raster::Light directionalLight(std::string name, glm::vec3 direction, glm::vec3 color,
                               float intensity) {
    raster::Light light;
    light.name = std::move(name);
    light.type = raster::Light::Type::Directional;
    light.direction = glm::normalize(direction);
    light.color = color;
    light.intensity = intensity;
    return light;
}

raster::Light pointLight(std::string name, glm::vec3 position, glm::vec3 color, float intensity,
                         float range) {
    raster::Light light;
    light.name = std::move(name);
    light.type = raster::Light::Type::Point;
    light.position = position;
    light.color = color;
    light.intensity = intensity;
    light.range = range;
    return light;
}

} // namespace scenes::detail
