// builtin:bokeh — small, very bright emitters far behind the focal plane (emissive strength
// well above 1, so their bokeh discs keep their shape in linear EXR output) around a lit,
// in-focus object. Lee, Eisemann & Seidel 2009, Fig. 8 (bokeh row).
#include "generators.h"
#include "mesh_builder.h"
#include "procedural_texture.h"

#include <glm/gtc/matrix_transform.hpp>

#include <array>
#include <string>
#include <utility>

namespace scenes::detail {

raster::Scene makeBokehScene() {
    raster::Scene scene;
    scene.background = {0.004f, 0.006f, 0.014f};
    const int32_t repeat = addSampler(scene, {});

    const glm::vec3 eye{0.0f, 1.0f, 3.2f};
    const glm::vec3 target{0.0f, 0.75f, 0.0f};
    scene.cameras.push_back(lookAtCamera("bokeh", eye, target, 0.6f, 0.05f, 80.0f));

    // In focus: a checker-textured sphere on a pedestal, lit by a warm point light.
    const int32_t ball_tex = addImage(
        scene, checkerImage("ball_checker", 256, 8, {230, 60, 50, 255}, {235, 230, 220, 255}));
    const int32_t ball_mat = addMaterial(scene, textured("ball", ball_tex, repeat, 0.4f));
    raster::Primitive ball;
    ball.material = ball_mat;
    appendSphere(ball, target, 0.35f, 64, 32);
    addInstance(scene, addMesh(scene, "ball", std::move(ball)));
    const int32_t stone_mat = addMaterial(scene, matte("pedestal", {0.35f, 0.33f, 0.3f}, 0.8f));
    raster::Primitive pedestal;
    pedestal.material = stone_mat;
    appendBox(pedestal, {0.0f, 0.2f, 0.0f}, {0.3f, 0.2f, 0.3f});
    addInstance(scene, addMesh(scene, "pedestal", std::move(pedestal)));

    // Dark ground so the emitters are the only bright things in the distance.
    const int32_t ground_mat = addMaterial(scene, matte("ground", {0.05f, 0.05f, 0.06f}, 0.9f));
    raster::Primitive ground;
    ground.material = ground_mat;
    appendGrid(ground, {-30.0f, 0.0f, 6.0f}, {60.0f, 0.0f, 0.0f}, {0.0f, 0.0f, -46.0f}, 6, 6);
    addInstance(scene, addMesh(scene, "ground", std::move(ground)));

    // Emitters: one unit sphere mesh per colour, placed by instances. Black base colour and
    // emissive factors of 15..40 (linear), so only the emission shows.
    struct Tint {
        const char* name;
        glm::vec3 emission;
    };
    constexpr std::array<Tint, 5> kTints = {{{"warm_white", {40.0f, 32.0f, 22.0f}},
                                             {"amber", {40.0f, 20.0f, 4.0f}},
                                             {"red", {36.0f, 4.0f, 3.0f}},
                                             {"green", {6.0f, 30.0f, 10.0f}},
                                             {"blue", {5.0f, 12.0f, 40.0f}}}};
    std::array<uint32_t, kTints.size()> emitter_mesh{};
    for (size_t k = 0; k < kTints.size(); ++k) {
        raster::Material m = matte(std::string("emitter_") + kTints[k].name, glm::vec3(0.0f), 1.0f);
        m.emissive_factor = kTints[k].emission;
        raster::Primitive sphere;
        sphere.material = addMaterial(scene, std::move(m));
        appendSphere(sphere, glm::vec3(0.0f), 1.0f, 12, 6);
        emitter_mesh[k] =
            addMesh(scene, std::string("emitter_") + kTints[k].name, std::move(sphere));
    }
    auto place = [&](uint32_t mesh, glm::vec3 p, float radius) {
        addInstance(scene, mesh, glm::scale(glm::translate(glm::mat4(1.0f), p), glm::vec3(radius)));
    };
    // A scatter of city lights 15..30 m behind the object (depth-sorted by nothing; order is
    // the generator's), and two strings of fairy lights hanging in arcs 8 and 12 m back.
    for (uint32_t i = 0; i < 90; ++i) {
        const float z = hashRange(i, 0, -30.0f, -15.0f);
        const float x = hashRange(i, 1, -0.55f, 0.55f) * (3.2f - z);
        const float y = hashRange(i, 2, 0.3f, 0.62f) * (3.2f - z) * 0.5f;
        place(emitter_mesh[hash32(i + 77) % kTints.size()], {x, y, z}, 0.06f);
    }
    for (uint32_t s = 0; s < 2; ++s) {
        const float z = s == 0 ? -8.0f : -12.0f;
        const float half = s == 0 ? 4.5f : 6.5f;
        const uint32_t count = s == 0 ? 24 : 32;
        for (uint32_t i = 0; i <= count; ++i) {
            const float t = static_cast<float>(i) / static_cast<float>(count) * 2.0f - 1.0f;
            const float y = (s == 0 ? 2.6f : 4.0f) - 1.0f * (1.0f - t * t);
            place(emitter_mesh[s == 0 ? 0 : 1 + i % 2], {t * half, y, z}, 0.03f);
        }
    }

    scene.lights.push_back(pointLight("key", {1.6f, 2.4f, 2.0f}, {1.0f, 0.85f, 0.7f}, 25.0f));
    scene.lights.push_back(
        directionalLight("moon", {-0.3f, -0.5f, -0.8f}, {0.5f, 0.6f, 1.0f}, 0.25f));

    // Lens: E = 4 cm and f_px = 970; an emitter at 20 m has a CoC of ~+10 px, the fairy lights
    // at 8..12 m ~+7..9 px, the object stays sharp.
    scene.lens = raster::LensHint{0.04f, viewDepth(scene.cameras[0], target)};
    return scene;
}

} // namespace scenes::detail
