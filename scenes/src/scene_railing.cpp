// builtin:railing — Selgrad et al. 2015, Fig. 1 (right): a railing close to the camera is
// blurred so strongly that the in-focus text behind it shows through the bars. Post-process
// methods that start from one sharp image cannot reveal the text hidden behind a bar.
#include "generators.h"
#include "mesh_builder.h"
#include "procedural_texture.h"

#include <utility>

namespace scenes::detail {

raster::Scene makeRailingScene() {
    raster::Scene scene;
    scene.background = {0.55f, 0.68f, 0.85f};

    const int32_t repeat = addSampler(scene, {});
    const int32_t clamped = addClampedSampler(scene);

    // Camera: eye height 1.2 m looking horizontally at the sign 4 m away.
    const glm::vec3 eye{0.0f, 1.2f, 0.0f};
    const float wall_z = -4.0f;
    const float sign_z = wall_z + 0.02f;
    scene.cameras.push_back(lookAtCamera("railing", eye, {0.0f, 1.2f, sign_z}, 0.8f, 0.05f, 50.0f));

    // Wall: a grey checker with 20 cm cells (the texture repeats every 40 cm).
    const int32_t checker = addImage(
        scene, checkerImage("wall_checker", 256, 2, {200, 200, 200, 255}, {90, 90, 96, 255}));
    const int32_t wall_mat = addMaterial(scene, textured("wall", checker, repeat));
    raster::Primitive wall;
    wall.material = wall_mat;
    appendGrid(wall, {-3.2f, 0.0f, wall_z}, {6.4f, 0.0f, 0.0f}, {0.0f, 3.2f, 0.0f}, 8, 4,
               {16.0f, 8.0f});
    addInstance(scene, addMesh(scene, "wall", std::move(wall)));

    // Sign with the text, 2 cm in front of the wall: 3 m x 0.75 m on a 1024 x 256 texture
    // (2.9 mm per texel; a pixel covers ~5.6 mm at 4 m).
    raster::Image sign_image = solidImage("sign_text", 1024, 256, {236, 228, 205, 255});
    fillRect(sign_image, 0, 0, 1024, 6, {60, 40, 30, 255});
    fillRect(sign_image, 0, 250, 1024, 256, {60, 40, 30, 255});
    drawTextCentered(sign_image, "DEPTH OF FIELD", 512, 30, 11, {20, 24, 60, 255});
    drawTextCentered(sign_image, "SHARP TEXT SEEN THROUGH A BLURRED RAILING", 512, 150, 4,
                     {150, 30, 25, 255});
    drawTextCentered(sign_image, "SELGRAD ET AL. 2015 - FIG. 1", 512, 200, 3, {40, 40, 40, 255});
    addSign(scene, "text", std::move(sign_image), clamped, 0.9f, {-1.5f, 0.85f}, {1.5f, 1.6f},
            sign_z);

    // Floor: a checker with 50 cm cells between the railing and the wall.
    const int32_t floor_tex = addImage(
        scene, checkerImage("floor_checker", 256, 2, {180, 170, 150, 255}, {60, 55, 50, 255}));
    const int32_t floor_mat = addMaterial(scene, textured("floor", floor_tex, repeat));
    raster::Primitive floor;
    floor.material = floor_mat;
    appendGrid(floor, {-3.2f, 0.0f, 1.0f}, {6.4f, 0.0f, 0.0f}, {0.0f, 0.0f, wall_z - 1.0f}, 8, 5,
               {6.4f, 5.0f});
    addInstance(scene, addMesh(scene, "floor", std::move(floor)));

    // Railing 0.7 m from the eye: vertical bars (1.2 cm thick, 10 cm apart) and a handrail.
    // At f_px = 709 a bar is ~12 px wide while its circle of confusion is ~25 px in radius.
    const float bar_z = -0.7f;
    const int32_t metal = addMaterial(scene, matte("railing_paint", {0.03f, 0.035f, 0.04f}, 0.4f));
    raster::Primitive bars;
    bars.material = metal;
    for (int i = -6; i <= 6; ++i) {
        const float x = 0.1f * static_cast<float>(i) + 0.03f;
        appendCylinder(bars, {x, 0.0f, bar_z}, {x, 1.42f, bar_z}, 0.006f, 0.006f, 16, true);
    }
    appendCylinder(bars, {-0.75f, 1.42f, bar_z}, {0.75f, 1.42f, bar_z}, 0.015f, 0.015f, 24, true);
    appendCylinder(bars, {-0.75f, 0.95f, bar_z}, {0.75f, 0.95f, bar_z}, 0.008f, 0.008f, 16, true);
    addInstance(scene, addMesh(scene, "bars", std::move(bars)));

    scene.lights.push_back(
        directionalLight("sun", {0.35f, -0.55f, -0.75f}, {1.0f, 0.96f, 0.9f}, 2.6f));
    scene.lights.push_back(
        directionalLight("fill", {-0.4f, -0.3f, -0.85f}, {0.7f, 0.8f, 1.0f}, 0.8f));

    // Lens: the sign is sharp; E = 3 cm gives the bars a CoC of ~-25 px (C(d) = E f_px
    // (1/d_f - 1/d), docs/dof/lens.md; Lee et al. 2009 Eq. 3).
    scene.lens = raster::LensHint{0.03f, viewDepth(scene.cameras[0], {0.0f, 1.2f, sign_z})};
    return scene;
}

} // namespace scenes::detail
