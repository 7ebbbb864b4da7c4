// Tests of the multilayer probe (dof/multilayer.h, Multilayer::probe; issue 22): after a frame,
// the probe re-runs one pixel's traversal (Selgrad et al. 2015 §6.1) on the kept levels with a
// recorder. Its result is the rendered pixel bit for bit; its slices and reads add up to it.
#include "dof_test_util.h"

#include <dof/multilayer.h>
#include <raster/fragment_lists.h>
#include <raster/renderer.h>
#include <scenes/builtin.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

namespace focal::test {
namespace {

constexpr uint32_t kW = 160, kH = 120;

// A frame rendered with `ml`, which keeps it for probing.
dof::MultilayerImage renderWith(dof::Multilayer& ml, const raster::Scene& scene,
                                const raster::View& view, const dof::ThinLens& lens,
                                const dof::MultilayerSettings& settings, uint32_t threads = 2) {
    raster::TaskPool pool(threads);
    raster::Renderer renderer(pool);
    const dof::CollectFn collect = [&](const raster::FragmentListDesc& desc,
                                       raster::FragmentLists& lists) {
        return renderer.renderFragmentLists(scene, view, {}, desc, lists);
    };
    dof::MultilayerImage image;
    const raster::Status s =
        ml.render(view, lens, scene.background, settings, collect, pool, image, nullptr);
    EXPECT_TRUE(s.ok()) << s.message();
    return image;
}

bool sameBits(const float* a, const float* b) {
    return std::memcmp(a, b, 4 * sizeof(float)) == 0;
}

struct Variant {
    const char* name;
    dof::MultilayerSettings settings;
};

std::vector<Variant> variants() {
    std::vector<Variant> v;
    v.push_back({"default", {}});
    dof::MultilayerSettings s;
    s.filter = dof::LevelFilter::Box;
    s.mip_levels = 2;
    s.blend = dof::LayerBlend::Over;
    v.push_back({"box 2/auto, over", s});
    s = {};
    s.aperture.kind = dof::ApertureKind::Polygon; // near and far levels apart
    s.aperture.blades = 3;
    s.truncate = false;
    s.mean_depth = false;
    v.push_back({"triangle, no truncation, nearest depth", s});
    s = {};
    s.level_contributions = true;
    s.fragments_per_pixel = 0;
    v.push_back({"every fragment, level contributions", s});
    return v;
}

std::vector<std::pair<uint32_t, uint32_t>> probedPixels() {
    std::vector<std::pair<uint32_t, uint32_t>> p = {
        {0, 0}, {kW - 1, 0}, {0, kH - 1}, {kW - 1, kH - 1}, {kW / 2, kH / 2}};
    for (uint32_t y = 4; y < kH; y += 9)
        for (uint32_t x = 3; x < kW; x += 7)
            p.push_back({x, y});
    return p;
}

TEST(MultilayerProbe, ResultIsTheRenderedPixelAndTheReadsAddUpToIt) {
    for (const char* name : {"demo", "railing"}) {
        raster::Result<raster::Scene> scene = scenes::makeBuiltinScene(name);
        ASSERT_TRUE(scene.ok());
        const raster::View view = raster::viewFromCamera(scene->cameras[0], kW, kH);
        const dof::ThinLens lens =
            dof::makeThinLens(view, scene->lens->aperture_radius, scene->lens->focus_distance);
        const glm::vec3 bg = scene->background;
        for (const Variant& v : variants()) {
            dof::Multilayer ml;
            const dof::MultilayerImage image = renderWith(ml, *scene, view, lens, v.settings);
            uint32_t many_levels = 0;
            for (const auto& [x, y] : probedPixels()) {
                SCOPED_TRACE(std::string(name) + ", " + v.name + " at " + std::to_string(x) + "," +
                             std::to_string(y));
                dof::MultilayerPixelProbe probe;
                const raster::Status st = ml.probe(x, y, probe);
                ASSERT_TRUE(st.ok()) << st.message();
                const size_t p = size_t(y) * kW + x;
                EXPECT_TRUE(sameBits(probe.rgba, &image.rgba[4 * p]));
                // The collected list, as stored.
                ASSERT_EQ(probe.fragments.size(), size_t(ml.lists().count(p)));
                for (size_t i = 1; i < probe.fragments.size(); ++i)
                    EXPECT_LE(probe.fragments[i - 1].stored_depth, probe.fragments[i].stored_depth);
                // The blended slices, replayed in order, give the colour exactly; the reads, by
                // their weights, to float rounding.
                float c[3] = {0.0f, 0.0f, 0.0f};
                float coverage = 0.0f;
                for (const dof::MultilayerProbeSlice& s : probe.slices) {
                    if (!s.blended)
                        continue;
                    for (int i = 0; i < 3; ++i)
                        c[i] += s.k * (s.part[0][i] + s.part[1][i]);
                    coverage = s.coverage;
                }
                EXPECT_EQ(probe.coverage, std::min(coverage, 1.0f));
                const float rest = 1.0f - probe.coverage;
                const float bgc[3] = {bg.r, bg.g, bg.b};
                double from_reads[3] = {0.0, 0.0, 0.0};
                std::vector<uint8_t> levels_read(64, 0);
                for (const dof::MultilayerProbeRead& r : probe.reads) {
                    ASSERT_LE(r.blend, probe.slices.size());
                    if (!r.accepted) {
                        EXPECT_EQ(r.weight, 0.0f);
                        continue;
                    }
                    ASSERT_LT(r.blend, probe.slices.size());
                    const dof::MultilayerProbeSlice& s = probe.slices[r.blend];
                    EXPECT_TRUE(r.level == s.lo || r.level == s.hi);
                    EXPECT_EQ(r.segment, s.segment);
                    EXPECT_LE(r.depth, s.limit);
                    EXPECT_EQ(r.coc_px, dof::cocRadiusPx(lens, r.depth));
                    if (!s.blended) {
                        EXPECT_EQ(r.weight, 0.0f);
                    }
                    for (int i = 0; i < 3; ++i)
                        from_reads[i] += double(r.weight) * double(r.rgba[i]);
                    if (r.weight > 0.0f)
                        levels_read[r.level] = 1;
                }
                for (int i = 0; i < 3; ++i) {
                    EXPECT_EQ(probe.background[i], rest * bgc[i]);
                    EXPECT_EQ(probe.rgba[i], c[i] + probe.background[i]) << i;
                    EXPECT_NEAR(from_reads[i], double(c[i]), 1e-5 + 1e-5 * double(c[i])) << i;
                }
                EXPECT_EQ(probe.rgba[3], 1.0f);
                uint32_t count = 0;
                for (uint8_t l : levels_read)
                    count += l;
                many_levels += count >= 2 ? 1 : 0;
            }
            // The pixels probed include blurred ones that read filtered levels.
            EXPECT_GT(many_levels, 5u) << v.name;
        }
    }
}

raster::Scene wallAt(float d) {
    raster::Scene scene;
    const int32_t white = addMaterial(scene, flatMaterial({1.0f, 1.0f, 1.0f, 1.0f}));
    const int32_t dark = addMaterial(scene, flatMaterial({0.1f, 0.3f, 0.05f, 1.0f}));
    for (int j = -12; j < 12; ++j)
        for (int i = -12; i < 12; ++i)
            addQuad(scene, float(4 * i) * d / 100.0f, float(4 * j) * d / 100.0f,
                    float(4 * i + 4) * d / 100.0f, float(4 * j + 4) * d / 100.0f, d,
                    ((i + j) & 1) ? white : dark);
    return scene;
}

TEST(MultilayerProbe, InFocusPixelReadsItsOwnFragment) {
    const raster::View view = pixelView(64, 64, 100.0f);
    const raster::Scene scene = wallAt(100.0f); // at the focus distance
    const dof::ThinLens lens = dof::makeThinLens(view, 12.0f, 100.0f);
    dof::MultilayerSettings settings;
    settings.color_format = raster::ColorFormat::Float32;
    dof::Multilayer ml;
    const dof::MultilayerImage image = renderWith(ml, scene, view, lens, settings);
    for (const auto& [x, y] : {std::pair{0u, 0u}, {21u, 37u}, {63u, 63u}}) {
        dof::MultilayerPixelProbe probe;
        ASSERT_TRUE(ml.probe(x, y, probe).ok());
        ASSERT_EQ(probe.fragments.size(), 1u);
        EXPECT_NEAR(probe.fragments[0].coc_px, 0.0f, 1e-3f);
        // One read carries the pixel: the base level's own cell, weight 1 (a filtered level
        // may join with a weight t(d0) of C(d0)² ~ 0).
        uint32_t weighted = 0;
        for (const dof::MultilayerProbeRead& r : probe.reads)
            if (r.weight > 1e-4f) {
                ++weighted;
                EXPECT_EQ(r.level, 0u);
                EXPECT_EQ(r.kind, dof::LevelKind::Base);
                EXPECT_EQ(r.x, int32_t(x));
                EXPECT_EQ(r.y, int32_t(y));
                EXPECT_EQ(r.slice, 0u);
                EXPECT_NEAR(r.weight, 1.0f, 1e-4f);
            }
        EXPECT_EQ(weighted, 1u);
        EXPECT_EQ(probe.coverage, 1.0f);
        EXPECT_TRUE(sameBits(probe.rgba, &image.rgba[4 * (size_t(y) * 64 + x)]));
    }
}

TEST(MultilayerProbe, NoFrameOrBadPixelIsAnErrorNotACrash) {
    dof::Multilayer ml;
    dof::MultilayerPixelProbe probe;
    raster::Status st = ml.probe(0, 0, probe);
    EXPECT_FALSE(st.ok());
    EXPECT_NE(st.message().find("no frame"), std::string::npos) << st.message();

    const raster::View view = pixelView(32, 24, 100.0f);
    const raster::Scene scene = wallAt(150.0f);
    const dof::ThinLens lens = dof::makeThinLens(view, 12.0f, 100.0f);
    renderWith(ml, scene, view, lens, {});
    EXPECT_TRUE(ml.probe(31, 23, probe).ok());
    for (const auto& [x, y] : {std::pair{32u, 0u}, {0u, 24u}, {~0u, ~0u}}) {
        st = ml.probe(x, y, probe);
        EXPECT_FALSE(st.ok());
        EXPECT_NE(st.message().find("outside the 32x24 image"), std::string::npos) << st.message();
    }
    // A failed frame leaves nothing to probe.
    raster::TaskPool pool(0);
    dof::MultilayerImage image;
    const dof::CollectFn failing = [](const raster::FragmentListDesc&, raster::FragmentLists&) {
        return raster::Status::error("collection failed");
    };
    EXPECT_FALSE(ml.render(view, lens, scene.background, {}, failing, pool, image).ok());
    EXPECT_FALSE(ml.probe(0, 0, probe).ok());
}

} // namespace
} // namespace focal::test
