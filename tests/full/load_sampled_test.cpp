// Loading only what is sampled (issue 18) changes no pixel: on the third-party glTF scenes in
// /work/shared/scenes (skipped where absent), a render from a scene imported with only the
// texture roles its shading samples is bit-identical to one from a scene with every image
// decoded, for every shading mode; and the images imported are the same for any thread count.
#include "support/test_util.h"

#include <raster/camera.h>
#include <raster/gltf_import.h>
#include <raster/renderer.h>
#include <raster/task_pool.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

namespace {

constexpr raster::ShadingMode kShadingModes[] = {
    raster::ShadingMode::Material, raster::ShadingMode::Unlit, raster::ShadingMode::Lit};

class LoadSampled : public ::testing::TestWithParam<const char*> {
protected:
    void SetUp() override {
        path_ = std::string("/work/shared/scenes/") + GetParam() + "/glTF/" + GetParam() + ".gltf";
        if (!std::filesystem::exists(path_))
            GTEST_SKIP() << path_ << " not present";
    }

    raster::Scene import(const raster::ImportOptions& options) const {
        raster::Result<raster::Scene> scene = raster::importGltf(path_, options);
        EXPECT_TRUE(scene.ok()) << scene.status().message();
        return scene.ok() ? std::move(scene.value()) : raster::Scene{};
    }

    std::string path_;
};

raster::View viewOf(const raster::Scene& scene) {
    return scene.cameras.empty() ? raster::viewFramingBounds(raster::worldBounds(scene), 128, 96)
                                 : raster::viewFromCamera(scene.cameras[0], 128, 96);
}

TEST_P(LoadSampled, SamePixelsAsWithEveryImageDecoded) {
    raster::TaskPool pool(2);
    raster::ImportOptions every;
    every.pool = &pool;
    const raster::Scene full = import(every);
    ASSERT_FALSE(HasFailure());
    const raster::View view = viewOf(full);
    for (const raster::ShadingMode mode : kShadingModes) {
        raster::ImportOptions options = every;
        options.roles = raster::sampledTextureRoles(mode);
        const raster::Scene sampled = import(options);
        ASSERT_FALSE(HasFailure());
        raster::RenderOptions render;
        render.shading = mode;
        EXPECT_EQ(focal::test::hashFrame(focal::test::render(sampled, view, render, 2)),
                  focal::test::hashFrame(focal::test::render(full, view, render, 2)))
            << "shading " << int(mode);
    }
}

TEST_P(LoadSampled, SameImagesForEveryThreadCount) {
    raster::ImportOptions options;
    options.roles = raster::sampledTextureRoles(raster::ShadingMode::Material);
    const uint64_t reference = focal::test::hashImages(import(options));
    for (const uint32_t threads : {1u, 2u, 3u}) {
        raster::TaskPool pool(threads);
        options.pool = &pool;
        EXPECT_EQ(focal::test::hashImages(import(options)), reference) << threads << " threads";
    }
}

INSTANTIATE_TEST_SUITE_P(Shared, LoadSampled,
                         ::testing::Values("ToyCar", "StainedGlassLamp", "GlassVaseFlowers",
                                           "AlphaBlendModeTest"));

} // namespace
