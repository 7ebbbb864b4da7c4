// builtin:glass — semi-transparent coloured panes (alpha_mode BLEND, alpha 0.3-0.5,
// double-sided) at several depths, in front of and behind the focal plane, over a textured
// wall and objects. Exercises transparency in the layered methods (Selgrad et al. 2015, Sec. 7,
// Fig. 12: "our method integrates transparency seamlessly").
#include "generators.h"
#include "mesh_builder.h"
#include "procedural_texture.h"

#include <array>
#include <string>
#include <utility>

namespace scenes::detail {

raster::Scene makeGlassScene() {
    raster::Scene scene;
    scene.background = {0.5f, 0.6f, 0.75f};
    const int32_t repeat = addSampler(scene, {});
    const int32_t clamped = addClampedSampler(scene);

    const glm::vec3 eye{0.0f, 1.4f, 0.0f};
    const glm::vec3 target{0.0f, 1.1f, -3.5f};
    scene.cameras.push_back(lookAtCamera("glass", eye, target, 0.8f, 0.05f, 40.0f));

    // Opaque detail first: brick wall at 4.5 m with a sign, floor, objects at 3.5 m.
    const int32_t brick_tex = addImage(scene, brickImage(256, 8));
    const int32_t brick_mat = addMaterial(scene, textured("brick", brick_tex, repeat, 0.9f));
    raster::Primitive wall;
    wall.material = brick_mat;
    appendGrid(wall, {-4.0f, 0.0f, -4.5f}, {8.0f, 0.0f, 0.0f}, {0.0f, 3.5f, 0.0f}, 8, 4,
               {8.0f, 3.5f});
    addInstance(scene, addMesh(scene, "wall", std::move(wall)));

    raster::Image sign_image = solidImage("glass_sign", 512, 128, {240, 236, 225, 255});
    drawTextCentered(sign_image, "ALPHA BLEND", 256, 16, 7, {25, 30, 70, 255});
    drawTextCentered(sign_image, "COLOURED GLASS AT 1.0 - 3.0 M", 256, 88, 3, {120, 30, 20, 255});
    addSign(scene, "sign", std::move(sign_image), clamped, 0.8f, {-1.4f, 1.75f}, {1.4f, 2.45f},
            -4.5f + 0.02f);

    const int32_t floor_tex = addImage(
        scene, checkerImage("floor_checker", 256, 2, {190, 185, 175, 255}, {70, 70, 75, 255}));
    const int32_t floor_mat = addMaterial(scene, textured("floor", floor_tex, repeat, 0.7f));
    raster::Primitive floor;
    floor.material = floor_mat;
    appendGrid(floor, {-4.0f, 0.0f, 1.0f}, {8.0f, 0.0f, 0.0f}, {0.0f, 0.0f, -5.5f}, 8, 6,
               {16.0f, 11.0f});
    addInstance(scene, addMesh(scene, "floor", std::move(floor)));

    const int32_t ball_tex = addImage(
        scene, checkerImage("ball_checker", 256, 8, {40, 90, 200, 255}, {240, 240, 235, 255}));
    const int32_t ball_mat = addMaterial(scene, textured("ball", ball_tex, repeat, 0.4f));
    raster::Primitive ball;
    ball.material = ball_mat;
    appendSphere(ball, {-0.55f, 0.45f, -3.5f}, 0.45f, 48, 24);
    addInstance(scene, addMesh(scene, "ball", std::move(ball)));
    const int32_t crate_mat = addMaterial(scene, matte("crate", {0.75f, 0.45f, 0.12f}, 0.6f));
    raster::Primitive crates;
    crates.material = crate_mat;
    appendBox(crates, {0.65f, 0.35f, -3.5f}, {0.35f, 0.35f, 0.35f});
    appendBox(crates, {0.65f, 0.95f, -3.5f}, {0.25f, 0.25f, 0.25f});
    addInstance(scene, addMesh(scene, "crates", std::move(crates)));

    // Panes, back to front (the order a sorted-blend pinhole render wants). Each is a
    // double-sided quad held by a frame of thin opaque bars.
    struct Pane {
        const char* name;
        glm::vec3 center;
        glm::vec2 half;  // half width, half height
        glm::vec4 color; // linear RGB + alpha
    };
    constexpr std::array<Pane, 4> kPanes = {{
        {"blue", {0.9f, 1.05f, -3.0f}, {0.45f, 0.55f}, {0.15f, 0.3f, 0.9f, 0.5f}},
        {"green", {0.15f, 1.3f, -2.1f}, {0.5f, 0.45f}, {0.2f, 0.8f, 0.3f, 0.35f}},
        {"red", {-0.6f, 1.15f, -1.3f}, {0.35f, 0.5f}, {0.9f, 0.15f, 0.1f, 0.4f}},
        {"clear", {0.45f, 1.0f, -0.9f}, {0.2f, 0.3f}, {0.85f, 0.9f, 1.0f, 0.3f}},
    }};
    // Opaque frames of thin bars first, so every BLEND surface comes last in instance order.
    const int32_t frame_mat = addMaterial(scene, matte("frame", {0.08f, 0.08f, 0.09f}, 0.5f));
    raster::Primitive frames;
    frames.material = frame_mat;
    for (const Pane& p : kPanes) {
        const glm::vec3 c = p.center;
        const glm::vec2 h = p.half;
        const float t = 0.012f; // bar half thickness
        appendBox(frames, {c.x, c.y + h.y + t, c.z}, {h.x + 2.0f * t, t, t});
        appendBox(frames, {c.x, c.y - h.y - t, c.z}, {h.x + 2.0f * t, t, t});
        appendBox(frames, {c.x - h.x - t, c.y, c.z}, {t, h.y, t});
        appendBox(frames, {c.x + h.x + t, c.y, c.z}, {t, h.y, t});
    }
    addInstance(scene, addMesh(scene, "frames", std::move(frames)));
    for (const Pane& p : kPanes) {
        raster::Material m = matte(std::string("glass_") + p.name, glm::vec3(p.color), 0.05f);
        m.base_color_factor = p.color;
        m.alpha_mode = raster::AlphaMode::Blend;
        m.double_sided = true;
        raster::Primitive pane;
        pane.material = addMaterial(scene, std::move(m));
        const glm::vec3 c = p.center;
        const glm::vec2 h = p.half;
        appendQuad(pane, {c.x - h.x, c.y - h.y, c.z}, {c.x + h.x, c.y - h.y, c.z},
                   {c.x + h.x, c.y + h.y, c.z}, {c.x - h.x, c.y + h.y, c.z}, {0.0f, 0.0f, 1.0f});
        addInstance(scene, addMesh(scene, std::string("pane_") + p.name, std::move(pane)));
    }

    scene.lights.push_back(
        directionalLight("sun", {0.35f, -0.6f, -0.7f}, {1.0f, 0.96f, 0.9f}, 2.6f));
    scene.lights.push_back(
        directionalLight("fill", {-0.4f, -0.3f, -0.85f}, {0.7f, 0.8f, 1.0f}, 0.8f));

    // Lens: objects at 3.5 m sharp; the red pane (1.3 m) has a CoC of ~-14 px, the clear one
    // (0.9 m) ~-23 px, the wall +2 px.
    scene.lens = raster::LensHint{0.04f, viewDepth(scene.cameras[0], target)};
    return scene;
}

} // namespace scenes::detail
