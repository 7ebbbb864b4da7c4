// builtin:perforated — thin machined parts at several depths: a perforated metal grill (a sheet
// with 192 octagonal holes, 15 mm holes 5 mm apart: 21 and 7 px) 0.46-0.54 m from the lens, blurred
// by a CoC of ~25 px at 800 x 600; a gear with 24 thin teeth and a bore in front of the focal plane
// (-11 px), one in focus at 1.2 m, one behind (+8 px); and a checker wall 3 m away
// (+11 px). The holes and teeth are a few pixels wide: much thinner than their blur.
#include "generators.h"
#include "mesh_builder.h"
#include "procedural_texture.h"

#include <glm/ext/matrix_transform.hpp>

#include <utility>

namespace scenes::detail {

raster::Scene makePerforatedScene() {
    raster::Scene scene;
    scene.background = {0.45f, 0.5f, 0.55f};
    const int32_t repeat = addSampler(scene, {});

    // Camera at the origin looking down -Z; yfov 0.8 rad gives f_px = 709 at 800 x 600.
    scene.cameras.push_back(
        lookAtCamera("perforated", {0.0f, 0.0f, 0.0f}, {0.0f, 0.0f, -1.0f}, 0.8f, 0.05f, 10.0f));

    // Wall 3 m away: a checker with 15 cm cells.
    const int32_t checker = addImage(
        scene, checkerImage("wall_checker", 256, 8, {215, 205, 185, 255}, {70, 80, 95, 255}));
    const int32_t wall_mat = addMaterial(scene, textured("wall", checker, repeat, 0.9f));
    raster::Primitive wall;
    wall.material = wall_mat;
    appendGrid(wall, {-2.4f, -1.8f, -3.0f}, {4.8f, 0.0f, 0.0f}, {0.0f, 3.6f, 0.0f}, 4, 3,
               {4.0f, 3.0f});
    addInstance(scene, addMesh(scene, "wall", std::move(wall)));

    // Gears: flat, 24 teeth, facing the camera with a slight tilt; each a different colour.
    struct GearPlacement {
        const char* name;
        glm::vec3 center;
        float tip_radius;
        glm::vec3 color;
    };
    constexpr GearPlacement kGears[3] = {
        {"gear_near", {0.17f, -0.1f, -0.75f}, 0.07f, {0.75f, 0.55f, 0.25f}}, // brass, -11 px
        {"gear_focus", {0.12f, 0.12f, -1.2f}, 0.11f, {0.6f, 0.62f, 0.66f}},  // steel, in focus
        {"gear_far", {-0.25f, 0.35f, -2.2f}, 0.2f, {0.35f, 0.45f, 0.6f}},    // blue, +8 px
    };
    for (const GearPlacement& g : kGears) {
        const int32_t mat = addMaterial(scene, matte(g.name, g.color, 0.4f));
        raster::Primitive gear;
        gear.material = mat;
        // Teeth 0.1 of the radius deep; the bore is a third of the radius.
        appendGear(gear, 24, 0.9f * g.tip_radius, g.tip_radius, 0.33f * g.tip_radius,
                   0.15f * g.tip_radius);
        glm::mat4 world = glm::translate(glm::mat4(1.0f), g.center);
        world = glm::rotate(world, 0.35f, glm::vec3(0.3f, 1.0f, 0.0f));
        addInstance(scene, addMesh(scene, g.name, std::move(gear)), world);
    }

    // Grill: 12 x 16 cells of 2 cm with 1.5 cm holes, turned 20 degrees about +Y so its depth
    // runs from about 0.46 m (right edge) to 0.54 m (left edge); it covers the left of the frame.
    raster::Material metal = matte("grill", {0.3f, 0.31f, 0.33f}, 0.5f);
    metal.double_sided = true;
    const int32_t grill_mat = addMaterial(scene, std::move(metal));
    raster::Primitive grill;
    grill.material = grill_mat;
    appendPerforatedPlate(grill, {-0.12f, -0.16f, 0.0f}, 12, 16, 0.02f, 0.0075f);
    glm::mat4 grill_world = glm::translate(glm::mat4(1.0f), glm::vec3(-0.17f, 0.0f, -0.5f));
    grill_world = glm::rotate(grill_world, 0.35f, glm::vec3(0.0f, 1.0f, 0.0f));
    addInstance(scene, addMesh(scene, "grill", std::move(grill)), grill_world);

    scene.lights.push_back(
        directionalLight("key", {0.4f, -0.5f, -0.75f}, {1.0f, 0.96f, 0.9f}, 2.6f));
    scene.lights.push_back(
        directionalLight("fill", {-0.5f, 0.2f, -0.85f}, {0.7f, 0.8f, 1.0f}, 0.8f));

    // Lens: the middle gear is sharp at 1.2 m; E = 3 cm gives the grill a CoC of about -25 px
    // (C(d) = E f_px (1/d_f - 1/d), docs/dof/lens.md; Lee et al. 2009 Eq. 3).
    scene.lens = raster::LensHint{0.03f, 1.2f};
    return scene;
}

} // namespace scenes::detail
