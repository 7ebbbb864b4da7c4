// Tests for scenes/include/scenes/builtin.h: every built-in scene builds, is well formed
// (indices in range, no NaN, valid materials/images, camera and lens), is deterministic, and
// has the property its DOF test case relies on. Also checks the private mesh builders for
// watertightness and outward winding.
#include "scenes/src/mesh_builder.h"
#include "scenes/src/procedural_texture.h"

#include <raster/scene.h>
#include <scenes/builtin.h>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <map>
#include <set>
#include <string>
#include <tuple>
#include <vector>

namespace {

using raster::Scene;

bool finite(float v) {
    return std::isfinite(v);
}
bool finite(glm::vec2 v) {
    return finite(v.x) && finite(v.y);
}
bool finite(glm::vec3 v) {
    return finite(v.x) && finite(v.y) && finite(v.z);
}
bool finite(glm::vec4 v) {
    return finite(glm::vec3(v)) && finite(v.w);
}

Scene build(std::string_view name) {
    raster::Result<Scene> result = scenes::makeBuiltinScene(name);
    EXPECT_TRUE(result.ok()) << result.status().message();
    return result.ok() ? std::move(result.value()) : Scene{};
}

uint64_t countTriangles(const Scene& scene) {
    uint64_t n = 0;
    for (const raster::Instance& inst : scene.instances)
        for (const raster::Primitive& prim : scene.meshes[inst.mesh].primitives)
            n += prim.indices.size() / 3;
    return n;
}

const raster::Mesh* findMesh(const Scene& scene, std::string_view name, uint32_t* index = nullptr) {
    for (size_t i = 0; i < scene.meshes.size(); ++i) {
        if (scene.meshes[i].name == name) {
            if (index)
                *index = static_cast<uint32_t>(i);
            return &scene.meshes[i];
        }
    }
    return nullptr;
}

// Min and max view depth of every vertex of every instance of mesh `name`.
std::pair<float, float> depthRange(const Scene& scene, std::string_view name) {
    uint32_t mesh = 0;
    EXPECT_NE(findMesh(scene, name, &mesh), nullptr) << name;
    float lo = INFINITY, hi = -INFINITY;
    for (const raster::Instance& inst : scene.instances) {
        if (inst.mesh != mesh)
            continue;
        for (const raster::Primitive& prim : scene.meshes[mesh].primitives) {
            for (glm::vec3 p : prim.positions) {
                const float d = scenes::detail::viewDepth(
                    scene.cameras[0], glm::vec3(inst.world * glm::vec4(p, 1.0f)));
                lo = std::min(lo, d);
                hi = std::max(hi, d);
            }
        }
    }
    return {lo, hi};
}

// FNV-1a over the bytes of a vector.
template <class T> void hashBytes(uint64_t& h, const std::vector<T>& v) {
    const auto* bytes = reinterpret_cast<const unsigned char*>(v.data());
    for (size_t i = 0; i < v.size() * sizeof(T); ++i) {
        h ^= bytes[i];
        h *= 1099511628211ull;
    }
}

uint64_t sceneHash(const Scene& scene) {
    uint64_t h = 14695981039346656037ull;
    for (const raster::Mesh& mesh : scene.meshes) {
        for (const raster::Primitive& prim : mesh.primitives) {
            hashBytes(h, prim.positions);
            hashBytes(h, prim.normals);
            hashBytes(h, prim.texcoords0);
            hashBytes(h, prim.colors);
            hashBytes(h, prim.indices);
        }
    }
    for (const raster::Image& image : scene.images)
        hashBytes(h, image.levels[0].rgba8);
    std::vector<float> cams;
    for (const raster::Camera& c : scene.cameras)
        for (int i = 0; i < 4; ++i)
            for (int j = 0; j < 4; ++j)
                cams.push_back(c.world[i][j]);
    cams.push_back(scene.lens->aperture_radius);
    cams.push_back(scene.lens->focus_distance);
    hashBytes(h, cams);
    return h;
}

TEST(BuiltinScenes, ListHasFixedOrderAndDescriptions) {
    const std::vector<std::string> expected = {
        "demo",  "railing",    "branches",    "bokeh",       "foliage",   "glass",
        "dense", "reflective", "nearsurface", "nearfoliage", "perforated"};
    std::span<const scenes::BuiltinInfo> list = scenes::builtinScenes();
    ASSERT_EQ(list.size(), expected.size());
    for (size_t i = 0; i < list.size(); ++i) {
        EXPECT_EQ(list[i].name, expected[i]);
        EXPECT_FALSE(list[i].exercises.empty());
    }
}

TEST(BuiltinScenes, UnknownNameIsAnErrorListingValidNames) {
    raster::Result<Scene> result = scenes::makeBuiltinScene("no_such_scene");
    ASSERT_FALSE(result.ok());
    const std::string& message = result.status().message();
    EXPECT_NE(message.find("no_such_scene"), std::string::npos) << message;
    for (const scenes::BuiltinInfo& info : scenes::builtinScenes())
        EXPECT_NE(message.find(info.name), std::string::npos) << message;
}

TEST(BuiltinScenes, PrefixIsAcceptedAndSourceIsSet) {
    raster::Result<Scene> result = scenes::makeBuiltinScene("builtin:railing");
    ASSERT_TRUE(result.ok()) << result.status().message();
    EXPECT_EQ(result->source, "builtin:railing");
}

class EveryBuiltinScene : public ::testing::TestWithParam<std::string> {};

TEST_P(EveryBuiltinScene, IsWellFormed) {
    const Scene scene = build(GetParam());
    EXPECT_EQ(scene.source, "builtin:" + GetParam());
    EXPECT_TRUE(finite(scene.background));
    ASSERT_FALSE(scene.meshes.empty());
    ASSERT_FALSE(scene.instances.empty());

    // Camera: orthonormal frame, sane projection.
    ASSERT_FALSE(scene.cameras.empty());
    const raster::Camera& cam = scene.cameras[0];
    for (int i = 0; i < 3; ++i) {
        EXPECT_NEAR(glm::length(glm::vec3(cam.world[i])), 1.0f, 1e-5f);
        for (int j = i + 1; j < 3; ++j)
            EXPECT_NEAR(glm::dot(glm::vec3(cam.world[i]), glm::vec3(cam.world[j])), 0.0f, 1e-5f);
    }
    EXPECT_GT(cam.yfov, 0.1f);
    EXPECT_LT(cam.yfov, 2.5f);
    EXPECT_GT(cam.znear, 0.0f);
    EXPECT_TRUE(cam.zfar == 0.0f || cam.zfar > cam.znear);

    // Lens hint: a real aperture, focus beyond the near plane.
    ASSERT_TRUE(scene.lens.has_value());
    EXPECT_GT(scene.lens->aperture_radius, 0.0f);
    EXPECT_LT(scene.lens->aperture_radius, 0.5f);
    EXPECT_GT(scene.lens->focus_distance, cam.znear);

    // Images: 8-bit RGBA, <= 1024^2, full mip chain.
    for (const raster::Image& image : scene.images) {
        ASSERT_FALSE(image.levels.empty()) << image.name;
        const raster::MipLevel& top = image.levels[0];
        EXPECT_GE(top.width, 1u);
        EXPECT_LE(top.width, 1024u);
        EXPECT_LE(top.height, 1024u);
        EXPECT_EQ(top.rgba8.size(), size_t{top.width} * top.height * 4) << image.name;
        EXPECT_EQ(image.levels.back().width, 1u) << image.name << ": mip chain not built";
        EXPECT_EQ(image.levels.back().height, 1u) << image.name << ": mip chain not built";
    }

    // Materials: indices in range, factors in range.
    const auto check_ref = [&](const raster::TextureRef& ref, const std::string& what) {
        EXPECT_GE(ref.image, -1) << what;
        EXPECT_LT(ref.image, static_cast<int32_t>(scene.images.size())) << what;
        EXPECT_GE(ref.sampler, -1) << what;
        EXPECT_LT(ref.sampler, static_cast<int32_t>(scene.samplers.size())) << what;
    };
    for (const raster::Material& m : scene.materials) {
        check_ref(m.base_color_texture, m.name);
        check_ref(m.emissive_texture, m.name);
        EXPECT_TRUE(finite(m.base_color_factor)) << m.name;
        EXPECT_TRUE(finite(m.emissive_factor)) << m.name;
        for (int c = 0; c < 4; ++c) {
            EXPECT_GE(m.base_color_factor[c], 0.0f) << m.name;
            EXPECT_LE(m.base_color_factor[c], 1.0f) << m.name;
        }
        EXPECT_GE(m.metallic_factor, 0.0f);
        EXPECT_LE(m.metallic_factor, 1.0f);
        EXPECT_GE(m.roughness_factor, 0.0f);
        EXPECT_LE(m.roughness_factor, 1.0f);
        EXPECT_GE(m.alpha_cutoff, 0.0f);
        EXPECT_LE(m.alpha_cutoff, 1.0f);
    }

    // Geometry: attributes sized, finite, indices in range, normals unit and agreeing with the
    // counter-clockwise winding (front face = outside, as glTF).
    for (const raster::Mesh& mesh : scene.meshes) {
        ASSERT_FALSE(mesh.primitives.empty()) << mesh.name;
        for (const raster::Primitive& prim : mesh.primitives) {
            const size_t n = prim.positions.size();
            ASSERT_GT(n, 0u) << mesh.name;
            EXPECT_TRUE(prim.normals.empty() || prim.normals.size() == n) << mesh.name;
            EXPECT_TRUE(prim.texcoords0.empty() || prim.texcoords0.size() == n) << mesh.name;
            EXPECT_TRUE(prim.colors.empty() || prim.colors.size() == n) << mesh.name;
            ASSERT_EQ(prim.indices.size() % 3, 0u) << mesh.name;
            EXPECT_GE(prim.material, -1);
            EXPECT_LT(prim.material, static_cast<int32_t>(scene.materials.size())) << mesh.name;
            size_t bad = 0;
            for (size_t i = 0; i < n; ++i) {
                bad += !finite(prim.positions[i]);
                if (!prim.normals.empty())
                    bad += !finite(prim.normals[i]) ||
                           std::fabs(glm::length(prim.normals[i]) - 1.0f) > 1e-3f;
                if (!prim.texcoords0.empty())
                    bad += !finite(prim.texcoords0[i]);
                if (!prim.colors.empty())
                    bad += !finite(prim.colors[i]);
            }
            EXPECT_EQ(bad, 0u) << mesh.name << ": non-finite or non-unit attributes";
            size_t out_of_range = 0, flipped = 0;
            for (size_t t = 0; t < prim.indices.size(); t += 3) {
                const uint32_t a = prim.indices[t], b = prim.indices[t + 1],
                               c = prim.indices[t + 2];
                if (a >= n || b >= n || c >= n) {
                    ++out_of_range;
                    continue;
                }
                if (prim.normals.empty())
                    continue;
                const glm::vec3 face = glm::cross(prim.positions[b] - prim.positions[a],
                                                  prim.positions[c] - prim.positions[a]);
                const glm::vec3 vn = prim.normals[a] + prim.normals[b] + prim.normals[c];
                if (glm::dot(face, vn) < 0.0f)
                    ++flipped;
            }
            EXPECT_EQ(out_of_range, 0u) << mesh.name;
            EXPECT_EQ(flipped, 0u) << mesh.name << ": winding disagrees with the normals";
        }
    }
    for (const raster::Instance& inst : scene.instances) {
        EXPECT_LT(inst.mesh, scene.meshes.size());
        for (int i = 0; i < 4; ++i)
            EXPECT_TRUE(finite(inst.world[i]));
    }

    // Lights: finite and positive.
    for (const raster::Light& light : scene.lights) {
        EXPECT_TRUE(finite(light.color) && finite(light.position)) << light.name;
        EXPECT_GT(light.intensity, 0.0f) << light.name;
        if (light.type != raster::Light::Type::Point) {
            EXPECT_NEAR(glm::length(light.direction), 1.0f, 1e-4f) << light.name;
        }
    }

    // Sizes: every scene but dense stays small so tests are fast.
    if (GetParam() != "dense") {
        EXPECT_LT(countTriangles(scene), 200000u);
    }

    // The far plane encloses the scene, and the camera looks at it: the point in focus on the
    // view axis lies inside the scene's bounds.
    glm::vec3 lo{INFINITY}, hi{-INFINITY};
    for (const raster::Instance& inst : scene.instances)
        for (const raster::Primitive& prim : scene.meshes[inst.mesh].primitives)
            for (glm::vec3 p : prim.positions) {
                const glm::vec3 w{inst.world * glm::vec4(p, 1.0f)};
                lo = glm::min(lo, w);
                hi = glm::max(hi, w);
            }
    const glm::vec3 eye{cam.world[3]};
    if (cam.zfar > 0.0f) {
        for (int corner = 0; corner < 8; ++corner) {
            const glm::vec3 p{corner & 1 ? hi.x : lo.x, corner & 2 ? hi.y : lo.y,
                              corner & 4 ? hi.z : lo.z};
            EXPECT_LT(scenes::detail::viewDepth(cam, p), cam.zfar);
        }
    }
    const glm::vec3 focus_point = eye - glm::vec3(cam.world[2]) * scene.lens->focus_distance;
    EXPECT_TRUE(glm::all(glm::greaterThanEqual(focus_point, lo)) &&
                glm::all(glm::lessThanEqual(focus_point, hi)));
}

TEST_P(EveryBuiltinScene, IsDeterministic) {
    const Scene a = build(GetParam());
    const Scene b = build(GetParam());
    EXPECT_EQ(sceneHash(a), sceneHash(b));
    EXPECT_EQ(countTriangles(a), countTriangles(b));
}

std::vector<std::string> allNames() {
    std::vector<std::string> names;
    for (const scenes::BuiltinInfo& info : scenes::builtinScenes())
        names.emplace_back(info.name);
    return names;
}

INSTANTIATE_TEST_SUITE_P(BuiltinScenes, EveryBuiltinScene, ::testing::ValuesIn(allNames()),
                         [](const ::testing::TestParamInfo<std::string>& param) {
                             return param.param;
                         });

TEST(BuiltinScenes, DemoHasTexturesEmitterAndNearRailing) {
    const Scene scene = build("demo");
    bool textured = false, emissive = false;
    for (const raster::Material& m : scene.materials) {
        textured |= m.base_color_texture.image >= 0;
        emissive |=
            std::max({m.emissive_factor.x, m.emissive_factor.y, m.emissive_factor.z}) > 1.0f;
    }
    EXPECT_TRUE(textured);
    EXPECT_TRUE(emissive);
    const auto [near, far] = depthRange(scene, "railing");
    EXPECT_LT(far, 0.5f * scene.lens->focus_distance);
}

TEST(BuiltinScenes, RailingBarsAreNearAndTextIsAtTheFocusDistance) {
    const Scene scene = build("railing");
    const float focus = scene.lens->focus_distance;
    const auto [bars_near, bars_far] = depthRange(scene, "bars");
    EXPECT_GT(bars_near, scene.cameras[0].znear);
    EXPECT_LT(bars_far, 0.25f * focus);
    const auto [text_near, text_far] = depthRange(scene, "text");
    EXPECT_NEAR(text_near, focus, 1e-3f * focus);
    EXPECT_NEAR(text_far, focus, 1e-3f * focus);
    // The bars are thinner than their blur: |C(d)| (docs/dof/lens.md) exceeds the bar width in px.
    const float f_px = 300.0f / std::tan(0.5f * scene.cameras[0].yfov);
    const float coc = scene.lens->aperture_radius * f_px * (1.0f / bars_near - 1.0f / focus);
    EXPECT_GT(coc, 0.012f * f_px / bars_near);
}

TEST(BuiltinScenes, BranchesStraddleTheFocalPlaneAndCrossInTheImage) {
    const Scene scene = build("branches");
    const float focus = scene.lens->focus_distance;
    const auto [front_near, front_far] = depthRange(scene, "branch_front");
    const auto [back_near, back_far] = depthRange(scene, "branch_back");
    EXPECT_LT(front_far, focus);
    EXPECT_GT(back_near, focus);
    // The main axes (first two ring centres of the first cylinder) cross in image space: their
    // projections are segments on opposite diagonals through the image centre.
    const auto project = [&](glm::vec3 p) {
        const float d = scenes::detail::viewDepth(scene.cameras[0], p);
        return glm::vec2(glm::dot(p, glm::vec3(scene.cameras[0].world[0])),
                         glm::dot(p, glm::vec3(scene.cameras[0].world[1]))) /
               d;
    };
    const glm::vec3 fa = findMesh(scene, "branch_front")->primitives[0].positions.front();
    const glm::vec3 ba = findMesh(scene, "branch_back")->primitives[0].positions.front();
    const glm::vec2 f = project(fa), b = project(ba);
    // Front branch rises to the right, back branch falls to the right: their slopes differ in
    // sign, so the two lines through the image centre cross there.
    EXPECT_LT(f.x * f.y * (b.x * b.y), 0.0f);
}

TEST(BuiltinScenes, BokehEmittersAreBrightAndFarBehindFocus) {
    const Scene scene = build("bokeh");
    const float focus = scene.lens->focus_distance;
    size_t emitters = 0;
    for (const raster::Instance& inst : scene.instances) {
        for (const raster::Primitive& prim : scene.meshes[inst.mesh].primitives) {
            const raster::Material& m = scene.materials[static_cast<size_t>(prim.material)];
            if (std::max({m.emissive_factor.x, m.emissive_factor.y, m.emissive_factor.z}) < 10.0f)
                continue;
            ++emitters;
            const float d = scenes::detail::viewDepth(scene.cameras[0], glm::vec3(inst.world[3]));
            EXPECT_GT(d, 2.0f * focus);
        }
    }
    EXPECT_GE(emitters, 50u);
}

TEST(BuiltinScenes, FoliageUsesManyMaskedDoubleSidedLeaves) {
    const Scene scene = build("foliage");
    const raster::Mesh* leaves = findMesh(scene, "leaves");
    ASSERT_NE(leaves, nullptr);
    const raster::Primitive& prim = leaves->primitives[0];
    const raster::Material& m = scene.materials[static_cast<size_t>(prim.material)];
    EXPECT_EQ(m.alpha_mode, raster::AlphaMode::Mask);
    EXPECT_TRUE(m.double_sided);
    EXPECT_GE(prim.indices.size() / 6, 5000u);
    ASSERT_GE(m.base_color_texture.image, 0);
    const raster::Image& image = scene.images[static_cast<size_t>(m.base_color_texture.image)];
    size_t transparent = 0, opaque = 0;
    for (size_t i = 3; i < image.levels[0].rgba8.size(); i += 4) {
        transparent += image.levels[0].rgba8[i] == 0;
        opaque += image.levels[0].rgba8[i] == 255;
    }
    EXPECT_GT(transparent, image.levels[0].rgba8.size() / 4 / 5);
    EXPECT_GT(opaque, image.levels[0].rgba8.size() / 4 / 5);
}

TEST(BuiltinScenes, GlassPanesBlendAfterTheOpaqueGeometry) {
    const Scene scene = build("glass");
    size_t panes = 0;
    bool seen_blend = false;
    for (const raster::Instance& inst : scene.instances) {
        const raster::Primitive& prim = scene.meshes[inst.mesh].primitives[0];
        const raster::Material& m = scene.materials[static_cast<size_t>(prim.material)];
        if (m.alpha_mode == raster::AlphaMode::Blend) {
            seen_blend = true;
            ++panes;
            EXPECT_GE(m.base_color_factor.w, 0.3f);
            EXPECT_LE(m.base_color_factor.w, 0.5f);
            EXPECT_TRUE(m.double_sided);
        } else {
            EXPECT_FALSE(seen_blend) << "opaque instance after a BLEND one";
        }
    }
    EXPECT_GE(panes, 3u);
}

TEST(BuiltinScenes, DenseHasAtLeastAMillionTriangles) {
    const Scene scene = build("dense");
    EXPECT_GE(countTriangles(scene), 1000000u);
}

TEST(BuiltinScenes, ReflectiveHasShinyMetals) {
    const Scene scene = build("reflective");
    size_t shiny = 0;
    for (const raster::Material& m : scene.materials)
        shiny += m.metallic_factor == 1.0f && m.roughness_factor <= 0.2f;
    EXPECT_GE(shiny, 3u);
}

// --- Mesh builders: closed shapes are watertight and wound outwards.

// Welds vertices by exact position and checks every edge is used once in each direction.
// Returns the signed volume (positive when the winding faces outwards).
double checkClosed(const raster::Primitive& prim) {
    std::map<std::tuple<float, float, float>, uint32_t> weld;
    std::vector<uint32_t> id(prim.positions.size());
    for (size_t i = 0; i < prim.positions.size(); ++i) {
        const glm::vec3 p = prim.positions[i];
        id[i] = weld.emplace(std::make_tuple(p.x, p.y, p.z), static_cast<uint32_t>(weld.size()))
                    .first->second;
    }
    std::map<std::pair<uint32_t, uint32_t>, int> directed;
    double volume = 0.0;
    for (size_t t = 0; t < prim.indices.size(); t += 3) {
        const uint32_t v[3] = {id[prim.indices[t]], id[prim.indices[t + 1]],
                               id[prim.indices[t + 2]]};
        EXPECT_TRUE(v[0] != v[1] && v[1] != v[2] && v[0] != v[2])
            << "degenerate triangle " << t / 3;
        for (int e = 0; e < 3; ++e)
            ++directed[{v[e], v[(e + 1) % 3]}];
        const glm::dvec3 a{prim.positions[prim.indices[t]]}, b{prim.positions[prim.indices[t + 1]]},
            c{prim.positions[prim.indices[t + 2]]};
        volume += glm::dot(a, glm::cross(b, c)) / 6.0;
    }
    size_t bad = 0;
    for (const auto& [edge, count] : directed) {
        const auto it = directed.find({edge.second, edge.first});
        bad += count != 1 || it == directed.end() || it->second != 1;
    }
    EXPECT_EQ(bad, 0u) << "edges not shared by exactly two opposite half-edges";
    return volume;
}

TEST(MeshBuilder, ClosedShapesAreWatertightAndOutward) {
    using namespace scenes::detail;
    const double pi = 3.14159265358979;
    {
        raster::Primitive p;
        appendBox(p, {0.3f, -1.0f, 2.0f}, {0.5f, 1.0f, 1.5f});
        EXPECT_NEAR(checkClosed(p), 1.0 * 2.0 * 3.0, 1e-5);
    }
    {
        raster::Primitive p;
        appendSphere(p, {1.0f, 2.0f, 3.0f}, 0.5f, 64, 32);
        EXPECT_NEAR(checkClosed(p), 4.0 / 3.0 * pi * 0.125, 0.01 * 4.0 / 3.0 * pi * 0.125);
    }
    {
        raster::Primitive p;
        appendCylinder(p, {0.0f, 0.0f, 0.0f}, {0.3f, 1.0f, -0.2f}, 0.2f, 0.2f, 64, true);
        const double h = std::sqrt(0.09 + 1.0 + 0.04);
        EXPECT_NEAR(checkClosed(p), pi * 0.04 * h, 0.01 * pi * 0.04 * h);
    }
    {
        raster::Primitive p;
        appendCylinder(p, {0.0f, 1.0f, 0.0f}, {0.0f, -1.0f, 0.0f}, 0.3f, 0.1f, 48, true);
        EXPECT_GT(checkClosed(p), 0.0);
    }
    {
        raster::Primitive p;
        appendTorus(p, {0.0f, 0.0f, 0.0f}, 1.0f, 0.25f, 96, 48);
        const double v = 2.0 * pi * pi * 1.0 * 0.0625;
        EXPECT_NEAR(checkClosed(p), v, 0.01 * v);
    }
}

TEST(MeshBuilder, HashIsAPureFunctionInUnitRange) {
    using namespace scenes::detail;
    EXPECT_EQ(hash32(12345u), hash32(12345u));
    EXPECT_NE(hash32(1u), hash32(2u));
    double sum = 0.0;
    for (uint32_t i = 0; i < 10000; ++i) {
        const float u = hashUnit(i, 7);
        ASSERT_GE(u, 0.0f);
        ASSERT_LT(u, 1.0f);
        sum += static_cast<double>(u);
    }
    EXPECT_NEAR(sum / 10000.0, 0.5, 0.02);
}

TEST(ProceduralTexture, TextIsDrawnWhereExpected) {
    using namespace scenes::detail;
    raster::Image image = solidImage("t", 64, 16, {0, 0, 0, 255});
    EXPECT_EQ(textWidth("HI", 2), (2 * kGlyphAdvance - 1) * 2);
    drawText(image, "I", 0, 0, 2, {255, 255, 255, 255});
    const auto at = [&](int x, int y) {
        return image.levels[0].rgba8[(static_cast<size_t>(y) * 64 + static_cast<size_t>(x)) * 4];
    };
    // 'I' is a full-width top bar (columns 1-3) and a centre stem (column 2).
    EXPECT_EQ(at(2, 0), 255); // top bar, column 1
    EXPECT_EQ(at(0, 0), 0);   // column 0 is empty
    EXPECT_EQ(at(4, 6), 255); // stem, column 2, row 3
    EXPECT_EQ(at(2, 6), 0);   // beside the stem
    EXPECT_EQ(at(20, 6), 0);  // nothing drawn beyond the glyph
}

} // namespace
