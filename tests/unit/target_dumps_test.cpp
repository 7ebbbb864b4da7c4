// --dump-layers / --dump-fragments: the files written and what they hold (issue 5).
#include "apps/image_io.h"
#include "apps/target_dumps.h"
#include "support/test_util.h"

#include <raster/task_pool.h>
#include <scenes/builtin.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>

namespace focal::test {
namespace {

namespace fs = std::filesystem;

fs::path freshDir(const char* name) {
    const fs::path dir = fs::temp_directory_path() /
                         ("focal_dump_" + std::string(name) + "_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    return dir / "nested"; // not created yet: the dump creates it
}

TEST(TargetDumps, UniformInverseDepthBounds) {
    const std::vector<float> b = uniformInverseDepthBounds(1.0f, 4.0f, 3);
    ASSERT_EQ(b.size(), 4u);
    EXPECT_FLOAT_EQ(b[0], 1.0f);
    EXPECT_FLOAT_EQ(b[3], 4.0f);
    // Equal steps in 1/d: 1, 0.75, 0.5, 0.25.
    EXPECT_NEAR(1.0f / b[1], 0.75f, 1e-6f);
    EXPECT_NEAR(1.0f / b[2], 0.5f, 1e-6f);
}

TEST(TargetDumps, LayersAndFragmentsOfTheRailing) {
    raster::Result<raster::Scene> s = scenes::makeBuiltinScene("railing");
    ASSERT_TRUE(s.ok());
    const raster::View v = raster::viewFromCamera(s->cameras[0], 96, 72);
    raster::TaskPool pool(2);
    raster::Renderer r(pool);

    raster::LayeredTargetDesc desc;
    desc.bounds = uniformInverseDepthBounds(0.5f, 5.0f, 4);
    raster::LayeredTarget layers;
    ASSERT_TRUE(r.renderLayers(*s, v, {}, desc, layers).ok());
    const fs::path ldir = freshDir("layers");
    ASSERT_TRUE(dumpLayers(layers, v, ldir.string()).ok());
    for (int l = 0; l < 4; ++l) {
        const std::string stem = (ldir / ("layer_0" + std::to_string(l))).string();
        raster::Result<ImageData> c = readImage(stem + "_color.png");
        raster::Result<ImageData> d = readImage(stem + "_depth.exr");
        ASSERT_TRUE(c.ok() && d.ok()) << stem;
        EXPECT_EQ(c->width, 96u);
        EXPECT_EQ(c->channels, 4u);
        // Covered pixels have a positive distance inside the layer's overlapped interval.
        const raster::LayerInterval iv = raster::overlappedInterval(desc, uint32_t(l));
        for (float dist : d->pixels)
            if (dist > 0.0f) {
                EXPECT_GE(dist, iv.near_d * 0.999f);
                EXPECT_LE(dist, iv.far_d * 1.001f);
            }
    }
    nlohmann::json index = nlohmann::json::parse(std::ifstream(ldir / "layers.json"));
    EXPECT_EQ(index["layers"].size(), 4u);

    raster::FragmentLists lists;
    ASSERT_TRUE(r.renderFragmentLists(*s, v, {}, {}, lists).ok());
    const fs::path fdir = freshDir("fragments");
    ASSERT_TRUE(dumpFragments(lists, v, fdir.string(), 2).ok());
    raster::Result<ImageData> counts = readImage((fdir / "fragment_count.exr").string());
    ASSERT_TRUE(counts.ok());
    for (size_t p = 0; p < counts->pixels.size(); ++p)
        ASSERT_EQ(counts->pixels[p], float(lists.list_length[p]));
    EXPECT_TRUE(fs::exists(fdir / "fragment_count.png"));
    EXPECT_TRUE(fs::exists(fdir / "fragment_01_color.png"));
    EXPECT_FALSE(fs::exists(fdir / "fragment_02_color.png"));
    fs::remove_all(ldir.parent_path());
    fs::remove_all(fdir.parent_path());
}

} // namespace
} // namespace focal::test
