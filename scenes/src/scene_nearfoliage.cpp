// builtin:nearfoliage — alpha-masked leaves (MASK, double-sided) on a few sprigs hanging into the
// view 0.3-1 m in front of the lens, blurred by a circle of confusion of up to ~50 px at
// 800 x 600, over an in-focus brick wall, sign and sphere 3 m away. Unlike builtin:foliage the
// leaves are few and large on screen: each blurred leaf edge is a cut-out silhouette crossing
// many layers of CoC. Leaf placement is a pure function of (sprig, leaf) through hash32.
#include "generators.h"
#include "mesh_builder.h"
#include "procedural_texture.h"

#include <glm/geometric.hpp>

#include <array>
#include <cmath>
#include <utility>

namespace scenes::detail {
namespace {

struct Sprig {
    glm::vec3 from, to; // the twig
    glm::vec3 facing;   // the leaves' blades lie roughly across this direction
    float leaf_size;    // metres
    uint32_t pairs;     // leaf pairs along the twig
};

void appendSprig(raster::Primitive& leaves, raster::Primitive& twigs, const Sprig& s,
                 uint32_t seed) {
    appendCylinder(twigs, s.from, s.to, 0.004f, 0.002f, 8, true);
    const glm::vec3 along_twig = glm::normalize(s.to - s.from);
    const glm::vec3 side = glm::normalize(glm::cross(along_twig, s.facing));
    for (uint32_t i = 0; i < 2 * s.pairs; ++i) {
        const uint32_t key = seed * 4096u + i;
        const float t = (static_cast<float>(i / 2) + 0.5f) / static_cast<float>(s.pairs);
        const glm::vec3 base = s.from + t * (s.to - s.from);
        // The blade leaves the twig sideways and forwards, alternating sides, with some wobble
        // in and out of the sprig's plane.
        const float sign = i % 2 == 0 ? 1.0f : -1.0f;
        const glm::vec3 along = glm::normalize(sign * side + 0.7f * along_twig +
                                               hashRange(key, 0, -0.35f, 0.35f) * s.facing);
        const glm::vec3 across = glm::normalize(glm::cross(s.facing, along));
        const float size = s.leaf_size * hashRange(key, 1, 0.75f, 1.2f);
        const glm::vec4 tint{hashRange(key, 2, 0.75f, 1.1f), hashRange(key, 3, 0.85f, 1.1f),
                             hashRange(key, 4, 0.65f, 1.0f), 1.0f};
        appendLeaf(leaves, base, along, across, size, tint);
    }
}

} // namespace

raster::Scene makeNearFoliageScene() {
    raster::Scene scene;
    scene.background = {0.6f, 0.72f, 0.88f};
    const int32_t repeat = addSampler(scene, {});
    const int32_t clamped = addClampedSampler(scene);

    const glm::vec3 eye{0.0f, 1.2f, 0.0f};
    scene.cameras.push_back(
        lookAtCamera("nearfoliage", eye, {0.0f, 1.2f, -3.0f}, 0.8f, 0.05f, 20.0f));

    // In focus, 3 m away: a brick wall, a sign and a checkered sphere on a box.
    const float wall_z = -3.2f;
    const int32_t brick_tex = addImage(scene, brickImage(256, 8));
    const int32_t brick_mat = addMaterial(scene, textured("bricks", brick_tex, repeat, 0.9f));
    raster::Primitive wall;
    wall.material = brick_mat;
    appendGrid(wall, {-3.0f, 0.0f, wall_z}, {6.0f, 0.0f, 0.0f}, {0.0f, 3.0f, 0.0f}, 6, 3,
               {6.0f, 3.0f});
    addInstance(scene, addMesh(scene, "wall", std::move(wall)));

    raster::Image sign_image = solidImage("sign", 512, 128, {232, 226, 210, 255});
    drawTextCentered(sign_image, "LEAVES 0.3 - 1 M AWAY", 256, 30, 4, {30, 60, 30, 255});
    drawTextCentered(sign_image, "SHARP SIGN AT 3 M", 256, 80, 3, {140, 30, 25, 255});
    addSign(scene, "sign", std::move(sign_image), clamped, 0.8f, {-0.8f, 1.35f}, {0.8f, 1.75f},
            wall_z + 0.02f);

    const int32_t ball_tex = addImage(
        scene, checkerImage("ball_checker", 128, 8, {210, 200, 180, 255}, {90, 70, 60, 255}));
    const int32_t ball_mat = addMaterial(scene, textured("ball", ball_tex, repeat, 0.6f));
    raster::Primitive ball;
    ball.material = ball_mat;
    appendBox(ball, {0.3f, 0.45f, -3.0f}, {0.2f, 0.45f, 0.2f});
    appendSphere(ball, {0.3f, 1.1f, -3.0f}, 0.2f, 48, 24);
    addInstance(scene, addMesh(scene, "ball", std::move(ball)));

    const int32_t floor_tex = addImage(
        scene, checkerImage("floor_checker", 128, 2, {170, 160, 140, 255}, {80, 75, 70, 255}));
    const int32_t floor_mat = addMaterial(scene, textured("floor", floor_tex, repeat, 0.9f));
    raster::Primitive floor;
    floor.material = floor_mat;
    appendGrid(floor, {-3.0f, 0.0f, 0.5f}, {6.0f, 0.0f, 0.0f}, {0.0f, 0.0f, wall_z - 0.5f}, 6, 4,
               {6.0f, 3.7f});
    addInstance(scene, addMesh(scene, "floor", std::move(floor)));

    // Near sprigs: from the top left (0.3-0.45 m), from the right (0.55-0.8 m) and up from the
    // bottom (0.6-1 m).
    const int32_t leaf_tex = addImage(scene, leafImage(256));
    const int32_t leaf_mat = addMaterial(scene, maskedLeaf(leaf_tex, clamped));
    const int32_t twig_mat = addMaterial(scene, matte("twig", {0.22f, 0.15f, 0.08f}, 0.9f));
    constexpr std::array<Sprig, 3> kSprigs = {{
        {{-0.22f, 1.42f, -0.3f}, {-0.02f, 1.24f, -0.45f}, {0.2f, 0.3f, 1.0f}, 0.055f, 5},
        {{0.55f, 1.3f, -0.55f}, {0.12f, 1.12f, -0.8f}, {-0.3f, 0.2f, 1.0f}, 0.08f, 5},
        {{-0.1f, 0.72f, -0.6f}, {-0.2f, 1.0f, -1.0f}, {0.1f, -0.2f, 1.0f}, 0.1f, 4},
    }};
    raster::Primitive leaves;
    leaves.material = leaf_mat;
    raster::Primitive twigs;
    twigs.material = twig_mat;
    for (uint32_t s = 0; s < kSprigs.size(); ++s)
        appendSprig(leaves, twigs, kSprigs[s], s + 1);
    addInstance(scene, addMesh(scene, "twigs", std::move(twigs)));
    addInstance(scene, addMesh(scene, "leaves", std::move(leaves)));

    scene.lights.push_back(
        directionalLight("sun", {0.4f, -0.7f, -0.55f}, {1.0f, 0.95f, 0.85f}, 2.8f));
    scene.lights.push_back(
        directionalLight("sky", {-0.3f, -0.4f, 0.85f}, {0.6f, 0.7f, 1.0f}, 0.8f));

    // Lens: sharp at 3 m; E = 24 mm gives the nearest leaves (0.3 m) a CoC of -51 px and the
    // farthest (1 m) -11 px at 800 x 600.
    scene.lens = raster::LensHint{0.024f, viewDepth(scene.cameras[0], {0.0f, 1.2f, -3.0f})};
    return scene;
}

} // namespace scenes::detail
