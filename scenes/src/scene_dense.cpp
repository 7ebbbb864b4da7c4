// builtin:dense — a performance scene with more than 1,000,000 triangles: an 8 x 8 grid of
// finely tessellated spheres and tori (each its own mesh and colour) over a tessellated ground.
// Generation is plain loops over sin/cos (well under a second in Release).
#include "generators.h"
#include "mesh_builder.h"
#include "procedural_texture.h"

#include <glm/gtc/matrix_transform.hpp>

#include <string>
#include <utility>

namespace scenes::detail {

raster::Scene makeDenseScene() {
    raster::Scene scene;
    scene.background = {0.45f, 0.55f, 0.7f};
    const int32_t repeat = addSampler(scene, {});

    const glm::vec3 target{0.0f, 0.0f, -0.5f};
    scene.cameras.push_back(lookAtCamera("dense", {0.0f, 8.0f, 17.5f}, target, 0.8f, 0.1f, 80.0f));

    // Ground: 128 x 128 cells (32,768 triangles) with a checker of 1.25 m cells.
    const int32_t ground_tex = addImage(
        scene, checkerImage("ground_checker", 256, 2, {190, 190, 185, 255}, {80, 85, 90, 255}));
    const int32_t ground_mat = addMaterial(scene, textured("ground", ground_tex, repeat, 0.9f));
    raster::Primitive ground;
    ground.material = ground_mat;
    appendGrid(ground, {-16.0f, 0.0f, 16.0f}, {32.0f, 0.0f, 0.0f}, {0.0f, 0.0f, -32.0f}, 128, 128,
               {12.8f, 12.8f});
    addInstance(scene, addMesh(scene, "ground", std::move(ground)));

    // Objects: 2.5 m apart; spheres have 144 x 72 (20,448 triangles), tori 144 x 48 (13,824).
    // 32 of each plus the ground: 1,129,472 triangles.
    constexpr int kGrid = 8;
    constexpr float kSpacing = 2.5f;
    for (int row = 0; row < kGrid; ++row) {
        for (int col = 0; col < kGrid; ++col) {
            const uint32_t id = static_cast<uint32_t>(row * kGrid + col);
            const glm::vec3 color{hashRange(id, 0, 0.1f, 0.9f), hashRange(id, 1, 0.1f, 0.9f),
                                  hashRange(id, 2, 0.1f, 0.9f)};
            raster::Material m =
                matte("object_" + std::to_string(id), color, hashRange(id, 3, 0.2f, 0.9f));
            m.metallic_factor = id % 5 == 0 ? 1.0f : 0.0f;
            raster::Primitive prim;
            prim.material = addMaterial(scene, std::move(m));
            const bool sphere = (row + col) % 2 == 0;
            const glm::vec3 cell{(static_cast<float>(col) - 3.5f) * kSpacing, 0.0f,
                                 (static_cast<float>(row) - 3.5f) * kSpacing};
            glm::mat4 world{1.0f};
            if (sphere) {
                appendSphere(prim, glm::vec3(0.0f), 0.9f, 144, 72);
                world = glm::translate(world, cell + glm::vec3(0.0f, 0.9f, 0.0f));
            } else if (row % 2 == 0) { // lying flat
                appendTorus(prim, glm::vec3(0.0f), 0.75f, 0.3f, 144, 48);
                world = glm::translate(world, cell + glm::vec3(0.0f, 0.3f, 0.0f));
            } else { // standing on its edge, facing the camera
                appendTorus(prim, glm::vec3(0.0f), 0.75f, 0.3f, 144, 48);
                world = glm::translate(world, cell + glm::vec3(0.0f, 1.05f, 0.0f));
                world = glm::rotate(world, 0.5f * kPi, glm::vec3(1.0f, 0.0f, 0.0f));
            }
            const std::string name = (sphere ? "sphere_" : "torus_") + std::to_string(id);
            addInstance(scene, addMesh(scene, name, std::move(prim)), world);
        }
    }

    scene.lights.push_back(
        directionalLight("sun", {-0.4f, -0.75f, -0.5f}, {1.0f, 0.95f, 0.9f}, 2.8f));
    scene.lights.push_back(directionalLight("sky", {0.3f, -0.4f, 0.85f}, {0.6f, 0.7f, 1.0f}, 0.7f));

    // Lens: focus on the grid's centre; E = 8 cm blurs the front and back rows.
    scene.lens = raster::LensHint{0.08f, viewDepth(scene.cameras[0], target)};
    return scene;
}

} // namespace scenes::detail
