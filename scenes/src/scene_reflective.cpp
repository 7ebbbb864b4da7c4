// builtin:reflective — view-dependent shading (Lee, Eisemann & Seidel 2009, Sec. 5 and Fig. 9):
// shiny metallic spheres of varying roughness under coloured point lights, at several depths.
// Specular highlights move with the lens position, so methods that shade once per pixel differ
// from the accumulation reference here.
#include "generators.h"
#include "mesh_builder.h"
#include "procedural_texture.h"

#include <array>
#include <string>
#include <utility>

namespace scenes::detail {

raster::Scene makeReflectiveScene() {
    raster::Scene scene;
    scene.background = {0.05f, 0.06f, 0.08f};
    const int32_t repeat = addSampler(scene, {});

    const glm::vec3 target{0.0f, 0.6f, 0.0f};
    scene.cameras.push_back(
        lookAtCamera("reflective", {0.0f, 1.25f, 4.5f}, target, 0.7f, 0.05f, 60.0f));

    const int32_t floor_tex = addImage(
        scene, checkerImage("floor_checker", 256, 2, {150, 150, 150, 255}, {35, 35, 40, 255}));
    const int32_t floor_mat = addMaterial(scene, textured("floor", floor_tex, repeat, 0.35f));
    raster::Primitive floor;
    floor.material = floor_mat;
    appendGrid(floor, {-10.0f, 0.0f, 8.0f}, {20.0f, 0.0f, 0.0f}, {0.0f, 0.0f, -20.0f}, 10, 10,
               {20.0f, 20.0f});
    addInstance(scene, addMesh(scene, "floor", std::move(floor)));

    struct Ball {
        const char* name;
        glm::vec3 center;
        float radius;
        glm::vec3 color; // linear; F0 for metals
        float metallic;
        float roughness;
    };
    constexpr std::array<Ball, 7> kBalls = {{
        {"gold", {0.0f, 0.6f, 0.0f}, 0.6f, {1.0f, 0.77f, 0.34f}, 1.0f, 0.15f},
        {"silver", {-1.35f, 0.45f, 1.3f}, 0.45f, {0.97f, 0.96f, 0.91f}, 1.0f, 0.05f},
        {"copper", {1.5f, 0.5f, -1.4f}, 0.5f, {0.95f, 0.64f, 0.54f}, 1.0f, 0.3f},
        {"red_lacquer", {-1.9f, 0.55f, -2.6f}, 0.55f, {0.6f, 0.04f, 0.03f}, 0.0f, 0.08f},
        {"chrome_small", {0.9f, 0.22f, 1.6f}, 0.22f, {0.55f, 0.56f, 0.55f}, 1.0f, 0.02f},
        {"blue_plastic", {-0.5f, 0.25f, 2.3f}, 0.25f, {0.05f, 0.15f, 0.6f}, 0.0f, 0.2f},
        {"brushed_steel", {2.6f, 0.7f, -4.0f}, 0.7f, {0.56f, 0.57f, 0.58f}, 1.0f, 0.45f},
    }};
    for (const Ball& b : kBalls) {
        raster::Material m = matte(b.name, b.color, b.roughness);
        m.metallic_factor = b.metallic;
        raster::Primitive prim;
        prim.material = addMaterial(scene, std::move(m));
        appendSphere(prim, b.center, b.radius, 96, 48);
        addInstance(scene, addMesh(scene, b.name, std::move(prim)));
    }

    scene.lights.push_back(pointLight("warm", {2.5f, 3.0f, 3.0f}, {1.0f, 0.8f, 0.6f}, 60.0f));
    scene.lights.push_back(pointLight("cool", {-3.0f, 2.0f, 1.5f}, {0.5f, 0.7f, 1.0f}, 40.0f));
    scene.lights.push_back(pointLight("rim", {0.5f, 2.5f, -4.0f}, {1.0f, 1.0f, 1.0f}, 40.0f));
    scene.lights.push_back(
        directionalLight("ambient_key", {0.2f, -0.8f, -0.5f}, {1.0f, 1.0f, 1.0f}, 0.8f));

    // Lens: the gold sphere is sharp; E = 5 cm.
    scene.lens = raster::LensHint{0.05f, viewDepth(scene.cameras[0], target)};
    return scene;
}

} // namespace scenes::detail
