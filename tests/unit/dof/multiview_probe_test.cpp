// probeMultiview (multiview.h): one pixel's lens rays traced again after the frame with the
// tracer's own functions and a recorder give the bytes the frame wrote, and say what each ray did.
#include "dof_test_util.h"

#include <dof/multiview.h>
#include <scenes/builtin.h>

#include <gtest/gtest.h>

#include <cstring>
#include <string>

namespace focal::test {
namespace {

// A frame of renderMultiview with every buffer kept for the probe.
struct KeptFrame {
    raster::TaskPool pool{2};
    raster::Renderer renderer{pool};
    raster::Scene scene;
    raster::View view;
    dof::ThinLens lens;
    dof::ShadingInputs shading;
    raster::Frame pinhole;
    raster::LayeredTarget layers;
    dof::MultiviewScratch scratch;
    std::vector<float> rgba;
    dof::MultiviewStats stats;

    // Renders builtin scene `name` at width x height with its lens; false when it fails.
    bool render(const char* name, uint32_t width, uint32_t height,
                const dof::LensSampleSet& samples, const dof::MultiviewSettings& settings) {
        raster::Result<raster::Scene> s = scenes::makeBuiltinScene(name);
        if (!s.ok())
            return false;
        scene = std::move(*s);
        view = raster::viewFromCamera(scene.cameras[0], width, height);
        lens = dof::makeThinLens(view, scene.lens->aperture_radius, scene.lens->focus_distance);
        shading.scene = &scene;
        return renderAgain(samples, settings);
    }

    // Renders the loaded scene again into the kept buffers (with `lens` as it is now).
    bool renderAgain(const dof::LensSampleSet& samples, const dof::MultiviewSettings& settings) {
        raster::RenderOptions options;
        const dof::PinholeFn pin = pinholeFnOf(renderer, scene, options);
        const dof::LayersFn lay = layersFnOf(renderer, scene, options);
        raster::Result<dof::MultiviewStats> r =
            dof::renderMultiview(view, lens, samples, settings, shading, scene.background, pin, lay,
                                 pool, rgba, &pinhole, &layers, &scratch);
        if (!r.ok())
            return false;
        stats = *r;
        return true;
    }

    raster::Status probe(const dof::LensSampleSet& samples, const dof::MultiviewSettings& settings,
                         uint32_t x, uint32_t y, dof::MultiviewPixelProbe& out) const {
        return dof::probeMultiview(view, lens, samples, pinhole, layers, settings, shading, scratch,
                                   x, y, out);
    }
};

bool sameBits(const float* a, const float* b, size_t n) {
    return std::memcmp(a, b, n * sizeof(float)) == 0;
}

// What a grid of probed pixels covered, so the test shows it met every kind of pixel.
struct Seen {
    uint32_t in_focus = 0;   // resolved in focus by the frame (sharp)
    uint32_t silhouette = 0; // rays ended in two layers or more
    uint32_t cones = 0;      // (ray, layer) steps coloured by a cone (blur, §4.4)
    uint32_t culled = 0;     // some layer culled per tile or pixel (§4.3)
};

// Probes every `step`-th pixel of the frame and the four corners, and checks each against the
// frame: the same bytes, one record per lens sample, and the weighted mean of the rays' colours
// in sample order (endPixel's sums) giving the pixel. Counts what the pixels covered in `seen`.
void checkProbes(const KeptFrame& f, const dof::LensSampleSet& samples,
                 const dof::MultiviewSettings& s, uint32_t step, const std::string& what,
                 Seen& seen) {
    const uint32_t w = f.view.width, h = f.view.height;
    std::vector<glm::uvec2> pixels = {{0, 0}, {w - 1, 0}, {0, h - 1}, {w - 1, h - 1}};
    for (uint32_t y = step / 2; y < h; y += step)
        for (uint32_t x = step / 2; x < w; x += step)
            pixels.emplace_back(x, y);
    for (const glm::uvec2 p : pixels) {
        dof::MultiviewPixelProbe probe;
        const raster::Status st = f.probe(samples, s, p.x, p.y, probe);
        ASSERT_TRUE(st.ok()) << what << ": " << st.message();
        const std::string at = what + " pixel " + std::to_string(p.x) + "," + std::to_string(p.y);
        EXPECT_TRUE(sameBits(probe.rgba, f.rgba.data() + (size_t(p.y) * w + p.x) * 4, 4)) << at;
        ASSERT_EQ(probe.rays.size(), samples.size()) << at;
        ASSERT_EQ(probe.layers.size(), f.stats.layers) << at;
        double sum[3] = {0.0, 0.0, 0.0}, sum_w = 0.0;
        std::vector<bool> ended_in(f.stats.layers, false);
        for (uint32_t k = 0; k < probe.rays.size(); ++k) {
            const dof::MultiviewRayRecord& r = probe.rays[k];
            if (s.jitter == dof::JitterMode::None) {
                EXPECT_EQ(r.lens, samples.sample(k).position) << at;
            }
            if (r.discarded) {
                EXPECT_EQ(r.rgba[3], 0.0f) << at;
                continue;
            }
            EXPECT_EQ(r.rgba[3], 1.0f) << at;
            for (int c = 0; c < 3; ++c)
                sum[c] += double(r.weight) * double(r.rgba[c]);
            sum_w += double(r.weight);
            if (r.layer >= 0)
                ended_in[size_t(r.layer)] = true;
            for (const dof::MultiviewLayerStep& step_rec : r.steps)
                seen.cones += step_rec.result == dof::MultiviewStepResult::Cone ||
                                      step_rec.result == dof::MultiviewStepResult::MissedCone
                                  ? 1
                                  : 0;
            // The steps run front to back, and the last one leaves the colour the ray ended with
            // (before the background it sees).
            for (size_t i = 1; i < r.steps.size(); ++i)
                EXPECT_LT(r.steps[i - 1].layer, r.steps[i].layer) << at;
            if (!r.steps.empty() && r.layer >= 0) {
                EXPECT_EQ(r.steps.back().transmit, 0.0f) << at;
            }
        }
        for (int c = 0; sum_w > 0.0 && c < 3; ++c)
            EXPECT_EQ(float(sum[c] / sum_w), probe.rgba[c]) << at << " channel " << c;
        seen.in_focus += probe.in_focus ? 1 : 0;
        seen.silhouette += std::count(ended_in.begin(), ended_in.end(), true) >= 2 ? 1 : 0;
        for (const dof::MultiviewLayerCull c : probe.layers)
            if (c == dof::MultiviewLayerCull::Tile || c == dof::MultiviewLayerCull::Pixel) {
                ++seen.culled;
                break;
            }
    }
}

TEST(MultiviewProbe, ProbedPixelsAreTheFramesBytes) {
    // The traversals, jitter modes and sample counts; in focus, blurred in front and behind,
    // silhouettes (rays ending in two layers) and the image corners.
    struct Case {
        const char* scene;
        const char* config;
        uint32_t samples;
    };
    for (const Case c :
         {Case{"demo", "default", 32}, Case{"demo", "default", 16}, Case{"demo", "no paths", 16},
          Case{"demo", "false position", 16}, Case{"demo", "halton", 16}, Case{"demo", "noise", 16},
          Case{"glass", "default", 16}, Case{"reflective", "view dependent", 16},
          Case{"foliage", "discard", 16}}) {
        const std::string what =
            std::string(c.scene) + " " + c.config + " N=" + std::to_string(c.samples);
        const dof::LensSampleSet samples = makeSamples(c.samples);
        const dof::LensSampleSet seq = makeSamples(2 * c.samples, {}, dof::LensPattern::Halton);
        dof::MultiviewSettings s;
        s.skip_unblurred = false;
        const std::string config = c.config;
        if (config == "no paths")
            s.precompute_paths = false;
        if (config == "false position")
            s.traversal = dof::Traversal::FalsePosition;
        if (config == "halton")
            s.jitter = dof::JitterMode::Halton, s.sequence_2n = &seq;
        if (config == "noise")
            s.jitter = dof::JitterMode::Noise;
        if (config == "view dependent")
            s.view_dependent = true;
        if (config == "discard")
            s.offscreen = dof::OffscreenPolicy::Discard;
        KeptFrame f;
        ASSERT_TRUE(f.render(c.scene, 120, 90, samples, s)) << what;
        Seen seen;
        checkProbes(f, samples, s, 7, what, seen);
        // At N = 32 the demo's cones are no wider than a pixel (lambda |C| <= 1) at this size.
        if (config == "default" && std::string(c.scene) == "demo" && c.samples == 16) {
            EXPECT_GT(seen.in_focus, 0u) << what;
            EXPECT_GT(seen.silhouette, 0u) << what;
            EXPECT_GT(seen.cones, 0u) << what;
            EXPECT_GT(seen.culled, 0u) << what;
        }
    }
}

TEST(MultiviewProbe, FalsePositionStepsAreRecorded) {
    const dof::LensSampleSet samples = makeSamples(16);
    dof::MultiviewSettings s;
    s.skip_unblurred = false;
    s.traversal = dof::Traversal::FalsePosition;
    KeptFrame f;
    ASSERT_TRUE(f.render("demo", 96, 72, samples, s));
    uint32_t tested = 0, steps = 0;
    for (uint32_t y = 3; y < 72; y += 9)
        for (uint32_t x = 3; x < 96; x += 9) {
            dof::MultiviewPixelProbe probe;
            ASSERT_TRUE(f.probe(samples, s, x, y, probe).ok());
            for (const dof::MultiviewRayRecord& r : probe.rays)
                for (const dof::MultiviewLayerStep& st : r.steps) {
                    tested += st.tested ? 1 : 0;
                    steps += st.false_position_steps;
                    EXPECT_LE(st.false_position_steps, s.iterations);
                    EXPECT_LE(st.binary_steps, s.refine_steps);
                    if (st.tested) {
                        EXPECT_GT(st.fetches, 0u);
                    }
                }
        }
    EXPECT_GT(tested, 0u);
    EXPECT_GT(steps, 0u);
}

TEST(MultiviewProbe, DebugRaysAreTheProbesRays) {
    // MultiviewSettings::debug_rays (focal render --multiview-debug-out) is the probe of the
    // debug pixel, run at the end of the frame.
    const dof::LensSampleSet samples = makeSamples(16);
    dof::MultiviewSettings s;
    s.skip_unblurred = false;
    std::vector<dof::MultiviewRayRecord> debug;
    s.debug_x = 40;
    s.debug_y = 30;
    s.debug_rays = &debug;
    KeptFrame f;
    ASSERT_TRUE(f.render("demo", 96, 72, samples, s));
    dof::MultiviewPixelProbe probe;
    ASSERT_TRUE(f.probe(samples, s, 40, 30, probe).ok());
    ASSERT_EQ(debug.size(), probe.rays.size());
    for (size_t k = 0; k < debug.size(); ++k) {
        EXPECT_EQ(debug[k].layer, probe.rays[k].layer);
        EXPECT_EQ(debug[k].end_px, probe.rays[k].end_px);
        EXPECT_EQ(debug[k].steps.size(), probe.rays[k].steps.size());
        EXPECT_TRUE(sameBits(debug[k].rgba, probe.rays[k].rgba, 4));
    }
    // Outside the image: an error, for the debug pixel as for the probe.
    s.debug_x = 96;
    EXPECT_FALSE(f.render("demo", 96, 72, samples, s));
}

TEST(MultiviewProbe, RefusesWhatItCannotProbe) {
    const dof::LensSampleSet samples = makeSamples(16);
    dof::MultiviewSettings s;
    s.skip_unblurred = false;
    KeptFrame f;
    dof::MultiviewPixelProbe probe;
    // No frame yet.
    ASSERT_TRUE(f.render("demo", 64, 48, samples, s));
    dof::MultiviewScratch fresh;
    EXPECT_FALSE(dof::probeMultiview(f.view, f.lens, samples, f.pinhole, f.layers, s, f.shading,
                                     fresh, 0, 0, probe)
                     .ok());
    // Outside the image.
    EXPECT_FALSE(f.probe(samples, s, 64, 0, probe).ok());
    EXPECT_FALSE(f.probe(samples, s, 0, 48, probe).ok());
    // Another sample count than the frame's.
    EXPECT_FALSE(f.probe(makeSamples(8), s, 0, 0, probe).ok());
    EXPECT_TRUE(f.probe(samples, s, 63, 47, probe).ok());
}

TEST(MultiviewProbe, SkippedFrameGivesThePinholePixel) {
    // A pinhole lens: renderMultiview returns the pinhole image, and so does the probe.
    const dof::LensSampleSet samples = makeSamples(16);
    dof::MultiviewSettings s;
    KeptFrame f;
    ASSERT_TRUE(f.render("demo", 64, 48, samples, s));
    f.lens.aperture_radius = 0.0f;
    ASSERT_TRUE(f.renderAgain(samples, s));
    ASSERT_TRUE(f.stats.skipped);
    dof::MultiviewPixelProbe probe;
    ASSERT_TRUE(f.probe(samples, s, 10, 20, probe).ok());
    EXPECT_TRUE(probe.skipped);
    EXPECT_TRUE(probe.rays.empty());
    EXPECT_TRUE(sameBits(probe.rgba, f.rgba.data() + (20 * 64 + 10) * 4, 4));
}

} // namespace
} // namespace focal::test
