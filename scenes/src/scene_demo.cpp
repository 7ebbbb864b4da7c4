// builtin:demo — the overview scene the README renders: a checker ground, objects at several
// depths (textured, coloured, metallic, one emissive) and a thin railing close to the camera,
// strongly blurred in front of the in-focus centre sphere.
#include "generators.h"
#include "mesh_builder.h"
#include "procedural_texture.h"

#include <glm/gtc/matrix_transform.hpp>

#include <utility>

namespace scenes::detail {

raster::Scene makeDemoScene() {
    raster::Scene scene;
    scene.background = {0.52f, 0.66f, 0.88f};

    const int32_t repeat = addSampler(scene, {});
    const int32_t clamped = addClampedSampler(scene);

    const glm::vec3 eye{0.0f, 1.15f, 5.5f};
    const glm::vec3 target{0.0f, 0.7f, 0.0f};
    scene.cameras.push_back(lookAtCamera("demo", eye, target, 0.7f, 0.05f, 100.0f));

    // Ground: 40 m x 40 m, 1 m checker cells (the texture holds 2 x 2 cells).
    const int32_t ground_tex = addImage(
        scene, checkerImage("ground_checker", 256, 2, {205, 200, 190, 255}, {95, 100, 105, 255}));
    const int32_t ground_mat = addMaterial(scene, textured("ground", ground_tex, repeat, 0.9f));
    raster::Primitive ground;
    ground.material = ground_mat;
    appendGrid(ground, {-20.0f, 0.0f, 20.0f}, {40.0f, 0.0f, 0.0f}, {0.0f, 0.0f, -40.0f}, 20, 20,
               {20.0f, 20.0f});
    addInstance(scene, addMesh(scene, "ground", std::move(ground)));

    // Centre: a textured sphere at the focus distance.
    const int32_t ball_tex = addImage(
        scene, checkerImage("ball_checker", 256, 8, {240, 120, 30, 255}, {245, 240, 230, 255}));
    const int32_t ball_mat = addMaterial(scene, textured("ball", ball_tex, repeat, 0.45f));
    raster::Primitive ball;
    ball.material = ball_mat;
    appendSphere(ball, {0.0f, 0.0f, 0.0f}, 0.7f, 64, 32);
    addInstance(scene, addMesh(scene, "ball", std::move(ball)),
                glm::translate(glm::mat4(1.0f), target));

    // Left, a little behind: a brick-textured crate, turned 30 degrees.
    const int32_t brick_tex = addImage(scene, brickImage(256, 8));
    const int32_t brick_mat = addMaterial(scene, textured("brick", brick_tex, repeat, 0.85f));
    raster::Primitive crate;
    crate.material = brick_mat;
    appendBox(crate, {0.0f, 0.0f, 0.0f}, {0.55f, 0.55f, 0.55f});
    addInstance(scene, addMesh(scene, "crate", std::move(crate)),
                glm::rotate(glm::translate(glm::mat4(1.0f), {-1.8f, 0.55f, -1.4f}), 0.52f,
                            {0.0f, 1.0f, 0.0f}));

    // Right, further back: a blue matte sphere and a stack of two coloured boxes.
    const int32_t blue_mat = addMaterial(scene, matte("blue", {0.08f, 0.2f, 0.6f}, 0.6f));
    raster::Primitive blue;
    blue.material = blue_mat;
    appendSphere(blue, {1.9f, 0.55f, -2.8f}, 0.55f, 48, 24);
    addInstance(scene, addMesh(scene, "blue_sphere", std::move(blue)));
    const int32_t green_mat = addMaterial(scene, matte("green", {0.15f, 0.45f, 0.12f}, 0.7f));
    raster::Primitive stack;
    stack.material = green_mat;
    appendBox(stack, {3.6f, 0.6f, -5.5f}, {0.6f, 0.6f, 0.6f});
    appendBox(stack, {3.5f, 1.55f, -5.4f}, {0.35f, 0.35f, 0.35f});
    addInstance(scene, addMesh(scene, "box_stack", std::move(stack)));

    // Front right, just before the focal plane: a glossy red torus standing on its edge.
    const int32_t red_mat = addMaterial(scene, matte("red_glossy", {0.7f, 0.06f, 0.05f}, 0.3f));
    raster::Primitive ring;
    ring.material = red_mat;
    appendTorus(ring, glm::vec3(0.0f), 0.42f, 0.13f, 64, 24);
    glm::mat4 ring_world = glm::translate(glm::mat4(1.0f), {0.95f, 0.55f, 2.5f});
    ring_world = glm::rotate(ring_world, -0.7f, glm::vec3(0.0f, 1.0f, 0.0f));
    ring_world = glm::rotate(ring_world, 0.5f * kPi, glm::vec3(1.0f, 0.0f, 0.0f));
    addInstance(scene, addMesh(scene, "red_ring", std::move(ring)), ring_world);

    // Far back: a column and a sign with the project name (out of focus behind).
    const int32_t stone_mat = addMaterial(scene, matte("stone", {0.6f, 0.58f, 0.55f}, 0.9f));
    raster::Primitive columns;
    columns.material = stone_mat;
    appendCylinder(columns, {-3.4f, 0.0f, -7.0f}, {-3.4f, 3.2f, -7.0f}, 0.3f, 0.26f, 32, true);
    appendCylinder(columns, {3.0f, 0.0f, -10.0f}, {3.0f, 3.2f, -10.0f}, 0.3f, 0.26f, 32, true);
    addInstance(scene, addMesh(scene, "columns", std::move(columns)));
    raster::Image sign_image = solidImage("focal_sign", 512, 256, {30, 34, 48, 255});
    drawTextCentered(sign_image, "FOCAL", 256, 60, 14, {250, 250, 240, 255});
    drawTextCentered(sign_image, "DEPTH OF FIELD", 256, 190, 5, {250, 190, 60, 255});
    addSign(scene, "sign", std::move(sign_image), clamped, 0.7f, {-2.0f, 1.4f}, {2.0f, 3.4f},
            -8.0f);
    raster::Primitive sign_back;
    sign_back.material = stone_mat;
    appendBox(sign_back, {0.0f, 2.4f, -8.06f}, {2.05f, 1.05f, 0.05f});
    appendBox(sign_back, {-1.6f, 0.7f, -8.06f}, {0.08f, 0.7f, 0.05f});
    appendBox(sign_back, {1.6f, 0.7f, -8.06f}, {0.08f, 0.7f, 0.05f});
    addInstance(scene, addMesh(scene, "sign_frame", std::move(sign_back)));

    // Emissive orbs floating behind the focal plane (strength > 1: bokeh discs in EXR).
    raster::Material glow = matte("glow", {0.0f, 0.0f, 0.0f}, 1.0f);
    glow.emissive_factor = {12.0f, 7.0f, 2.5f};
    const int32_t glow_mat = addMaterial(scene, std::move(glow));
    raster::Primitive orb;
    orb.material = glow_mat;
    appendSphere(orb, {-1.3f, 1.9f, -3.5f}, 0.16f, 24, 12);
    appendSphere(orb, {5.0f, 2.2f, -14.0f}, 0.22f, 24, 12);
    addInstance(scene, addMesh(scene, "orbs", std::move(orb)));

    // Railing 1.3 m in front of the eye: posts, balusters and a handrail, dark painted metal.
    const int32_t rail_mat = addMaterial(scene, matte("railing", {0.05f, 0.05f, 0.055f}, 0.35f));
    raster::Primitive railing;
    railing.material = rail_mat;
    const float rail_z = 4.2f;
    for (int i = -10; i <= 10; ++i) {
        const float x = 0.11f * static_cast<float>(i);
        const float r = i % 5 == 0 ? 0.018f : 0.007f;
        appendCylinder(railing, {x, 0.0f, rail_z}, {x, 0.95f, rail_z}, r, r, 16, true);
    }
    appendCylinder(railing, {-1.3f, 0.95f, rail_z}, {1.3f, 0.95f, rail_z}, 0.02f, 0.02f, 24, true);
    appendCylinder(railing, {-1.3f, 0.12f, rail_z}, {1.3f, 0.12f, rail_z}, 0.01f, 0.01f, 16, true);
    addInstance(scene, addMesh(scene, "railing", std::move(railing)));

    scene.lights.push_back(
        directionalLight("sun", {-0.45f, -0.7f, -0.55f}, {1.0f, 0.95f, 0.88f}, 2.8f));
    scene.lights.push_back(directionalLight("sky", {0.3f, -0.5f, 0.8f}, {0.6f, 0.7f, 1.0f}, 0.7f));

    // Lens: the centre sphere is sharp; the railing's CoC is ~-27 px at 800 x 600.
    scene.lens = raster::LensHint{0.05f, viewDepth(scene.cameras[0], target)};
    return scene;
}

} // namespace scenes::detail
