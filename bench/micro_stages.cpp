// Micro-benchmarks of the hot stages (issue 9 item 6), with Google Benchmark: geometry
// (transform/clip/cull), binning, tile raster coverage (unlit) and coverage + shading (material),
// layer decomposition (Lee et al. 2009 §4.2 layered rendering), fragment-list building (Selgrad
// et al. 2015 §4), the gather filter (Zhou et al. 2007), multiview ray traversal and multilayer
// list filtering (whole methods; their per-stage times are reported as counters), the error
// metrics, and the task pool's cost per parallelFor. The stages run inline (TaskPool(0)) on one
// thread at 400x300 from each scene's default camera, so their numbers are per-core costs. Run:
//   build/bench/focal_microbench --benchmark_filter=Binning
#include "apps/scene_source.h"
#include "raster/src/binning.h"
#include "raster/src/geometry.h"
#include "raster/src/light_kernel.h"

#include <dof/frame_renderer.h>
#include <dof/gather.h>
#include <dof/lens.h>
#include <dof/lens_samples.h>
#include <dof/metrics.h>
#include <raster/camera.h>
#include <raster/check.h>
#include <raster/fragment_lists.h>
#include <raster/layered_target.h>
#include <raster/renderer.h>
#include <raster/task_pool.h>

#include <benchmark/benchmark.h>

#include <atomic>
#include <chrono>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

namespace {

constexpr uint32_t kWidth = 400;
constexpr uint32_t kHeight = 300;

// One loaded scene with its default view and lens, built on first use and kept.
struct Setup {
    raster::Scene scene;
    raster::View view;
    dof::ThinLens lens;
};

const Setup& setupFor(const std::string& name) {
    static std::map<std::string, std::unique_ptr<Setup>> cache;
    auto& slot = cache[name];
    if (!slot) {
        raster::Result<raster::Scene> scene = focal::loadScene("builtin:" + name);
        FOCAL_CHECK(scene.ok());
        slot = std::make_unique<Setup>();
        slot->scene = std::move(*scene);
        slot->view = raster::viewFromCamera(slot->scene.cameras[0], kWidth, kHeight);
        const float aperture = slot->scene.lens ? slot->scene.lens->aperture_radius : 0.05f;
        const float focus =
            slot->scene.lens ? slot->scene.lens->focus_distance : slot->view.focus_distance;
        slot->view.focus_distance = focus;
        slot->lens = dof::makeThinLens(slot->view, aperture, focus);
    }
    return *slot;
}

const char* sceneName(int64_t i) {
    static const char* kScenes[] = {"demo", "railing", "foliage", "dense"};
    return kScenes[i];
}

void sceneArgs(benchmark::internal::Benchmark* b) {
    for (int i = 0; i < 4; ++i)
        b->Arg(i);
    b->Unit(benchmark::kMillisecond);
}

void BM_Geometry(benchmark::State& state) {
    const Setup& s = setupFor(sceneName(state.range(0)));
    state.SetLabel(sceneName(state.range(0)));
    raster::TaskPool pool(0);
    raster::GeometryState geometry;
    for (auto _ : state) {
        raster::runGeometry(pool, s.scene, s.view, geometry);
        benchmark::DoNotOptimize(geometry.chunks.data());
    }
}
BENCHMARK(BM_Geometry)->Apply(sceneArgs);

void BM_Binning(benchmark::State& state) {
    const Setup& s = setupFor(sceneName(state.range(0)));
    state.SetLabel(sceneName(state.range(0)));
    raster::TaskPool pool(0);
    raster::GeometryState geometry;
    raster::runGeometry(pool, s.scene, s.view, geometry);
    const raster::TileGrid grid = raster::makeTileGrid(kWidth, kHeight, 64);
    std::vector<raster::ChunkBins> bins;
    for (auto _ : state) {
        raster::binChunks(pool, geometry, grid, bins);
        benchmark::DoNotOptimize(bins.data());
    }
}
BENCHMARK(BM_Binning)->Apply(sceneArgs);

// Whole pinhole frame; the FrameStats split is reported as counters (ms per frame).
void rasterBench(benchmark::State& state, raster::ShadingMode shading) {
    const Setup& s = setupFor(sceneName(state.range(0)));
    state.SetLabel(sceneName(state.range(0)));
    raster::TaskPool pool(0);
    raster::Renderer renderer(pool);
    raster::RenderOptions options;
    options.shading = shading;
    raster::Frame frame;
    raster::FrameStats stats;
    double raster_ms = 0.0;
    for (auto _ : state) {
        FOCAL_CHECK(renderer.render(s.scene, s.view, options, frame, &stats).ok());
        raster_ms += stats.ms_raster;
    }
    state.counters["tile_raster_ms"] = raster_ms / double(state.iterations());
}
// Coverage + depth with trivial shading, then with the materials' shading.
void BM_RasterCoverageUnlit(benchmark::State& state) {
    rasterBench(state, raster::ShadingMode::Unlit);
}
void BM_RasterShadingMaterial(benchmark::State& state) {
    rasterBench(state, raster::ShadingMode::Material);
}
BENCHMARK(BM_RasterCoverageUnlit)->Apply(sceneArgs);
BENCHMARK(BM_RasterShadingMaterial)->Apply(sceneArgs);

// Layer decomposition: 8 layers uniform in 1/d between near focus and far (Lee et al. Eq. 4).
void BM_LayerDecomposition(benchmark::State& state) {
    const Setup& s = setupFor(sceneName(state.range(0)));
    state.SetLabel(sceneName(state.range(0)));
    raster::TaskPool pool(0);
    raster::Renderer renderer(pool);
    raster::LayeredTargetDesc desc;
    const float n = s.view.znear, f = s.view.zfar > 0.0f ? s.view.zfar : 1000.0f;
    for (int l = 0; l <= 8; ++l) {
        const float t = float(l) / 8.0f;
        desc.bounds.push_back(1.0f / ((1.0f - t) / n + t / f));
    }
    raster::LayeredTarget target;
    for (auto _ : state)
        FOCAL_CHECK(renderer.renderLayers(s.scene, s.view, {}, desc, target).ok());
}
BENCHMARK(BM_LayerDecomposition)->Apply(sceneArgs);

void BM_FragmentLists(benchmark::State& state) {
    const Setup& s = setupFor(sceneName(state.range(0)));
    state.SetLabel(sceneName(state.range(0)));
    raster::TaskPool pool(0);
    raster::Renderer renderer(pool);
    raster::FragmentListDesc desc;
    raster::FragmentLists lists;
    for (auto _ : state)
        FOCAL_CHECK(renderer.renderFragmentLists(s.scene, s.view, {}, desc, lists).ok());
}
BENCHMARK(BM_FragmentLists)->Apply(sceneArgs);

void BM_GatherFilter(benchmark::State& state) {
    const Setup& s = setupFor(sceneName(state.range(0)));
    state.SetLabel(sceneName(state.range(0)));
    raster::TaskPool pool(0);
    raster::Renderer renderer(pool);
    raster::Frame frame;
    FOCAL_CHECK(renderer.render(s.scene, s.view, {}, frame).ok());
    const dof::GatherImage image{frame.color.data(), dof::depthRefOf(frame.depth), kWidth, kHeight};
    dof::GatherSettings settings;
    std::vector<float> out;
    for (auto _ : state)
        FOCAL_CHECK(dof::gather(image, s.lens, s.view, settings, out).ok());
}
BENCHMARK(BM_GatherFilter)->Apply(sceneArgs);

// A method with its default settings through dof::FrameRenderer (kept between iterations, as
// `focal render --repeat` keeps it); its stage times become counters.
void methodBench(benchmark::State& state, const std::string& method) {
    const Setup& s = setupFor(sceneName(state.range(0)));
    state.SetLabel(sceneName(state.range(0)));
    raster::TaskPool pool(0);
    raster::Result<dof::LensSampleSet> samples =
        dof::LensSampleSet::create(dof::ApertureShape{}, dof::LensPattern::Hammersley, 32, 0);
    FOCAL_CHECK(samples.ok());
    dof::MethodSettings settings = dof::MultilayerMethod{{}, &*samples};
    if (method == "multiview")
        settings = dof::MultiviewMethod{{}, &*samples};
    const raster::RenderOptions options;
    std::map<std::string, double> stage_sum;
    dof::FrameRenderer frames(pool);
    std::vector<float> rgba(size_t(s.view.width) * s.view.height * 4);
    const dof::FrameImage image{rgba.data(), size_t(s.view.width) * 4, nullptr, 0};
    dof::FrameReport report;
    for (auto _ : state) {
        FOCAL_CHECK(frames.render(s.scene, s.view, s.lens, options, settings, image, &report).ok());
        for (const auto& [stage, ms] : report.stage_ms)
            stage_sum[stage] += ms;
    }
    for (const auto& [stage, ms] : stage_sum)
        state.counters[stage + "_ms"] = ms / double(state.iterations());
}
// Multiview = layer decomposition + N-buffers + lens-ray traversal (counter "tracing_ms").
void BM_MultiviewRayTraversal(benchmark::State& state) {
    methodBench(state, "multiview");
}
// Multilayer = fragment lists + level building + list filtering (Selgrad et al. §5).
void BM_MultilayerListFiltering(benchmark::State& state) {
    methodBench(state, "multilayer");
}
BENCHMARK(BM_MultiviewRayTraversal)->Apply(sceneArgs);
BENCHMARK(BM_MultilayerListFiltering)->Apply(sceneArgs);

void BM_Metrics(benchmark::State& state) {
    const Setup& s = setupFor("demo");
    raster::TaskPool pool(0);
    raster::Renderer renderer(pool);
    raster::Frame a, b;
    FOCAL_CHECK(renderer.render(s.scene, s.view, {}, a).ok());
    raster::View shifted = s.view;
    shifted.pixel_shift = {0.5f, 0.0f};
    FOCAL_CHECK(renderer.render(s.scene, shifted, {}, b).ok());
    const dof::ImageRef ra{a.color.data(), kWidth, kHeight, 4};
    const dof::ImageRef rb{b.color.data(), kWidth, kHeight, 4};
    for (auto _ : state) {
        raster::Result<dof::ErrorMetrics> m = dof::compareImages(ra, rb);
        FOCAL_CHECK(m.ok());
        benchmark::DoNotOptimize(m->ssim);
    }
    state.SetLabel("PSNR + SSIM, 400x300");
    state.SetItemsProcessed(state.iterations() * int64_t(kWidth) * kHeight);
}
BENCHMARK(BM_Metrics)->Unit(benchmark::kMillisecond);

// One TaskPool::parallelFor of two trivial tasks on a two-worker pool (the caller and one
// thread): the fixed cost a stage pays per call, which a frame pays about 40 times (multilayer).
// Arg 0: calls back to back; arg N: N microseconds of the caller's own work before each call,
// long enough for the worker to have gone to sleep.
void BM_TaskPoolRoundTrip(benchmark::State& state) {
    raster::TaskPool pool(2);
    const auto gap = std::chrono::microseconds(state.range(0));
    std::atomic<uint32_t> sum{0};
    for (auto _ : state) {
        if (gap.count() > 0) {
            state.PauseTiming();
            const auto until = std::chrono::steady_clock::now() + gap;
            while (std::chrono::steady_clock::now() < until) {
            }
            state.ResumeTiming();
        }
        pool.parallelFor(2, [&](uint32_t i, uint32_t) { sum.fetch_add(i); });
    }
    benchmark::DoNotOptimize(sum.load());
}
BENCHMARK(BM_TaskPoolRoundTrip)->Arg(0)->Arg(1000)->Unit(benchmark::kMicrosecond);

// The lighting kernel (SIMD build where the CPU has it) on 64 sets of random lanes, one after
// the other: args (blocks per call, directional lights). Items are lanes, so items/s compares
// one block against two (whose chains it interleaves) and one light against two.
void BM_LightKernel(benchmark::State& state) {
    const int blocks = int(state.range(0));
    const auto light_count = uint32_t(state.range(1));
    raster::Scene scene;
    for (uint32_t i = 0; i < light_count; ++i) {
        raster::Light sun;
        sun.direction = {0.3f + 0.2f * float(i), -1.0f, -0.5f};
        scene.lights.push_back(sun);
    }
    std::vector<raster::PreparedLight> lights;
    raster::prepareLights(scene, glm::vec3(0.0f, -1.0f, 0.0f), lights);
    std::minstd_rand rng(1);
    std::uniform_real_distribution<float> unit_dist(0.0f, 1.0f);
    auto unit = [&] { return unit_dist(rng); };
    constexpr int kSets = 64;
    std::vector<raster::LightLanes> io(kSets * 2);
    for (raster::LightLanes& b : io)
        for (int c = 0; c < 3; ++c)
            for (int l = 0; l < raster::kLightLanes; ++l) {
                b.albedo[c][l] = unit();
                b.emissive[c][l] = 0.0f;
                b.world[c][l] = 2.0f * unit() - 1.0f;
                b.normal[c][l] = 2.0f * unit() - 1.0f;
            }
    const raster::LightKernel kernel = raster::selectLightKernel(true);
    const raster::LightMaterial material{0.1f, 0.5f};
    const float eye[3] = {0.0f, 1.0f, 5.0f};
    int set = 0;
    for (auto _ : state) {
        kernel(lights.data(), light_count, material, eye, &io[size_t(2 * set)], blocks,
               raster::kLightLanes);
        set = (set + 1) % kSets;
    }
    benchmark::DoNotOptimize(io.data());
    state.SetItemsProcessed(state.iterations() * blocks * raster::kLightLanes);
}
BENCHMARK(BM_LightKernel)->ArgsProduct({{1, 2}, {1, 2}})->ArgNames({"blocks", "lights"});

} // namespace

BENCHMARK_MAIN();
