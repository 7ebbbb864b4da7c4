// Tests of the gather probe (dof/gather.h, probeGather; issue 22): after gather(), the probe
// re-runs one pixel's two passes (Zhou et al. 2007 §4.2, §5) on the kept scratch and records
// every tap. Its result is the rendered pixel bit for bit, and its taps add up to it.
#include "dof_test_util.h"

#include <dof/gather.h>
#include <dof/lens.h>
#include <raster/camera.h>
#include <scenes/builtin.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

namespace focal::test {
namespace {

constexpr uint32_t kW = 160, kH = 120;

struct Demo {
    raster::View view;
    dof::ThinLens lens;
    raster::Frame frame;
};

// builtin:demo, pinhole: a floor through every depth, objects in front of and behind the focus.
const Demo& demo() {
    static const Demo d = [] {
        raster::Result<raster::Scene> scene = scenes::makeBuiltinScene("demo");
        FOCAL_CHECK(scene.ok());
        Demo x;
        x.view = raster::viewFromCamera(scene->cameras.at(0), kW, kH);
        x.lens =
            dof::makeThinLens(x.view, scene->lens->aperture_radius, scene->lens->focus_distance);
        x.frame = render(*scene, x.view);
        return x;
    }();
    return d;
}

dof::GatherImage imageOf(const raster::Frame& f) {
    return {f.color.data(), dof::depthRefOf(f.depth), f.width, f.height};
}

bool sameBits(const float* a, const float* b, size_t n = 4) {
    return std::memcmp(a, b, n * sizeof(float)) == 0;
}

std::string rgbaText(const float* c) {
    return std::to_string(c[0]) + " " + std::to_string(c[1]) + " " + std::to_string(c[2]) + " " +
           std::to_string(c[3]);
}

// One pass replayed from its taps in the order the pass adds them (the centre first): Σ W·c /
// Σ W, or the centre itself when no neighbour had weight (§4.2 renormalisation).
void replay(const std::vector<dof::GatherTap>& taps, float* out) {
    ASSERT_FALSE(taps.empty());
    ASSERT_EQ(taps[0].offset, 0);
    float acc[4], wsum = taps[0].weight, nsum = 0.0f;
    for (int c = 0; c < 4; ++c)
        acc[c] = taps[0].weight * taps[0].rgba[c];
    for (size_t i = 1; i < taps.size(); ++i) {
        wsum += taps[i].weight;
        nsum += taps[i].weight;
        for (int c = 0; c < 4; ++c)
            acc[c] += taps[i].weight * taps[i].rgba[c];
    }
    for (int c = 0; c < 4; ++c)
        out[c] = nsum > 0.0f ? acc[c] / wsum + 0.0f : taps[0].rgba[c];
}

struct Variant {
    const char* name;
    dof::GatherSettings settings;
};

std::vector<Variant> variants() {
    std::vector<Variant> v;
    v.push_back({"default", {}});
    dof::GatherSettings s;
    s.skip_tiles = false;
    v.push_back({"skip_tiles off", s});
    s = {};
    s.simd = false;
    s.tile_size = 16;
    v.push_back({"scalar, tile 16", s});
    s = {};
    s.max_radius_px = 24.0f;
    s.leak_scale = 0.25f;
    s.min_radius_px = 1.0f;
    v.push_back({"R 24, leak 0.25, min radius 1", s});
    return v;
}

// The pixels probed: the corners, the centre, and a grid over the whole frame (edges of focus,
// background, foreground blur).
std::vector<std::pair<uint32_t, uint32_t>> probedPixels() {
    std::vector<std::pair<uint32_t, uint32_t>> p = {
        {0, 0}, {kW - 1, 0}, {0, kH - 1}, {kW - 1, kH - 1}, {kW / 2, kH / 2}};
    for (uint32_t y = 3; y < kH; y += 7)
        for (uint32_t x = 2; x < kW; x += 5)
            p.push_back({x, y});
    return p;
}

TEST(GatherProbe, ResultIsTheRenderedPixelAndTheTapsAddUpToIt) {
    const Demo& d = demo();
    const dof::GatherImage image = imageOf(d.frame);
    for (const Variant& v : variants()) {
        dof::GatherScratch scratch;
        std::vector<float> out, coc;
        raster::TaskPool pool(2);
        ASSERT_TRUE(
            dof::gather(image, d.lens, d.view, v.settings, out, &coc, &pool, &scratch).ok());
        uint32_t blurred = 0;
        for (const auto& [x, y] : probedPixels()) {
            SCOPED_TRACE(std::string(v.name) + " at " + std::to_string(x) + "," +
                         std::to_string(y));
            dof::GatherPixelProbe probe;
            const raster::Status st =
                dof::probeGather(image, d.lens, d.view, v.settings, scratch, x, y, probe);
            ASSERT_TRUE(st.ok()) << st.message();
            const size_t i = size_t(y) * kW + x;
            EXPECT_EQ(probe.x, x);
            EXPECT_EQ(probe.y, y);
            EXPECT_EQ(probe.coc_px, coc[i]);
            EXPECT_TRUE(sameBits(probe.rgba, &out[4 * i]))
                << rgbaText(probe.rgba) << " vs " << rgbaText(&out[4 * i]);
            EXPECT_TRUE(sameBits(probe.vertical_rgba, &scratch.vertical[4 * i]));
            // Each pass: the centre, then 2K samples; every weight the product of its factors.
            for (const auto* taps : {&probe.vertical, &probe.horizontal}) {
                const uint32_t reach =
                    taps == &probe.vertical ? probe.vertical_reach : probe.horizontal_reach;
                ASSERT_EQ(taps->size(), 1 + 2 * size_t(reach));
                for (const dof::GatherTap& t : *taps)
                    EXPECT_EQ(t.weight, (t.overlap * t.intensity) * t.leakage);
            }
            if (!v.settings.skip_tiles) {
                // The reference loop: every pixel over the full reach ceil(R) - 1.
                const uint32_t full = uint32_t(std::ceil(v.settings.max_radius_px)) - 1u;
                EXPECT_EQ(probe.vertical_reach, full);
                EXPECT_EQ(probe.horizontal_reach, full);
            }
            EXPECT_EQ(probe.copied_vertical, probe.vertical_reach == 0);
            EXPECT_EQ(probe.copied_horizontal, probe.horizontal_reach == 0);
            // The vertical pass reads the pinhole image down the column, the horizontal pass the
            // vertical output along the row (clamped to the edge).
            for (const dof::GatherTap& t : probe.vertical) {
                EXPECT_EQ(t.x, int32_t(x));
                EXPECT_EQ(t.y, std::clamp(int32_t(y) + t.offset, 0, int32_t(kH) - 1));
                EXPECT_TRUE(sameBits(t.rgba, &d.frame.color[4 * (size_t(t.y) * kW + x)]));
            }
            for (const dof::GatherTap& t : probe.horizontal) {
                EXPECT_EQ(t.y, int32_t(y));
                EXPECT_EQ(t.x, std::clamp(int32_t(x) + t.offset, 0, int32_t(kW) - 1));
                EXPECT_TRUE(
                    sameBits(t.rgba, &scratch.vertical[4 * (size_t(y) * kW + size_t(t.x))]));
            }
            // The taps, summed in the pass's order, give each pass's output exactly.
            float v_out[4], h_out[4];
            replay(probe.vertical, v_out);
            replay(probe.horizontal, h_out);
            EXPECT_TRUE(sameBits(v_out, probe.vertical_rgba));
            EXPECT_TRUE(sameBits(h_out, probe.rgba));
            blurred += probe.radius_px > 4.0f ? 1 : 0;
        }
        // The grid meets strong blur (InFocusPixelIsItsOwnOnlyTap probes copied pixels).
        EXPECT_GT(blurred, 10u) << v.name;
    }
}

// A frame at the focus distance: every CoC is below half a pixel.
raster::Frame focusedFrame(const raster::View& view, float distance) {
    raster::Frame f;
    f.width = view.width;
    f.height = view.height;
    f.color.resize(size_t(f.width) * f.height * 4);
    f.depth.resize(raster::DepthFormat::Float32, f.width, f.height);
    for (uint32_t i = 0; i < f.width * f.height; ++i) {
        for (uint32_t c = 0; c < 4; ++c)
            f.color[4 * i + c] = dof::hashToUnit(dof::hashWords(i, c, 7));
        f.depth.store(i, raster::depthFromDistance(view, distance));
    }
    return f;
}

TEST(GatherProbe, InFocusPixelIsItsOwnOnlyTap) {
    const raster::View view = pixelView(64, 48, 100.0f);
    const dof::ThinLens lens = dof::makeThinLens(view, 8.0f, 100.0f);
    const raster::Frame f = focusedFrame(view, 100.0f);
    for (bool skip : {true, false}) {
        dof::GatherSettings s;
        s.skip_tiles = skip;
        dof::GatherScratch scratch;
        std::vector<float> out;
        ASSERT_TRUE(dof::gather(imageOf(f), lens, view, s, out, nullptr, nullptr, &scratch).ok());
        for (const auto& [x, y] : {std::pair{0u, 0u}, {31u, 20u}, {63u, 47u}}) {
            dof::GatherPixelProbe probe;
            ASSERT_TRUE(dof::probeGather(imageOf(f), lens, view, s, scratch, x, y, probe).ok());
            EXPECT_LT(probe.radius_px, 0.5f);
            const float* in = &f.color[4 * (size_t(y) * 64 + x)];
            EXPECT_TRUE(sameBits(probe.rgba, in));
            if (skip) {
                // The block's reach is 0: both passes copy, the centre is the only tap.
                EXPECT_TRUE(probe.copied_vertical && probe.copied_horizontal);
                ASSERT_EQ(probe.vertical.size(), 1u);
                ASSERT_EQ(probe.horizontal.size(), 1u);
                EXPECT_EQ(probe.vertical[0].x, int32_t(x));
                EXPECT_EQ(probe.vertical[0].y, int32_t(y));
            } else {
                // The full reach is read, but no neighbour overlaps the centre: O(r_p) = 0.
                EXPECT_FALSE(probe.copied_vertical);
                for (const auto* taps : {&probe.vertical, &probe.horizontal})
                    for (size_t i = 1; i < taps->size(); ++i) {
                        EXPECT_EQ((*taps)[i].overlap, 0.0f);
                        EXPECT_EQ((*taps)[i].weight, 0.0f);
                    }
            }
        }
    }
}

TEST(GatherProbe, BadPixelOrScratchIsAnErrorNotACrash) {
    const Demo& d = demo();
    const dof::GatherImage image = imageOf(d.frame);
    const dof::GatherSettings s;
    dof::GatherPixelProbe probe;
    dof::GatherScratch empty;
    raster::Status st = dof::probeGather(image, d.lens, d.view, s, empty, 1, 1, probe);
    EXPECT_FALSE(st.ok());
    EXPECT_NE(st.message().find("scratch"), std::string::npos) << st.message();

    dof::GatherScratch scratch;
    std::vector<float> out;
    ASSERT_TRUE(dof::gather(image, d.lens, d.view, s, out, nullptr, nullptr, &scratch).ok());
    for (const auto& [x, y] : {std::pair{kW, 0u}, {0u, kH}, {~0u, ~0u}}) {
        st = dof::probeGather(image, d.lens, d.view, s, scratch, x, y, probe);
        EXPECT_FALSE(st.ok());
        EXPECT_NE(st.message().find("outside the 160x120 image"), std::string::npos)
            << st.message();
    }
    // The scratch of another frame (another lens: other radii) is refused.
    dof::ThinLens other = d.lens;
    other.aperture_radius *= 2.0f;
    st = dof::probeGather(image, other, d.view, s, scratch, kW / 2, kH / 2, probe);
    EXPECT_FALSE(st.ok());
    // Invalid settings are the settings' error.
    dof::GatherSettings bad;
    bad.max_radius_px = 0.0f;
    st = dof::probeGather(image, d.lens, d.view, bad, scratch, 0, 0, probe);
    EXPECT_FALSE(st.ok());
    EXPECT_NE(st.message().find("max_radius_px"), std::string::npos) << st.message();
}

} // namespace
} // namespace focal::test
