// builtin:nearsurface — a large, smooth, uniformly shaded machine part (a turned shaft with a
// flange and a domed end, CAD-like) 0.17-0.34 m from the lens, blurred by a circle of confusion
// of 17-40 px at 800 x 600 over an in-focus brick wall with a sign. The part's depth range spans
// more than 20 px of CoC, so a layered method slices one smooth surface into many layers; its
// shading gradient and its silhouette against the sharp wall show how those slices are joined.
#include "generators.h"
#include "mesh_builder.h"
#include "procedural_texture.h"

#include <glm/geometric.hpp>

#include <utility>

namespace scenes::detail {

raster::Scene makeNearSurfaceScene() {
    raster::Scene scene;
    scene.background = {0.5f, 0.55f, 0.6f};
    const int32_t repeat = addSampler(scene, {});
    const int32_t clamped = addClampedSampler(scene);

    // Camera at the origin looking down -Z; yfov 0.8 rad gives f_px = 709 at 800 x 600.
    scene.cameras.push_back(
        lookAtCamera("nearsurface", {0.0f, 0.0f, 0.0f}, {0.0f, 0.0f, -1.0f}, 0.8f, 0.02f, 10.0f));

    // In-focus wall 1.2 m away (bricks of ~6 cm) and a sign 1 cm in front of it.
    const float wall_z = -1.2f;
    const int32_t brick_tex = addImage(scene, brickImage(256, 8));
    const int32_t brick_mat = addMaterial(scene, textured("bricks", brick_tex, repeat, 0.9f));
    raster::Primitive wall;
    wall.material = brick_mat;
    appendGrid(wall, {-1.2f, -0.9f, wall_z}, {2.4f, 0.0f, 0.0f}, {0.0f, 1.8f, 0.0f}, 4, 3,
               {5.0f, 3.75f});
    addInstance(scene, addMesh(scene, "wall", std::move(wall)));

    raster::Image sign_image = solidImage("sign", 512, 256, {235, 230, 215, 255});
    fillRect(sign_image, 0, 0, 512, 8, {40, 50, 70, 255});
    fillRect(sign_image, 0, 248, 512, 256, {40, 50, 70, 255});
    drawTextCentered(sign_image, "NEAR PART", 256, 40, 8, {30, 40, 90, 255});
    drawTextCentered(sign_image, "BLURRED 40 PX IN FRONT", 256, 130, 3, {150, 30, 25, 255});
    drawTextCentered(sign_image, "OF A SHARP WALL", 256, 170, 3, {150, 30, 25, 255});
    addSign(scene, "sign", std::move(sign_image), clamped, 0.8f, {-0.1f, -0.05f}, {0.4f, 0.2f},
            wall_z + 0.01f);

    // The near part, smoothly shaded light grey: a shaft of radius 3 cm running from beyond the
    // lower-left corner of the frame (0.34 m away) towards the centre (0.17 m), a flange disc on
    // it and a domed end. Finely tessellated so the shading is a smooth gradient.
    const int32_t part_mat = addMaterial(scene, matte("part", {0.55f, 0.57f, 0.6f}, 0.45f));
    raster::Primitive part;
    part.material = part_mat;
    const glm::vec3 a{-0.3f, -0.11f, -0.34f};
    const glm::vec3 b{0.03f, -0.03f, -0.17f};
    const glm::vec3 axis = glm::normalize(b - a);
    appendCylinder(part, a, b, 0.03f, 0.03f, 64, false); // the dome closes it; `a` is off-screen
    appendSphere(part, b, 0.03f, 64, 32);
    const glm::vec3 flange = a + 0.55f * (b - a);
    appendCylinder(part, flange, flange + 0.008f * axis, 0.065f, 0.065f, 96, true);
    addInstance(scene, addMesh(scene, "part", std::move(part)));

    scene.lights.push_back(
        directionalLight("key", {0.45f, -0.6f, -0.65f}, {1.0f, 0.97f, 0.92f}, 2.6f));
    scene.lights.push_back(
        directionalLight("fill", {-0.5f, 0.3f, -0.8f}, {0.7f, 0.8f, 1.0f}, 0.7f));

    // Lens: the wall is sharp at 1.2 m; E = 11 mm gives the part's near end a CoC of -40 px and
    // its far end -17 px (C(d) = E f_px (1/d_f - 1/d), docs/dof/lens.md; Lee et al. 2009 Eq. 3).
    scene.lens = raster::LensHint{0.011f, viewDepth(scene.cameras[0], {0.0f, 0.0f, wall_z})};
    return scene;
}

} // namespace scenes::detail
