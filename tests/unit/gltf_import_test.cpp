// Tests for raster/gltf_import.h: the valid fixtures in tests/data/gltf/valid import with the
// expected values; every malformed fixture in tests/data/gltf/bad fails with its own message.
// Fixtures are written by tests/data/gltf/make_fixtures.py.
#include "support/test_util.h"

#include <raster/gltf_import.h>
#include <raster/renderer.h>
#include <raster/scene.h>
#include <raster/task_pool.h>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace {

using raster::importGltf;
using raster::Scene;

std::string validPath(const std::string& name) {
    return std::string(FOCAL_TEST_DATA_DIR) + "/gltf/valid/" + name;
}
std::string badPath(const std::string& name) {
    return std::string(FOCAL_TEST_DATA_DIR) + "/gltf/bad/" + name;
}

Scene load(const std::string& name) {
    auto result = importGltf(validPath(name));
    EXPECT_TRUE(result.ok()) << result.status().message();
    if (!result.ok())
        return Scene{};
    return std::move(result.value());
}

bool hasWarning(const Scene& scene, const std::string& needle) {
    return std::any_of(scene.warnings.begin(), scene.warnings.end(),
                       [&](const std::string& w) { return w.find(needle) != std::string::npos; });
}

void expectVec3(const glm::vec3& got, const glm::vec3& want, float eps = 1e-5f) {
    EXPECT_NEAR(got.x, want.x, eps);
    EXPECT_NEAR(got.y, want.y, eps);
    EXPECT_NEAR(got.z, want.z, eps);
}

glm::vec3 transformPoint(const glm::mat4& m, const glm::vec3& p) {
    return glm::vec3(m * glm::vec4(p, 1.0f));
}

TEST(GltfImport, TriangleWithExternalBuffer) {
    const Scene scene = load("triangle.gltf");
    ASSERT_EQ(scene.meshes.size(), 1u);
    ASSERT_EQ(scene.meshes[0].primitives.size(), 1u);
    const raster::Primitive& prim = scene.meshes[0].primitives[0];
    ASSERT_EQ(prim.positions.size(), 3u);
    expectVec3(prim.positions[1], {1, 0, 0});
    EXPECT_EQ(prim.indices, (std::vector<uint32_t>{0, 1, 2}));
    EXPECT_TRUE(prim.normals.empty());
    EXPECT_TRUE(prim.texcoords0.empty());
    EXPECT_TRUE(prim.colors.empty());
    EXPECT_EQ(prim.material, -1);
    ASSERT_EQ(scene.instances.size(), 1u);
    EXPECT_EQ(scene.instances[0].mesh, 0u);
    EXPECT_EQ(scene.instances[0].world, glm::mat4(1.0f));
    EXPECT_EQ(raster::triangleCount(scene), 1u);
    EXPECT_EQ(scene.source, validPath("triangle.gltf"));
    EXPECT_TRUE(scene.warnings.empty());
}

TEST(GltfImport, TexturedQuadAttributesMaterialImagesSamplers) {
    const Scene scene = load("textured_quad.gltf");
    ASSERT_EQ(scene.meshes.size(), 1u);
    const raster::Primitive& prim = scene.meshes[0].primitives[0];
    ASSERT_EQ(prim.positions.size(), 4u);
    EXPECT_EQ(prim.indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3}));
    ASSERT_EQ(prim.normals.size(), 4u);
    expectVec3(prim.normals[2], {0, 0, 1});
    // Normalized unsigned short UVs.
    ASSERT_EQ(prim.texcoords0.size(), 4u);
    EXPECT_FLOAT_EQ(prim.texcoords0[0].x, 0.0f);
    EXPECT_FLOAT_EQ(prim.texcoords0[0].y, 1.0f);
    EXPECT_FLOAT_EQ(prim.texcoords0[2].x, 1.0f);
    EXPECT_FLOAT_EQ(prim.texcoords0[2].y, 0.0f);
    // Normalized unsigned byte VEC4 colours.
    ASSERT_EQ(prim.colors.size(), 4u);
    EXPECT_EQ(prim.colors[1], glm::vec4(0, 1, 0, 1));
    EXPECT_EQ(prim.colors[3], glm::vec4(1, 1, 1, 0));
    EXPECT_EQ(prim.material, 0);

    ASSERT_EQ(scene.materials.size(), 1u);
    const raster::Material& m = scene.materials[0];
    EXPECT_EQ(m.name, "quad_material");
    EXPECT_EQ(m.base_color_factor, glm::vec4(0.5f, 0.25f, 1.0f, 0.75f));
    EXPECT_EQ(m.emissive_factor, glm::vec3(1.0f, 0.5f, 0.0f));
    EXPECT_FLOAT_EQ(m.metallic_factor, 0.25f);
    EXPECT_FLOAT_EQ(m.roughness_factor, 0.75f);
    EXPECT_EQ(m.alpha_mode, raster::AlphaMode::Mask);
    EXPECT_FLOAT_EQ(m.alpha_cutoff, 0.3f);
    EXPECT_TRUE(m.double_sided);
    EXPECT_FALSE(m.unlit);
    EXPECT_EQ(m.base_color_texture.image, 0);
    EXPECT_EQ(m.base_color_texture.sampler, 0);
    EXPECT_EQ(m.base_color_texture.texcoord, 0u);
    EXPECT_EQ(m.base_color_texture.transform, glm::mat3(1.0f));
    EXPECT_EQ(m.emissive_texture.image, 2);
    EXPECT_EQ(m.emissive_texture.sampler, -1);

    // Images: RGB expanded to RGBA, 16-bit grey reduced to 8 bits, grey-alpha expanded.
    ASSERT_EQ(scene.images.size(), 3u);
    const raster::Image& checker = scene.images[0];
    EXPECT_EQ(checker.name, "checker");
    EXPECT_TRUE(checker.srgb);
    ASSERT_FALSE(checker.levels.empty());
    EXPECT_EQ(checker.levels[0].width, 2u);
    EXPECT_EQ(checker.levels[0].height, 2u);
    EXPECT_EQ(checker.levels[0].rgba8, (std::vector<uint8_t>{255, 0, 0, 255, 0, 255, 0, 255, 0, 0,
                                                             255, 255, 255, 255, 255, 255}));
    EXPECT_EQ(checker.levels.size(), 2u); // 2x2 and 1x1 (buildMipChain)
    const raster::Image& grey16 = scene.images[1];
    EXPECT_FALSE(grey16.srgb); // a normal map: linear data
    ASSERT_FALSE(grey16.levels.empty());
    EXPECT_EQ(grey16.levels[0].width, 2u);
    EXPECT_EQ(grey16.levels[0].height, 1u);
    EXPECT_EQ(grey16.levels[0].rgba8, (std::vector<uint8_t>{0, 0, 0, 255, 255, 255, 255, 255}));
    const raster::Image& grey_alpha = scene.images[2];
    EXPECT_TRUE(grey_alpha.srgb); // emissive
    ASSERT_FALSE(grey_alpha.levels.empty());
    EXPECT_EQ(grey_alpha.levels[0].rgba8, (std::vector<uint8_t>{128, 128, 128, 64}));

    // Samplers: every mode mapped; an empty sampler gets the defaults.
    ASSERT_EQ(scene.samplers.size(), 2u);
    const raster::Sampler& s0 = scene.samplers[0];
    EXPECT_EQ(s0.mag, raster::Filter::Nearest);
    EXPECT_EQ(s0.min, raster::Filter::Nearest);
    EXPECT_EQ(s0.mip, raster::MipFilter::Linear);
    EXPECT_EQ(s0.wrap_s, raster::Wrap::ClampToEdge);
    EXPECT_EQ(s0.wrap_t, raster::Wrap::MirroredRepeat);
    const raster::Sampler& s1 = scene.samplers[1];
    EXPECT_EQ(s1.mag, raster::Filter::Linear);
    EXPECT_EQ(s1.min, raster::Filter::Linear);
    EXPECT_EQ(s1.mip, raster::MipFilter::Linear);
    EXPECT_EQ(s1.wrap_s, raster::Wrap::Repeat);
    EXPECT_EQ(s1.wrap_t, raster::Wrap::Repeat);
    EXPECT_TRUE(scene.warnings.empty());
}

TEST(GltfImport, HierarchyComposesTrsAndMatrix) {
    const Scene scene = load("hierarchy.gltf");
    ASSERT_EQ(scene.instances.size(), 2u);
    // leaf: root (T(1,2,3) R_y(90) S(2)) * child (T(0,0,5)) * identity.
    // Vertex (1,0,0): child -> (1,0,5); scale -> (2,0,10); R_y(90): (x,z) -> (z,-x) = (10,0,-2);
    // translate -> (11,2,1).
    const glm::mat4& leaf = scene.instances[0].world;
    expectVec3(transformPoint(leaf, {1, 0, 0}), {11, 2, 1});
    expectVec3(transformPoint(leaf, {0, 0, 0}), {11, 2, 3});
    expectVec3(transformPoint(leaf, {0, 1, 0}), {11, 4, 3});
    // plain: translation only.
    expectVec3(transformPoint(scene.instances[1].world, {1, 0, 0}), {11, 0, 0});
    EXPECT_EQ(raster::triangleCount(scene), 2u);
    const raster::Bounds b = raster::worldBounds(scene);
    ASSERT_FALSE(b.empty);
    expectVec3(b.min, {10, 0, 0});
    expectVec3(b.max, {11, 4, 3});
}

TEST(GltfImport, StripAndFanBecomeListsPointsAndLinesAreSkipped) {
    const Scene scene = load("strip_fan.gltf");
    ASSERT_EQ(scene.meshes.size(), 1u);
    ASSERT_EQ(scene.meshes[0].primitives.size(), 2u);
    // Strip 0..4, triangle i = (p_i, p_{i+1+i%2}, p_{i+2-i%2}) (glTF 2.0 §3.7.2.1):
    // (0,1,2) (1,3,2) (2,3,4), every triangle with the first one's winding.
    EXPECT_EQ(scene.meshes[0].primitives[0].indices,
              (std::vector<uint32_t>{0, 1, 2, 1, 3, 2, 2, 3, 4}));
    // Fan 0..4, non-indexed: (1,2,0) (2,3,0) (3,4,0).
    EXPECT_EQ(scene.meshes[0].primitives[1].indices,
              (std::vector<uint32_t>{1, 2, 0, 2, 3, 0, 3, 4, 0}));
    EXPECT_EQ(raster::triangleCount(scene), 6u);
    EXPECT_TRUE(hasWarning(scene, "mesh 0 primitive 2 draws points"));
    EXPECT_TRUE(hasWarning(scene, "mesh 0 primitive 3 draws lines"));
}

TEST(GltfImport, PerspectiveCameraImportedOrthographicSkipped) {
    const Scene scene = load("camera.gltf");
    ASSERT_EQ(scene.cameras.size(), 1u);
    const raster::Camera& cam = scene.cameras[0];
    EXPECT_EQ(cam.name, "persp");
    EXPECT_NEAR(cam.yfov, 1.0471976f, 1e-6f);
    EXPECT_FLOAT_EQ(cam.znear, 0.05f);
    EXPECT_FLOAT_EQ(cam.zfar, 100.0f);
    EXPECT_FLOAT_EQ(cam.aspect_ratio, 1.5f);
    expectVec3(transformPoint(cam.world, {0, 0, 0}), {0, 0, 5});
    EXPECT_TRUE(hasWarning(scene, "camera 1 is orthographic"));
}

TEST(GltfImport, PunctualLightsInWorldSpace) {
    const Scene scene = load("lights.gltf");
    ASSERT_EQ(scene.lights.size(), 3u);
    const raster::Light& sun = scene.lights[0];
    EXPECT_EQ(sun.name, "sun");
    EXPECT_EQ(sun.type, raster::Light::Type::Directional);
    EXPECT_EQ(sun.color, glm::vec3(1.0f, 0.9f, 0.8f));
    EXPECT_FLOAT_EQ(sun.intensity, 3.0f);
    expectVec3(sun.direction, {0, -1, 0}); // -Z rotated -90 degrees about X
    const raster::Light& bulb = scene.lights[1];
    EXPECT_EQ(bulb.type, raster::Light::Type::Point);
    EXPECT_FLOAT_EQ(bulb.range, 10.0f);
    EXPECT_EQ(bulb.color, glm::vec3(1.0f));
    expectVec3(bulb.position, {1, 2, 3});
    const raster::Light& torch = scene.lights[2];
    EXPECT_EQ(torch.type, raster::Light::Type::Spot);
    EXPECT_FLOAT_EQ(torch.inner_cone_angle, 0.1f);
    EXPECT_FLOAT_EQ(torch.outer_cone_angle, 0.5f);
    expectVec3(torch.position, {0, 4, 0});   // from its parent
    expectVec3(torch.direction, {-1, 0, 0}); // -Z rotated 90 degrees about Y
    EXPECT_FLOAT_EQ(glm::length(torch.direction), 1.0f);
}

TEST(GltfImport, TextureTransformFoldedIntoMatrix) {
    const Scene scene = load("texture_transform.gltf");
    ASSERT_EQ(scene.materials.size(), 1u);
    const raster::TextureRef& ref = scene.materials[0].base_color_texture;
    EXPECT_EQ(ref.image, 0);
    EXPECT_EQ(ref.texcoord, 1u); // the extension's texCoord overrides the textureInfo's
    // uv' = T(0.5,0.25) * R(pi/2) * S(2,3) * uv; with the spec's R, (u,v) -> (-v, u).
    auto apply = [&](float u, float v) { return ref.transform * glm::vec3(u, v, 1.0f); };
    expectVec3(apply(0, 0), {0.5f, 0.25f, 1});
    expectVec3(apply(1, 0), {0.5f, 2.25f, 1});  // S: (2,0); R: (0,2); T: (0.5,2.25)
    expectVec3(apply(0, 1), {-2.5f, 0.25f, 1}); // S: (0,3); R: (-3,0); T: (-2.5,0.25)
    EXPECT_EQ(scene.extensions_required, (std::vector<std::string>{"KHR_texture_transform"}));
    EXPECT_TRUE(hasWarning(scene, "TEXCOORD_1"));
}

TEST(GltfImport, UnlitEmissiveStrengthBlendAndUnknownOptionalExtension) {
    const Scene scene = load("unlit.gltf");
    ASSERT_EQ(scene.materials.size(), 1u);
    const raster::Material& m = scene.materials[0];
    EXPECT_TRUE(m.unlit);
    EXPECT_EQ(m.alpha_mode, raster::AlphaMode::Blend);
    EXPECT_EQ(m.emissive_factor, glm::vec3(4.0f, 2.0f, 1.0f));
    EXPECT_EQ(scene.extensions_used.size(), 3u);
    EXPECT_TRUE(hasWarning(scene, "extension EXT_made_up_optional is not supported"));
    EXPECT_FALSE(hasWarning(scene, "KHR_materials_unlit"));
}

TEST(GltfImport, NoScenesDrawsEveryRootNode) {
    const Scene scene = load("no_scenes.gltf");
    ASSERT_EQ(scene.instances.size(), 3u); // root 0, its child 1, root 2
    expectVec3(transformPoint(scene.instances[1].world, {0, 0, 0}), {0, 0, -1});
    expectVec3(transformPoint(scene.instances[2].world, {0, 0, 0}), {5, 0, 0});
}

TEST(GltfImport, SparseAccessorAndAccessorWithoutBufferView) {
    const Scene scene = load("sparse.gltf");
    const raster::Primitive& prim = scene.meshes.at(0).primitives.at(0);
    ASSERT_EQ(prim.positions.size(), 3u);
    expectVec3(prim.positions[1], {1, 0, 0});
    expectVec3(prim.positions[2], {0, 3, 0}); // replaced by the sparse value
    ASSERT_EQ(prim.colors.size(), 3u);
    EXPECT_EQ(prim.colors[0], glm::vec4(0, 0, 0, 1)); // zeros (VEC3: alpha 1)
}

TEST(GltfImport, BinaryGlbWithImageInBufferView) {
    const Scene scene = load("triangle.glb");
    EXPECT_EQ(raster::triangleCount(scene), 1u);
    ASSERT_EQ(scene.images.size(), 1u);
    ASSERT_FALSE(scene.images[0].levels.empty());
    EXPECT_EQ(scene.images[0].levels[0].width, 2u);
    EXPECT_EQ(scene.images[0].levels[0].rgba8[0], 255u);
    EXPECT_TRUE(scene.images[0].srgb);
    EXPECT_EQ(scene.materials.at(0).base_color_texture.image, 0);
}

// --- load only what is sampled (issue 18) ---------------------------------------------------

constexpr raster::ShadingMode kShadingModes[] = {
    raster::ShadingMode::Material, raster::ShadingMode::Unlit, raster::ShadingMode::Lit};

raster::ImportOptions sampledBy(raster::ShadingMode mode, raster::TaskPool* pool = nullptr) {
    raster::ImportOptions options;
    options.roles = raster::sampledTextureRoles(mode);
    options.pool = pool;
    return options;
}

TEST(GltfImportSampled, NoShadingModeSamplesNormalOcclusionOrMetallicRoughnessMaps) {
    for (const raster::ShadingMode mode : kShadingModes) {
        const raster::TextureRoles roles = raster::sampledTextureRoles(mode);
        EXPECT_TRUE(roles.has(raster::TextureRole::BaseColor));
        EXPECT_TRUE(roles.has(raster::TextureRole::Emissive));
        EXPECT_FALSE(roles.has(raster::TextureRole::Normal));
        EXPECT_FALSE(roles.has(raster::TextureRole::Occlusion));
        EXPECT_FALSE(roles.has(raster::TextureRole::MetallicRoughness));
    }
}

TEST(GltfImportSampled, UnsampledMapsAreNotDecodedForAnyShadingMode) {
    for (const raster::ShadingMode mode : kShadingModes) {
        raster::ImportStats stats;
        auto result = importGltf(validPath("unsampled_maps.gltf"), sampledBy(mode), &stats);
        ASSERT_TRUE(result.ok()) << result.status().message();
        const Scene& scene = *result;
        ASSERT_EQ(scene.images.size(), 4u);
        const raster::Image& checker = scene.images[0];
        EXPECT_TRUE(checker.decoded);
        ASSERT_EQ(checker.levels.size(), 2u);
        EXPECT_EQ(checker.levels[0].width, 2u);
        EXPECT_EQ(checker.roles, raster::TextureRoles{} | raster::TextureRole::BaseColor);
        // The undecodable normal map is never decoded, so it is no problem.
        const raster::Image& normal = scene.images[1];
        EXPECT_FALSE(normal.decoded);
        EXPECT_TRUE(normal.levels.empty());
        EXPECT_EQ(normal.roles, raster::TextureRoles{} | raster::TextureRole::MetallicRoughness |
                                    raster::TextureRole::Normal);
        EXPECT_FALSE(scene.images[2].decoded);
        EXPECT_EQ(scene.images[2].roles, raster::TextureRoles{} | raster::TextureRole::Occlusion);
        EXPECT_FALSE(scene.images[3].decoded);
        EXPECT_TRUE(scene.images[3].roles.empty());
        // A missing file is found without decoding: still reported, as a warning.
        ASSERT_EQ(scene.warnings.size(), 1u);
        EXPECT_EQ(scene.warnings[0], "image 2 (missing_occlusion.png) file not found: "
                                     "missing_occlusion.png; not needed, so not decoded");
        EXPECT_EQ(stats.images_decoded, 1u);
        EXPECT_EQ(stats.images_skipped, 3u);
        EXPECT_GE(stats.ms_total, stats.ms_parse);
    }
}

TEST(GltfImportSampled, EveryImageIsDecodedByDefaultAndWhenItsRoleIsAskedFor) {
    // Unset roles decode every image, as before: the broken normal map is a warning and a white
    // texel, the image no material uses is decoded too.
    raster::ImportStats stats;
    auto all = importGltf(validPath("unsampled_maps.gltf"), {}, &stats);
    ASSERT_TRUE(all.ok()) << all.status().message();
    ASSERT_EQ(all->images.size(), 4u);
    for (const raster::Image& image : all->images) {
        EXPECT_TRUE(image.decoded) << image.name;
        EXPECT_FALSE(image.levels.empty()) << image.name;
    }
    EXPECT_EQ(all->images[1].levels[0].rgba8, (std::vector<uint8_t>{255, 255, 255, 255}));
    EXPECT_EQ(all->images[3].levels[0].width, 2u);
    EXPECT_TRUE(hasWarning(*all, "image 1 (broken_normal) cannot be decoded"));
    EXPECT_TRUE(hasWarning(*all, "image 1 (broken_normal) cannot be decoded (not a "
                                 "PNG/JPEG/BMP/GIF/TGA/PSD/HDR/PNM image stb can read); replaced "
                                 "by a white texel"));
    EXPECT_TRUE(hasWarning(*all, "image 2 (missing_occlusion.png) file not found: "
                                 "missing_occlusion.png; replaced by a white texel"));
    EXPECT_EQ(stats.images_decoded, 2u); // the two placeholders are not counted as decoded
    EXPECT_EQ(stats.images_skipped, 0u);

    // Asking for normal maps decodes (and reports) exactly the broken one.
    raster::ImportOptions normals;
    normals.roles = raster::TextureRoles{} | raster::TextureRole::Normal;
    auto with_normals = importGltf(validPath("unsampled_maps.gltf"), normals);
    ASSERT_TRUE(with_normals.ok()) << with_normals.status().message();
    EXPECT_FALSE(with_normals->images[0].decoded);
    EXPECT_TRUE(with_normals->images[1].decoded);
    EXPECT_TRUE(hasWarning(*with_normals, "image 1 (broken_normal) cannot be decoded"));
}

TEST(GltfImportSampled, UndecodableBaseColourStillFailsForEveryShadingMode) {
    for (const raster::ShadingMode mode : kShadingModes) {
        auto result = importGltf(badPath("undecodable_image.gltf"), sampledBy(mode));
        ASSERT_FALSE(result.ok());
        EXPECT_NE(result.status().message().find("image 0 cannot be decoded"), std::string::npos)
            << result.status().message();
    }
}

TEST(GltfImportSampled, SameImagesAndWarningsForEveryThreadCount) {
    for (const char* name : {"textured_quad.gltf", "unsampled_maps.gltf", "triangle.glb"}) {
        for (const bool sampled : {false, true}) {
            raster::ImportOptions options =
                sampled ? sampledBy(raster::ShadingMode::Material) : raster::ImportOptions{};
            auto inline_result = importGltf(validPath(name), options);
            ASSERT_TRUE(inline_result.ok()) << inline_result.status().message();
            const uint64_t reference = focal::test::hashImages(*inline_result);
            for (const uint32_t threads : {0u, 1u, 2u, 5u}) {
                raster::TaskPool pool(threads);
                options.pool = &pool;
                auto result = importGltf(validPath(name), options);
                ASSERT_TRUE(result.ok()) << result.status().message();
                EXPECT_EQ(focal::test::hashImages(*result), reference)
                    << name << " threads " << threads << (sampled ? " sampled" : " all");
            }
        }
    }
}

TEST(GltfImportSampled, RenderRefusesATextureImportDidNotDecode) {
    raster::ImportOptions none;
    none.roles = raster::TextureRoles{};
    auto result = importGltf(validPath("textured_quad.gltf"), none);
    ASSERT_TRUE(result.ok()) << result.status().message();
    for (const raster::ShadingMode mode : kShadingModes) {
        const raster::Status s = raster::validateTextures(*result, mode);
        ASSERT_FALSE(s.ok());
        EXPECT_EQ(s.message(), "material 0 samples image 0 as its base colour texture, but the "
                               "scene has no pixels for it (import with the texture roles the "
                               "shading samples)");
    }
    raster::TaskPool pool(0);
    raster::Renderer renderer(pool);
    raster::Frame frame;
    EXPECT_FALSE(renderer.render(*result, focal::test::pixelView(8, 8, 8.0f), {}, frame).ok());

    auto sampled =
        importGltf(validPath("textured_quad.gltf"), sampledBy(raster::ShadingMode::Unlit));
    ASSERT_TRUE(sampled.ok()) << sampled.status().message();
    EXPECT_FALSE(sampled->images[1].decoded); // the 16-bit normal map
    for (const raster::ShadingMode mode : kShadingModes)
        EXPECT_TRUE(raster::validateTextures(*sampled, mode).ok());
}

TEST(GltfImport, MissingFile) {
    auto result = importGltf(validPath("does_not_exist.gltf"));
    ASSERT_FALSE(result.ok());
    EXPECT_EQ(result.status().message(), validPath("does_not_exist.gltf") + ": file not found");
}

struct BadCase {
    const char* file;
    const char* message; // expected substring after "<path>: "
};

void PrintTo(const BadCase& c, std::ostream* os) {
    *os << c.file;
}

class GltfImportBad : public ::testing::TestWithParam<BadCase> {};

TEST_P(GltfImportBad, FailsWithOneLineMessageNamingFileAndItem) {
    const BadCase& c = GetParam();
    const std::string path = badPath(c.file);
    ASSERT_TRUE(std::filesystem::exists(path)) << "run tests/data/gltf/make_fixtures.py";
    auto result = importGltf(path);
    ASSERT_FALSE(result.ok());
    const std::string& message = result.status().message();
    EXPECT_EQ(message.rfind(path + ": ", 0), 0u) << message;
    EXPECT_NE(message.find(c.message), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
}

const BadCase kBadCases[] = {
    {"bad_json.gltf", "invalid JSON"},
    {"not_gltf.gltf", "invalid JSON"},
    {"vertex_index_oob.gltf",
     "mesh 0 primitive 0 index 3 (element 2 of accessor 1) is out of range: there are 3 vertices"},
    {"material_oob.gltf", "mesh 0 primitive 0 refers to material 5, but there are 0"},
    {"texture_oob.gltf", "material 0 baseColorTexture refers to texture 3, but there are 0"},
    {"image_oob.gltf", "texture 0 refers to image 4, but there are 0"},
    {"sampler_oob.gltf", "texture 0 refers to sampler 2, but there are 0"},
    {"accessor_oob.gltf", "attribute POSITION refers to accessor 9, but there are 2"},
    {"bufferview_oob.gltf", "accessor 0 refers to bufferView 7, but there are 2"},
    {"buffer_oob.gltf", "bufferView 0 refers to buffer 3, but there are 1"},
    {"node_oob.gltf", "node 0 has child 42, but there are 1 nodes"},
    {"mesh_oob.gltf", "node 0 refers to mesh 3, but there are 1"},
    {"camera_oob.gltf", "node 1 refers to camera 2, but there are 0"},
    {"light_oob.gltf", "node 1 refers to light 5, but there are 0"},
    {"default_scene_oob.gltf", "default scene 3 is out of range"},
    {"accessor_past_buffer.gltf", "accessor 0 reads past the end of buffer 0"},
    {"accessor_past_view.gltf", "accessor 0 reads past the end of bufferView 0"},
    {"accessor_stride_past_view.gltf", "accessor 0 reads past the end of buffer"},
    {"view_past_buffer.gltf", "bufferView 1 reads past the end of buffer 0"},
    {"position_wrong_type.gltf", "accessor 0 (mesh 0 primitive 0 POSITION) has type VEC2"},
    {"position_wrong_component.gltf", "which POSITION does not allow"},
    {"indices_wrong_type.gltf", "of FLOAT, which indices does not allow"},
    {"texcoord_unnormalized_ubyte.gltf", "which TEXCOORD_0 does not allow"},
    {"normal_count_mismatch.gltf", "NORMAL has 2 elements, but POSITION has 3"},
    {"nan_position.gltf", "POSITION) has a non-finite value (NaN or Inf) in element 1"},
    {"inf_position.gltf", "POSITION) has a non-finite value (NaN or Inf) in element 1"},
    {"indices_not_multiple_of_3.gltf", "4 indices, which is not a multiple of 3"},
    {"missing_buffer.gltf", "buffer file not found: missing.bin"},
    {"missing_image.gltf", "image 0 (missing.png) file not found: missing.png"},
    {"undecodable_image.gltf", "image 0 cannot be decoded"},
    {"huge_image.gltf", "image 0 is too large (100000x100000)"},
    {"node_cycle.gltf", "node cycle"},
    {"node_self_child.gltf", "node 0 is its own child"},
    {"node_two_parents.gltf", "node 2 has two parents (nodes 0 and 1)"},
    {"scene_lists_child.gltf", "scene lists node 1, which is not a root node"},
    {"empty_scene.gltf", "no triangles to render"},
    {"only_points.gltf", "no triangles to render"},
    {"required_extension.gltf", "required extension KHR_draco_mesh_compression is not supported"},
    {"bad_alpha_mode.gltf", "material 0 has an unknown alphaMode \"SOMETIMES\""},
    {"bad_rotation.gltf", "node 0 rotation does not have 4 entries"},
    {"truncated.glb", "invalid GLB file"},
    // Issue 23: hostile files.
    {"deep_nesting.gltf", "JSON nests deeper than 128 levels (at byte 165), the most focal "
                          "accepts"},
    {"zero_accessors_per_file.gltf",
     "accessor 2 (mesh 0 primitive 2 POSITION) has no bufferView and brings the elements of such "
     "accessors read by this file to 1179648, more than the 1048576 a file of"},
    {"buffer_uri_directory.gltf", "is a directory, not a file"},
};

std::string badCaseName(const ::testing::TestParamInfo<BadCase>& param) {
    std::string name = param.param.file;
    std::replace_if(
        name.begin(), name.end(),
        [](char ch) { return !std::isalnum(static_cast<unsigned char>(ch)); }, '_');
    return name;
}

INSTANTIATE_TEST_SUITE_P(Malformed, GltfImportBad, ::testing::ValuesIn(kBadCases), badCaseName);

// Every file in the bad/ folder has a case above, so a new fixture cannot go untested.
TEST(GltfImportBadFolder, EveryFixtureHasACase) {
    const std::filesystem::path dir = std::string(FOCAL_TEST_DATA_DIR) + "/gltf/bad";
    ASSERT_TRUE(std::filesystem::is_directory(dir));
    for (const auto& entry : std::filesystem::directory_iterator(dir)) {
        const std::string name = entry.path().filename().string();
        const bool listed = std::any_of(std::begin(kBadCases), std::end(kBadCases),
                                        [&](const BadCase& c) { return name == c.file; });
        EXPECT_TRUE(listed) << name << " has no expected message in kBadCases";
    }
}

// Issue 23: hostile input beyond the fixtures (files too large to commit are written here).
std::string writeTemp(const std::string& name, const std::string& text) {
    const std::filesystem::path path = std::filesystem::temp_directory_path() / name;
    std::ofstream(path, std::ios::binary) << text;
    return path.string();
}

// One triangle drawn from an accessor without a bufferView of `count` VEC3 elements.
std::string zeroAccessorGltf(uint64_t count) {
    return R"({"asset":{"version":"2.0"},"accessors":[{"componentType":5126,"count":)" +
           std::to_string(count) +
           R"(,"type":"VEC3"}],"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],)"
           R"("nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}]})";
}

TEST(GltfImportHostile, TinyFileCannotDeclareMillionsOfZeros) {
    // 2^24 elements was the per-accessor limit: a 200-byte file made focal take 1.4 GB.
    const std::string path = writeTemp("focal_zero_accessor_2p24.gltf", zeroAccessorGltf(1u << 24));
    const auto r = importGltf(path);
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.status().message().find("has no bufferView and brings the elements of such "
                                        "accessors read by this file to 16777216"),
              std::string::npos)
        << r.status().message();
    std::filesystem::remove(path);
}

TEST(GltfImportHostile, ZerosAreCheckedAgainstTheMemoryBudget) {
    // 2^20 - 2 elements (a multiple of 3) fit the per-file limit; 24 MiB of values do not fit 16.
    const std::string path =
        writeTemp("focal_zero_accessor_budget.gltf", zeroAccessorGltf((1u << 20) - 1));
    raster::ImportOptions options;
    options.memory_budget.bytes = uint64_t{16} << 20;
    const auto r = importGltf(path, options);
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.status().message().find(
                  "reading accessors without a bufferView needs 24 MiB, more than the memory "
                  "budget of 16 MiB"),
              std::string::npos)
        << r.status().message();
    EXPECT_TRUE(importGltf(path).ok()); // unlimited: zeros are a legal (if useless) mesh
    std::filesystem::remove(path);
}

TEST(GltfImportHostile, RefusesWhatIsNotARegularFile) {
    // /dev/zero would be read until memory runs out.
    const auto r = importGltf("/dev/zero");
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.status().message(), "/dev/zero: is not a regular file");
}

TEST(GltfImportHostile, FromMemoryImportsLikeFromAFile) {
    std::ifstream in(validPath("triangle.glb"), std::ios::binary);
    const std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)),
                                           std::istreambuf_iterator<char>());
    const auto from_memory =
        raster::importGltfFromMemory(bytes.data(), bytes.size(), "triangle.glb", ".");
    ASSERT_TRUE(from_memory.ok()) << from_memory.status().message();
    const Scene from_file = load("triangle.glb");
    ASSERT_EQ(from_memory->meshes.size(), from_file.meshes.size());
    EXPECT_EQ(from_memory->meshes[0].primitives[0].positions,
              from_file.meshes[0].primitives[0].positions);
    const auto nested = raster::importGltfFromMemory(
        reinterpret_cast<const unsigned char*>("[[[[]]]]"), 8, "x.gltf", ".");
    EXPECT_FALSE(nested.ok());
}

// Third-party scenes (not shipped with focal; see /work/shared/scenes/README.md).
struct RealScene {
    const char* name;
    uint64_t triangles;
    size_t cameras;
};

class GltfImportRealScene : public ::testing::TestWithParam<RealScene> {};

TEST_P(GltfImportRealScene, ImportsWithKnownTriangleCount) {
    const RealScene& s = GetParam();
    const std::string path =
        std::string("/work/shared/scenes/") + s.name + "/glTF/" + s.name + ".gltf";
    if (!std::filesystem::exists(path))
        GTEST_SKIP() << path << " not present";
    auto result = importGltf(path);
    ASSERT_TRUE(result.ok()) << result.status().message();
    EXPECT_EQ(raster::triangleCount(*result), s.triangles);
    EXPECT_EQ(result->cameras.size(), s.cameras);
    for (const raster::Image& image : result->images)
        EXPECT_FALSE(image.levels.empty()) << image.name;
}

std::string realSceneName(const ::testing::TestParamInfo<RealScene>& param) {
    return param.param.name;
}

INSTANTIATE_TEST_SUITE_P(Shared, GltfImportRealScene,
                         ::testing::Values(RealScene{"ToyCar", 108936, 8},
                                           RealScene{"StainedGlassLamp", 35132, 0},
                                           RealScene{"GlassVaseFlowers", 14036, 0},
                                           RealScene{"AlphaBlendModeTest", 61, 0}),
                         realSceneName);

} // namespace
