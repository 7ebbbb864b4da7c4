// Tests for apps/scene_info.h: describeScene reports what a Scene holds.
#include "apps/scene_info.h"

#include <raster/gltf_import.h>

#include <gtest/gtest.h>

#include <string>

namespace {

bool contains(const std::string& text, const std::string& needle) {
    return text.find(needle) != std::string::npos;
}

raster::Scene handMadeScene() {
    raster::Scene scene;
    scene.source = "builtin:test";
    raster::Primitive prim;
    prim.positions = {{0, 0, 0}, {1, 0, 0}, {0, 2, 0}, {0, 0, 3}};
    prim.indices = {0, 1, 2, 0, 2, 3};
    prim.material = 0;
    scene.meshes.push_back({"two_tris", {prim}});
    scene.instances.push_back({0, glm::mat4(1.0f)});
    raster::Instance moved{0, glm::mat4(1.0f)};
    moved.world[3] = glm::vec4(10, 0, 0, 1);
    scene.instances.push_back(moved);

    raster::Material mat;
    mat.name = "leaves";
    mat.alpha_mode = raster::AlphaMode::Mask;
    mat.alpha_cutoff = 0.25f;
    mat.double_sided = true;
    mat.base_color_texture.image = 0;
    mat.base_color_texture.sampler = 0;
    scene.materials.push_back(mat);
    raster::Material glass;
    glass.alpha_mode = raster::AlphaMode::Blend;
    glass.unlit = true;
    scene.materials.push_back(glass);

    raster::Image image;
    image.name = "leaf.png";
    image.levels.resize(3);
    image.levels[0].width = 4;
    image.levels[0].height = 2;
    scene.images.push_back(image);
    raster::Sampler sampler;
    sampler.wrap_s = raster::Wrap::ClampToEdge;
    sampler.mip = raster::MipFilter::None;
    scene.samplers.push_back(sampler);

    raster::Camera cam;
    cam.name = "Main";
    cam.yfov = 0.5f * 3.14159265f;
    cam.znear = 0.1f;
    cam.zfar = 50.0f;
    scene.cameras.push_back(cam);
    raster::Camera inf;
    inf.zfar = 0.0f;
    scene.cameras.push_back(inf);

    raster::Light light;
    light.name = "sun";
    scene.lights.push_back(light);
    scene.extensions_used = {"KHR_texture_transform", "KHR_materials_sheen"};
    scene.extensions_required = {"KHR_texture_transform"};
    scene.warnings = {"extension KHR_materials_sheen is not supported; ignored"};
    return scene;
}

TEST(SceneInfo, DescribesEverySection) {
    const std::string text = focal::describeScene(handMadeScene());
    EXPECT_TRUE(contains(text, "scene: builtin:test\n")) << text;
    EXPECT_TRUE(contains(text, "triangles: 4\n")) << text; // 2 instances x 2 triangles
    EXPECT_TRUE(contains(text, "instances: 2\n")) << text;
    EXPECT_TRUE(contains(text, "meshes: 1 (1 primitives)\n")) << text;
    EXPECT_TRUE(contains(text, "mesh 0 \"two_tris\": 1 primitives, 2 triangles, 4 vertices"))
        << text;
    EXPECT_TRUE(contains(text, "materials: 2\n")) << text;
    EXPECT_TRUE(contains(text, "material 0 \"leaves\": MASK (cutoff 0.25), double-sided")) << text;
    EXPECT_TRUE(contains(text, "base colour texture: image 0 sampler 0")) << text;
    EXPECT_TRUE(contains(text, "material 1: BLEND, unlit")) << text;
    EXPECT_TRUE(contains(text, "image 0 \"leaf.png\": 4x2, 3 mip levels, sRGB")) << text;
    EXPECT_TRUE(contains(text, "sampler 0: wrap clamp-to-edge/repeat, mag linear, min linear, "
                               "mip none"))
        << text;
    EXPECT_TRUE(contains(text, "camera 0 \"Main\": yfov 90.00 deg, near 0.1, far 50")) << text;
    EXPECT_TRUE(contains(text, "camera 1: yfov 45.84 deg, near 0.1, far infinite")) << text;
    EXPECT_TRUE(contains(text, "light 0 \"sun\": directional")) << text;
    EXPECT_TRUE(contains(text, "bounds: min (0, 0, 0) max (11, 2, 3)\n")) << text;
    EXPECT_TRUE(contains(text, "extensions used: KHR_texture_transform, KHR_materials_sheen\n"))
        << text;
    EXPECT_TRUE(contains(text, "extensions required: KHR_texture_transform\n")) << text;
    EXPECT_TRUE(contains(text, "warnings: 1\n  extension KHR_materials_sheen is not supported"))
        << text;
    EXPECT_EQ(text.back(), '\n');
}

TEST(SceneInfo, EmptySceneSaysSo) {
    const std::string text = focal::describeScene(raster::Scene{});
    EXPECT_TRUE(contains(text, "triangles: 0\n")) << text;
    EXPECT_TRUE(contains(text, "bounds: empty\n")) << text;
    EXPECT_TRUE(contains(text, "extensions used: none\n")) << text;
    EXPECT_TRUE(contains(text, "warnings: 0\n")) << text;
}

TEST(SceneInfo, SaysWhichImagesWereNotDecodedAndWhatTheyAreFor) {
    raster::ImportOptions options;
    options.roles = raster::TextureRoles{} | raster::TextureRole::BaseColor;
    raster::ImportStats stats;
    auto scene = raster::importGltf(
        std::string(FOCAL_TEST_DATA_DIR) + "/gltf/valid/textured_quad.gltf", options, &stats);
    ASSERT_TRUE(scene.ok()) << scene.status().message();
    const std::string text = focal::describeScene(*scene);
    EXPECT_TRUE(contains(text, "images: 3 (2 not decoded: no shading mode samples them)\n"))
        << text;
    EXPECT_TRUE(contains(text, "image 0 \"checker\": 2x2, 2 mip levels, sRGB, used as base "
                               "colour\n"))
        << text;
    EXPECT_TRUE(contains(text, "image 1 \"grey16\": not decoded, used as normal\n")) << text;
    const std::string load = focal::describeLoad(stats);
    EXPECT_TRUE(contains(load, "load: ")) << load;
    EXPECT_TRUE(contains(load, "1 images decoded, 2 skipped")) << load;
}

TEST(SceneInfo, DescribesAnImportedFile) {
    auto scene =
        raster::importGltf(std::string(FOCAL_TEST_DATA_DIR) + "/gltf/valid/textured_quad.gltf");
    ASSERT_TRUE(scene.ok()) << scene.status().message();
    const std::string text = focal::describeScene(*scene);
    EXPECT_TRUE(contains(text, "triangles: 2\n")) << text;
    EXPECT_TRUE(contains(text, "\"quad_material\": MASK (cutoff 0.3), double-sided")) << text;
    EXPECT_TRUE(contains(text, "image 1 \"grey16\": 2x1, 2 mip levels, linear")) << text;
    EXPECT_TRUE(contains(text, "sampler 0: wrap clamp-to-edge/mirrored-repeat, mag nearest, "
                               "min nearest, mip linear"))
        << text;
}

} // namespace
