// builtin:foliage — Selgrad et al. 2015, Fig. 10: plants modelled by alpha-masked quads (glTF
// alpha_mode MASK, double-sided), giving high depth complexity: near bushes are strongly
// blurred in front of an in-focus statue, more bushes and a hedge stand behind it.
// Leaf placement is a pure function of (bush, leaf) through hash32: no RNG state.
#include "generators.h"
#include "mesh_builder.h"
#include "procedural_texture.h"

#include <glm/geometric.hpp>

#include <array>
#include <cmath>
#include <utility>

namespace scenes::detail {
namespace {

struct Bush {
    glm::vec3 center;
    glm::vec3 radius; // ellipsoid semi-axes
    float leaf_size;  // leaf length, metres
    uint32_t leaves;
};

void appendBush(raster::Primitive& leaves, raster::Primitive& stems, const Bush& bush,
                uint32_t seed) {
    for (uint32_t i = 0; i < bush.leaves; ++i) {
        const uint32_t key = seed * 65536u + i;
        // Point in the ellipsoid: direction from two angles, radius biased to the outside.
        const float phi = hashRange(key, 0, 0.0f, 2.0f * kPi);
        const float cos_theta = hashRange(key, 1, -0.6f, 1.0f);
        const float sin_theta = std::sqrt(1.0f - cos_theta * cos_theta);
        const glm::vec3 dir{sin_theta * cosf64(phi), cos_theta, sin_theta * sinf64(phi)};
        const float r = 0.45f + 0.55f * hashUnit(key, 2);
        const glm::vec3 pos = bush.center + r * dir * bush.radius;
        // The blade points outwards and upwards, with a random roll around itself.
        const glm::vec3 along = glm::normalize(
            dir + glm::vec3(hashRange(key, 3, -0.5f, 0.5f), 0.6f, hashRange(key, 4, -0.5f, 0.5f)));
        const glm::vec3 helper =
            std::fabs(along.y) < 0.9f ? glm::vec3(0.0f, 1.0f, 0.0f) : glm::vec3(1.0f, 0.0f, 0.0f);
        const glm::vec3 e1 = glm::normalize(glm::cross(helper, along));
        const glm::vec3 e2 = glm::cross(along, e1);
        const float roll = hashRange(key, 5, 0.0f, kPi);
        const glm::vec3 across = cosf64(roll) * e1 + sinf64(roll) * e2;
        const float size = bush.leaf_size * hashRange(key, 6, 0.7f, 1.3f);
        const glm::vec4 tint{hashRange(key, 7, 0.7f, 1.15f), hashRange(key, 8, 0.8f, 1.1f),
                             hashRange(key, 9, 0.6f, 1.0f), 1.0f};
        appendLeaf(leaves, pos, along, across, size, tint);
        // Every sixteenth leaf gets a twig from inside the bush, below it, out to its stem.
        if (i % 16 == 0) {
            const glm::vec3 root = bush.center + 0.35f * (pos - bush.center) -
                                   glm::vec3(0.0f, 0.2f * bush.radius.y, 0.0f);
            appendCylinder(stems, root, pos, 0.004f + 0.01f * bush.leaf_size, 0.003f, 6, true);
        }
    }
}

} // namespace

raster::Scene makeFoliageScene() {
    raster::Scene scene;
    scene.background = {0.6f, 0.74f, 0.9f};
    const int32_t repeat = addSampler(scene, {});
    const int32_t clamped = addClampedSampler(scene);

    const glm::vec3 eye{0.0f, 1.15f, 0.0f};
    const glm::vec3 target{0.0f, 1.0f, -3.5f};
    scene.cameras.push_back(lookAtCamera("foliage", eye, target, 0.8f, 0.05f, 60.0f));

    // Leaves: one MASK material (alpha cut-off 0.5), double-sided, tinted per leaf by COLOR_0.
    const int32_t leaf_tex = addImage(scene, leafImage(256));
    const int32_t leaf_mat = addMaterial(scene, maskedLeaf(leaf_tex, clamped));
    const int32_t stem_mat = addMaterial(scene, matte("stem", {0.2f, 0.13f, 0.07f}, 0.9f));

    // Near bushes frame the view (0.7-1.6 m, strongly blurred), mid bushes flank the statue,
    // far bushes and a hedge stand behind it.
    constexpr std::array<Bush, 12> kBushes = {{
        {{-0.75f, 0.95f, -1.0f}, {0.5f, 0.55f, 0.35f}, 0.11f, 700},
        {{0.7f, 1.35f, -1.2f}, {0.45f, 0.5f, 0.35f}, 0.11f, 650},
        {{0.15f, 0.45f, -1.5f}, {0.55f, 0.35f, 0.3f}, 0.12f, 600},
        {{-0.2f, 1.9f, -1.6f}, {0.6f, 0.25f, 0.3f}, 0.12f, 450},
        {{-1.5f, 0.8f, -3.4f}, {0.6f, 0.8f, 0.5f}, 0.16f, 800},
        {{1.45f, 0.7f, -3.7f}, {0.6f, 0.7f, 0.5f}, 0.16f, 800},
        {{0.45f, 0.3f, -2.9f}, {0.35f, 0.3f, 0.3f}, 0.14f, 300},
        {{-2.6f, 1.2f, -6.5f}, {1.0f, 1.2f, 0.8f}, 0.22f, 700},
        {{2.4f, 1.1f, -7.0f}, {1.0f, 1.1f, 0.8f}, 0.22f, 700},
        {{0.0f, 1.3f, -9.5f}, {4.5f, 1.3f, 0.6f}, 0.28f, 1800},
        {{-6.0f, 1.5f, -9.0f}, {2.0f, 1.5f, 0.8f}, 0.28f, 600},
        {{6.0f, 1.5f, -9.0f}, {2.0f, 1.5f, 0.8f}, 0.28f, 600},
    }};
    raster::Primitive leaves;
    leaves.material = leaf_mat;
    raster::Primitive stems;
    stems.material = stem_mat;
    for (uint32_t b = 0; b < kBushes.size(); ++b)
        appendBush(leaves, stems, kBushes[b], b + 1);
    addInstance(scene, addMesh(scene, "stems", std::move(stems)));
    addInstance(scene, addMesh(scene, "leaves", std::move(leaves)));

    // The in-focus subject: a stone sphere on a pedestal with a small engraved plaque.
    const int32_t stone_tex = addImage(
        scene, checkerImage("stone_checker", 128, 8, {170, 165, 155, 255}, {120, 115, 110, 255}));
    const int32_t stone_mat = addMaterial(scene, textured("stone", stone_tex, repeat, 0.8f));
    raster::Primitive statue;
    statue.material = stone_mat;
    appendBox(statue, {0.0f, 0.4f, -3.5f}, {0.25f, 0.4f, 0.25f});
    appendSphere(statue, {0.0f, 1.1f, -3.5f}, 0.3f, 48, 24);
    addInstance(scene, addMesh(scene, "statue", std::move(statue)));
    raster::Image plaque_image = solidImage("plaque", 256, 128, {60, 50, 40, 255});
    drawTextCentered(plaque_image, "FOCUS", 128, 20, 6, {230, 200, 120, 255});
    drawTextCentered(plaque_image, "3.5 M", 128, 80, 4, {230, 200, 120, 255});
    const int32_t plaque_tex = addImage(scene, std::move(plaque_image));
    const int32_t plaque_mat = addMaterial(scene, textured("plaque", plaque_tex, clamped, 0.6f));
    raster::Primitive plaque;
    plaque.material = plaque_mat;
    const float pz = -3.5f + 0.26f; // 1 cm proud of the pedestal: no depth fighting
    appendQuad(plaque, {-0.2f, 0.45f, pz}, {0.2f, 0.45f, pz}, {0.2f, 0.65f, pz}, {-0.2f, 0.65f, pz},
               {0.0f, 0.0f, 1.0f});
    addInstance(scene, addMesh(scene, "plaque", std::move(plaque)));

    // Grass-coloured ground.
    const int32_t grass_mat = addMaterial(scene, matte("grass", {0.12f, 0.22f, 0.06f}, 0.95f));
    raster::Primitive ground;
    ground.material = grass_mat;
    appendGrid(ground, {-15.0f, 0.0f, 2.0f}, {30.0f, 0.0f, 0.0f}, {0.0f, 0.0f, -16.0f}, 6, 6);
    addInstance(scene, addMesh(scene, "ground", std::move(ground)));

    scene.lights.push_back(
        directionalLight("sun", {0.4f, -0.75f, -0.5f}, {1.0f, 0.95f, 0.85f}, 2.8f));
    scene.lights.push_back(
        directionalLight("sky", {-0.3f, -0.4f, 0.85f}, {0.6f, 0.7f, 1.0f}, 0.8f));

    // Lens: statue sharp at 3.5 m; E = 4 cm gives the nearest leaves a CoC of ~-20 px.
    scene.lens = raster::LensHint{0.04f, viewDepth(scene.cameras[0], {0.0f, 1.1f, -3.5f})};
    return scene;
}

} // namespace scenes::detail
