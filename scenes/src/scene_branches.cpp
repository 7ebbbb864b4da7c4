// builtin:branches — Lee, Eisemann & Seidel 2009, Fig. 8 (second row): the focal plane lies
// between two thin branches that cross in the image. Both are blurred, one in front of and one
// behind the focal plane; a physically correct lens makes them appear separated where they
// cross, which post-process methods working from one layer cannot reproduce.
#include "generators.h"
#include "mesh_builder.h"
#include "procedural_texture.h"

#include <utility>

namespace scenes::detail {
namespace {

// A branch from `a` to `b` with a few twigs; twig k leaves the branch at parameter t_k.
void appendBranch(raster::Primitive& prim, glm::vec3 a, glm::vec3 b, float ra, float rb,
                  uint32_t seed) {
    appendCylinder(prim, a, b, ra, rb, 20, true);
    for (uint32_t k = 0; k < 4; ++k) {
        const float t = 0.2f + 0.18f * static_cast<float>(k) + hashRange(seed, k, -0.04f, 0.04f);
        const glm::vec3 base = a + t * (b - a);
        const float r = ra + t * (rb - ra);
        // Twigs leave alternately up and down, mostly in the branch's plane (constant depth).
        const float side = k % 2 == 0 ? 1.0f : -1.0f;
        const glm::vec3 along = (b - a) * hashRange(seed, k + 10, 0.12f, 0.2f);
        const glm::vec3 out{-side * along.y, side * along.x,
                            hashRange(seed, k + 20, -0.03f, 0.03f)};
        appendCylinder(prim, base, base + along + out, 0.55f * r, 0.2f * r, 12, true);
    }
}

} // namespace

raster::Scene makeBranchesScene() {
    raster::Scene scene;
    scene.background = {0.62f, 0.74f, 0.9f};
    const int32_t repeat = addSampler(scene, {});

    // Camera at the origin looking down -Z; yfov 0.6 rad gives f_px = 970 at 800 x 600.
    scene.cameras.push_back(
        lookAtCamera("branches", {0.0f, 0.0f, 0.0f}, {0.0f, 0.0f, -1.0f}, 0.6f, 0.05f, 30.0f));

    const int32_t bark_tex = addImage(scene, barkImage(128));
    raster::Material front_bark = textured("bark_front", bark_tex, repeat, 0.9f);
    front_bark.base_color_factor = {0.85f, 0.7f, 0.55f, 1.0f};
    raster::Material back_bark = textured("bark_back", bark_tex, repeat, 0.9f);
    back_bark.base_color_factor = {0.55f, 0.55f, 0.6f, 1.0f};
    const int32_t front_mat = addMaterial(scene, std::move(front_bark));
    const int32_t back_mat = addMaterial(scene, std::move(back_bark));

    // Front branch at 1.2 m, lower left to upper right (radius 12 -> 6 mm, ~16 px wide).
    raster::Primitive front;
    front.material = front_mat;
    appendBranch(front, {-0.62f, -0.42f, -1.2f}, {0.62f, 0.4f, -1.2f}, 0.012f, 0.006f, 1);
    addInstance(scene, addMesh(scene, "branch_front", std::move(front)));

    // Back branch at 2.4 m, upper left to lower right (radius 22 -> 12 mm, similar width).
    raster::Primitive back;
    back.material = back_mat;
    appendBranch(back, {-1.25f, 0.78f, -2.4f}, {1.25f, -0.8f, -2.4f}, 0.022f, 0.012f, 2);
    addInstance(scene, addMesh(scene, "branch_back", std::move(back)));

    // Backdrop 10 m away: a soft two-tone checker with 1 m cells (strongly blurred).
    const int32_t sky_tex = addImage(
        scene, checkerImage("backdrop", 64, 2, {200, 222, 240, 255}, {150, 180, 205, 255}));
    const int32_t sky_mat = addMaterial(scene, textured("backdrop", sky_tex, repeat, 1.0f));
    raster::Primitive backdrop;
    backdrop.material = sky_mat;
    appendGrid(backdrop, {-8.0f, -6.0f, -10.0f}, {16.0f, 0.0f, 0.0f}, {0.0f, 12.0f, 0.0f}, 4, 3,
               {8.0f, 6.0f});
    addInstance(scene, addMesh(scene, "backdrop", std::move(backdrop)));

    scene.lights.push_back(
        directionalLight("sun", {0.3f, -0.6f, -0.75f}, {1.0f, 0.95f, 0.88f}, 2.6f));
    scene.lights.push_back(
        directionalLight("fill", {-0.5f, 0.2f, -0.85f}, {0.7f, 0.8f, 1.0f}, 0.9f));

    // Focal plane at 1.6 m, between the branches: with E = 6 cm the front branch has a CoC of
    // -12 px and the back one +12 px (1/1.6 is the mean of 1/1.2 and 1/2.4; Lee et al. Eq. 3).
    scene.lens = raster::LensHint{0.06f, 1.6f};
    return scene;
}

} // namespace scenes::detail
