// Allocations of a second identical frame of dof::FrameRenderer, per method (issue 20 part 4).
// A program of its own: it replaces the global operator new, which would count every test of
// the executable it is linked into. The counts are printed and recorded (RecordProperty). The
// renderer and every method (multiview with the shared samples, Halton, noise and rotated
// jitter, per-ray shading and other options; multilayer with box or aperture levels, a
// polygon aperture, level contributions and other options) allocate nothing, with or without a
// report, and are asserted to; the second frame has the first one's bytes.
//
// The same program injects allocation failures (issue 20 part 4): the K-th allocation after
// arming fails (operator new throws std::bad_alloc), for every K a first frame of each method
// makes (strided when there are many), and the frame must end in a Status, never a crash or
// std::terminate, and leave the FrameRenderer able to render the next frame with the same bytes.
#include "support/test_util.h"

#include <dof/frame_renderer.h>
#include <raster/check.h>
#include <raster/renderer.h>
#include <scenes/builtin.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <new>
#include <optional>
#include <string>
#include <vector>

// The replaced operators below pair malloc with free; GCC, inlining them into the tests, takes
// that for a mismatch.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"

namespace {

std::atomic<bool> g_counting{false};
std::atomic<uint64_t> g_allocations{0};
std::atomic<uint64_t> g_bytes{0};
// Fault injection: while the countdown is positive, each allocation takes one off it, and the
// one that takes it to 0 fails (and sets g_failed).
std::atomic<int64_t> g_fail_countdown{0};
std::atomic<bool> g_failed{false};

void* allocate(size_t size, size_t alignment) {
    if (g_counting.load(std::memory_order_relaxed)) {
        g_allocations.fetch_add(1, std::memory_order_relaxed);
        g_bytes.fetch_add(size, std::memory_order_relaxed);
    }
    if (g_fail_countdown.load(std::memory_order_relaxed) > 0 &&
        g_fail_countdown.fetch_sub(1, std::memory_order_relaxed) == 1) {
        g_failed = true;
        return nullptr;
    }
    if (size == 0)
        size = 1;
    void* p = nullptr;
    if (alignment <= alignof(std::max_align_t)) {
        p = std::malloc(size);
    } else if (posix_memalign(&p, alignment, size) != 0) {
        p = nullptr;
    }
    return p;
}

} // namespace

void* operator new(size_t size) {
    if (void* p = allocate(size, 0))
        return p;
    throw std::bad_alloc();
}
void* operator new[](size_t size) {
    if (void* p = allocate(size, 0))
        return p;
    throw std::bad_alloc();
}
void* operator new(size_t size, std::align_val_t a) {
    if (void* p = allocate(size, size_t(a)))
        return p;
    throw std::bad_alloc();
}
void* operator new[](size_t size, std::align_val_t a) {
    if (void* p = allocate(size, size_t(a)))
        return p;
    throw std::bad_alloc();
}
void* operator new(size_t size, const std::nothrow_t&) noexcept {
    return allocate(size, 0);
}
void* operator new[](size_t size, const std::nothrow_t&) noexcept {
    return allocate(size, 0);
}
void* operator new(size_t size, std::align_val_t a, const std::nothrow_t&) noexcept {
    return allocate(size, size_t(a));
}
void* operator new[](size_t size, std::align_val_t a, const std::nothrow_t&) noexcept {
    return allocate(size, size_t(a));
}
void operator delete(void* p) noexcept {
    std::free(p);
}
void operator delete[](void* p) noexcept {
    std::free(p);
}
void operator delete(void* p, size_t) noexcept {
    std::free(p);
}
void operator delete[](void* p, size_t) noexcept {
    std::free(p);
}
void operator delete(void* p, std::align_val_t) noexcept {
    std::free(p);
}
void operator delete[](void* p, std::align_val_t) noexcept {
    std::free(p);
}
void operator delete(void* p, size_t, std::align_val_t) noexcept {
    std::free(p);
}
void operator delete[](void* p, size_t, std::align_val_t) noexcept {
    std::free(p);
}

namespace focal::test {
namespace {

struct Count {
    uint64_t allocations = 0;
    uint64_t bytes = 0;
};

template <class Fn> Count counted(Fn&& fn) {
    g_allocations = 0;
    g_bytes = 0;
    g_counting = true;
    fn();
    g_counting = false;
    return {g_allocations.load(), g_bytes.load()};
}

TEST(FrameRendererAllocations, CounterSeesAllocations) {
    // The counter itself can fail: a vector of 100 floats is one allocation of 400 bytes.
    const Count c = counted([] {
        std::vector<float> v(100);
        EXPECT_EQ(v.size(), 100u);
    });
    EXPECT_EQ(c.allocations, 1u);
    EXPECT_EQ(c.bytes, 400u);
}

// The demo scene at 96x64 with its lens, 16 Hammersley samples, and every method.
struct Case {
    Case() {
        raster::Result<raster::Scene> s = scenes::makeBuiltinScene("demo");
        FOCAL_CHECK(s.ok());
        scene = std::move(*s);
        view = raster::viewFromCamera(scene.cameras.at(0), 96, 64);
        view.focus_distance = scene.lens->focus_distance;
        lens = dof::makeThinLens(view, scene.lens->aperture_radius, scene.lens->focus_distance);
        raster::Result<dof::LensSampleSet> set =
            dof::LensSampleSet::create({}, dof::LensPattern::Hammersley, 16, 0);
        FOCAL_CHECK(set.ok());
        samples = std::move(*set);
        dof::ApertureShape pentagon;
        pentagon.kind = dof::ApertureKind::Polygon;
        pentagon.blades = 5;
        pentagon.rotation_deg = 10.0f;
        set = dof::LensSampleSet::create(pentagon, dof::LensPattern::Hammersley, 16, 0);
        FOCAL_CHECK(set.ok());
        polygon_samples = std::move(*set);
        dof::MultiviewSettings halton;
        halton.jitter = dof::JitterMode::Halton;
        methods = {{"pinhole", dof::PinholeMethod{}},
                   {"accum", dof::AccumMethod{{}, &samples, {}}},
                   {"gather", dof::GatherMethod{}},
                   {"multiview", dof::MultiviewMethod{{}, &samples}},
                   {"multiview_halton", dof::MultiviewMethod{halton, &samples}},
                   {"multilayer", dof::MultilayerMethod{{}, &samples}}};
        // Multiview's options that change what a frame builds (counted, not fault-injected).
        auto variant = [&](const char* name, auto&& configure) {
            dof::MultiviewSettings m;
            configure(m);
            variants.push_back({name, dof::MultiviewMethod{m, &samples}});
        };
        variant("multiview_noise", [](auto& m) { m.jitter = dof::JitterMode::Noise; });
        variant("multiview_rotate_discard_3_layers", [](auto& m) {
            m.jitter = dof::JitterMode::Rotate;
            m.offscreen = dof::OffscreenPolicy::Discard;
            m.layers = 3;
        });
        variant("multiview_false_position", [](auto& m) {
            m.traversal = dof::Traversal::FalsePosition;
            m.bound_init = true;
        });
        variant("multiview_no_culling", [](auto& m) { m.culling = false; });
        variant("multiview_no_cones", [](auto& m) {
            m.cone = false;
            m.precompute_paths = false;
        });
        variant("multiview_view_dependent", [](auto& m) { m.view_dependent = true; });
        // Multilayer's options that change what a frame builds (counted, not fault-injected).
        auto layered = [&](const char* name, const dof::LensSampleSet* lens_set, auto&& configure) {
            dof::MultilayerSettings m;
            configure(m);
            variants.push_back({name, dof::MultilayerMethod{m, lens_set}});
        };
        layered("multilayer_no_samples", nullptr, [](auto&) {});
        layered("multilayer_polygon", &polygon_samples, [](auto&) {});
        layered("multilayer_box_over", &samples, [](auto& m) {
            m.filter = dof::LevelFilter::Box;
            m.blend = dof::LayerBlend::Over;
        });
        layered("multilayer_all_fragments_stack_3", &samples, [](auto& m) {
            m.fragments_per_pixel = 0;
            m.mip_levels = 2;
            m.stack_levels = 3;
        });
        layered("multilayer_contributions_every_cell", &samples, [](auto& m) {
            m.level_contributions = true;
            m.skip_unread_cells = false;
            m.truncate = false;
            m.mean_depth = false;
        });
        layered("multilayer_float_no_skip_hidden", &samples, [](auto& m) {
            m.color_format = raster::ColorFormat::Float32;
            m.skip_hidden = false;
            m.aperture_grids = {3, 4, 5};
        });
        rgba.resize(size_t(view.width) * view.height * 4);
        depth.resize(size_t(view.width) * view.height);
        image = {rgba.data(), size_t(view.width) * 4, depth.data(), view.width};
    }
    Case(const Case&) = delete; // methods and image point into it
    // FNV-1a 64 over the colour and depth the last frame wrote.
    uint64_t hash() const {
        uint64_t h = 1469598103934665603ull;
        auto add = [&](const std::vector<float>& v) {
            const auto* bytes = reinterpret_cast<const unsigned char*>(v.data());
            for (size_t i = 0; i < v.size() * sizeof(float); ++i)
                h = (h ^ bytes[i]) * 1099511628211ull;
        };
        add(rgba);
        add(depth);
        return h;
    }

    raster::Scene scene;
    raster::View view;
    dof::ThinLens lens;
    dof::LensSampleSet samples;
    dof::LensSampleSet polygon_samples; // a pentagon: multilayer's near and far levels differ
    std::vector<std::pair<std::string, dof::MethodSettings>> methods, variants;
    std::vector<float> rgba, depth;
    dof::FrameImage image;
};

TEST(FrameRendererAllocations, SecondIdenticalFramePerMethod) {
    const Case setup;
    const raster::Scene* scene = &setup.scene;
    const raster::View& view = setup.view;
    const dof::ThinLens& lens = setup.lens;
    std::vector<std::pair<std::string, dof::MethodSettings>> methods = setup.methods;
    methods.insert(methods.end(), setup.variants.begin(), setup.variants.end());
    const dof::FrameImage image = setup.image;
    for (uint32_t threads : {0u, 2u}) {
        raster::TaskPool pool(threads);
        {
            // The baseline: a second Renderer::render into a kept frame, outside any method.
            raster::Renderer renderer(pool);
            raster::Frame frame;
            ASSERT_TRUE(renderer.render(*scene, view, {}, frame).ok());
            raster::Status second;
            const Count c = counted([&] { second = renderer.render(*scene, view, {}, frame); });
            ASSERT_TRUE(second.ok());
            EXPECT_EQ(c.allocations, 0u) << "Renderer::render, " << threads << " threads";
            std::printf("focal: second Renderer::render alone, %ux%u, %u threads: %llu "
                        "allocations, %llu bytes\n",
                        view.width, view.height, threads,
                        static_cast<unsigned long long>(c.allocations),
                        static_cast<unsigned long long>(c.bytes));
        }
        for (const auto& entry : methods) {
            // Not a structured binding: clang 14 cannot capture one in the lambdas below.
            const std::string& name = entry.first;
            const dof::MethodSettings& method = entry.second;
            dof::FrameRenderer frames(pool);
            dof::FrameReport report;
            ASSERT_TRUE(frames.render(*scene, view, lens, {}, method, image, &report).ok());
            const uint64_t first_hash = setup.hash();
            raster::Status second;
            const Count c = counted(
                [&] { second = frames.render(*scene, view, lens, {}, method, image, &report); });
            ASSERT_TRUE(second.ok()) << name << ": " << second.message();
            EXPECT_EQ(c.allocations, 0u) << name << ", " << threads << " threads";
            EXPECT_EQ(setup.hash(), first_hash) << name << ", " << threads << " threads";
            // Without a report: the frame renderer keeps its own, so a second such frame
            // allocates nothing either.
            ASSERT_TRUE(frames.render(*scene, view, lens, {}, method, image).ok());
            const Count no_report =
                counted([&] { second = frames.render(*scene, view, lens, {}, method, image); });
            ASSERT_TRUE(second.ok()) << name << ": " << second.message();
            EXPECT_EQ(no_report.allocations, 0u)
                << name << " without a report, " << threads << " threads";
            EXPECT_EQ(setup.hash(), first_hash) << name << ", " << threads << " threads";
            std::printf("focal: second %s frame, %ux%u, %u threads: %llu allocations, %llu "
                        "bytes\n",
                        name.c_str(), view.width, view.height, threads,
                        static_cast<unsigned long long>(c.allocations),
                        static_cast<unsigned long long>(c.bytes));
            const std::string key = name + "_threads" + std::to_string(threads);
            ::testing::Test::RecordProperty(key + "_allocations", std::to_string(c.allocations));
            ::testing::Test::RecordProperty(key + "_bytes", std::to_string(c.bytes));
        }
    }
}

// The K-th allocation of a first frame fails, for K = 1, 2, ... up to the `first` allocations a
// clean first frame makes (strided to at most 150 values of K, or FOCAL_FAULT_TRIALS; 0 tries
// every K): the frame returns an out-of-memory Status, or succeeds with the clean frame's bytes
// (`clean`) when that allocation was not needed after all; either way the next frame on the same
// objects succeeds with the clean bytes. `make()` returns fresh objects (a std::unique_ptr) for
// one attempt, `render(objects)` renders the frame and `hash(objects)` hashes what it wrote.
template <class Make, class Render, class Hash>
void failEachAllocation(const std::string& label, uint64_t first, uint64_t clean, Make&& make,
                        Render&& render, Hash&& hash) {
    const char* trials_env = std::getenv("FOCAL_FAULT_TRIALS");
    const uint64_t max_trials = trials_env ? std::strtoull(trials_env, nullptr, 10) : 150;
    const uint64_t stride =
        max_trials == 0 ? 1 : std::max<uint64_t>(1, (first + max_trials - 1) / max_trials);
    uint64_t trials = 0, statuses = 0;
    for (uint64_t k = 1; k <= first; k += stride, ++trials) {
        auto objects = make();
        g_failed = false;
        g_fail_countdown = int64_t(k);
        const raster::Status s = render(*objects);
        g_fail_countdown = 0;
        if (!s.ok()) {
            ++statuses;
            EXPECT_TRUE(g_failed) << label << ", allocation " << k << ": " << s.message();
            EXPECT_NE(s.message().find("out of memory"), std::string::npos)
                << label << ", allocation " << k << ": " << s.message();
        } else {
            EXPECT_EQ(hash(*objects), clean) << label << ", allocation " << k << " failed";
        }
        const raster::Status again = render(*objects);
        ASSERT_TRUE(again.ok()) << label << ", after allocation " << k
                                << " failed: " << again.message();
        EXPECT_EQ(hash(*objects), clean) << label << ", after allocation " << k << " failed";
    }
    std::printf("focal: %s: a first frame makes %llu allocations; %llu of them failed in turn "
                "(stride %llu), %llu ended in an out-of-memory Status\n",
                label.c_str(), static_cast<unsigned long long>(first),
                static_cast<unsigned long long>(trials), static_cast<unsigned long long>(stride),
                static_cast<unsigned long long>(statuses));
}

// failEachAllocation for a FrameRenderer's first frame, per method, at 0 and 2 threads.
TEST(FrameRendererAllocations, FailedAllocationIsAStatus) {
    Case c;
    for (uint32_t threads : {0u, 2u}) {
        raster::TaskPool pool(threads);
        for (const auto& entry : c.methods) {
            const dof::MethodSettings& method = entry.second;
            const auto make = [&] { return std::make_unique<dof::FrameRenderer>(pool); };
            const auto render = [&](dof::FrameRenderer& frames) {
                return frames.render(c.scene, c.view, c.lens, {}, method, c.image);
            };
            const auto hash = [&](const dof::FrameRenderer&) { return c.hash(); };
            uint64_t first = 0;
            {
                const auto frames = make();
                raster::Status s;
                first = counted([&] { s = render(*frames); }).allocations;
                ASSERT_TRUE(s.ok()) << entry.first << ": " << s.message();
            }
            failEachAllocation(entry.first + ", " + std::to_string(threads) + " threads", first,
                               c.hash(), make, render, hash);
        }
    }
}

// failEachAllocation for dof::Multilayer::render called directly (no FrameRenderer around it),
// with the renderer's fragment-list collection as its callback: on a fresh object, and on a
// warm one that rendered a smaller frame before (its kept buffers are then resized part way
// when the allocation fails).
TEST(FrameRendererAllocations, FailedAllocationInMultilayerRenderIsAStatus) {
    Case c;
    dof::MultilayerSettings settings;
    settings.aperture = c.samples.shape();
    settings.aperture_second_moment = dof::apertureSecondMoment(c.samples);
    const raster::View small = raster::viewFromCamera(c.scene.cameras.at(0), 48, 32);
    const dof::ThinLens small_lens =
        dof::makeThinLens(small, c.lens.aperture_radius, c.lens.focus_distance);
    for (uint32_t threads : {0u, 2u}) {
        raster::TaskPool pool(threads);
        struct Objects {
            explicit Objects(raster::TaskPool& p) : renderer(p) {}
            raster::Renderer renderer;
            dof::Multilayer multilayer;
            dof::MultilayerImage image;
        };
        const auto renderView = [&](Objects& o, const raster::View& view,
                                    const dof::ThinLens& lens) {
            const struct {
                raster::Renderer& renderer;
                const raster::Scene& scene;
                const raster::View& view;
            } call{o.renderer, c.scene, view};
            const dof::CollectFn collect = [&call](const raster::FragmentListDesc& desc,
                                                   raster::FragmentLists& lists) {
                return call.renderer.renderFragmentLists(call.scene, call.view, {}, desc, lists);
            };
            return o.multilayer.render(view, lens, c.scene.background, settings, collect, pool,
                                       o.image);
        };
        const auto render = [&](Objects& o) { return renderView(o, c.view, c.lens); };
        // FNV-1a 64 over the image's colour and depth.
        const auto hash = [](const Objects& o) {
            uint64_t h = 1469598103934665603ull;
            for (const std::vector<float>* v : {&o.image.rgba, &o.image.depth}) {
                const auto* bytes = reinterpret_cast<const unsigned char*>(v->data());
                for (size_t i = 0; i < v->size() * sizeof(float); ++i)
                    h = (h ^ bytes[i]) * 1099511628211ull;
            }
            return h;
        };
        for (bool warm : {false, true}) {
            const auto make = [&] {
                auto o = std::make_unique<Objects>(pool);
                if (warm)
                    FOCAL_CHECK(renderView(*o, small, small_lens).ok());
                return o;
            };
            uint64_t first = 0, clean = 0;
            {
                const auto o = make();
                raster::Status s;
                first = counted([&] { s = render(*o); }).allocations;
                ASSERT_TRUE(s.ok()) << s.message();
                clean = hash(*o);
            }
            failEachAllocation(std::string("Multilayer::render, ") + (warm ? "warm" : "fresh") +
                                   ", " + std::to_string(threads) + " threads",
                               first, clean, make, render, hash);
        }
    }
}

// The same for the lens resolution with autofocus on a focus pixel (FrameRenderer::resolveLens
// renders the pinhole frame through FrameRenderer::pinhole).
TEST(FrameRendererAllocations, FailedAllocationInResolveLensIsAStatus) {
    Case c;
    dof::LensRequest request;
    request.focus_pixel = glm::uvec2(c.view.width / 2, c.view.height / 2);
    for (uint32_t threads : {0u, 2u}) {
        raster::TaskPool pool(threads);
        float clean = 0.0f;
        uint64_t first = 0;
        {
            dof::FrameRenderer frames(pool);
            std::optional<raster::Result<dof::ResolvedLens>> r;
            first = counted([&] {
                        r.emplace(frames.resolveLens(request, c.scene, c.view, {}));
                    }).allocations;
            ASSERT_TRUE(r->ok()) << r->status().message();
            clean = (*r)->lens.focus_distance;
        }
        for (uint64_t k = 1; k <= first; ++k) {
            dof::FrameRenderer frames(pool);
            g_failed = false;
            g_fail_countdown = int64_t(k);
            const raster::Result<dof::ResolvedLens> r =
                frames.resolveLens(request, c.scene, c.view, {});
            g_fail_countdown = 0;
            if (!r.ok())
                EXPECT_NE(r.status().message().find("out of memory"), std::string::npos)
                    << "allocation " << k << ": " << r.status().message();
            else
                EXPECT_EQ(r->lens.focus_distance, clean) << "allocation " << k << " failed";
            const raster::Result<dof::ResolvedLens> again =
                frames.resolveLens(request, c.scene, c.view, {});
            ASSERT_TRUE(again.ok()) << again.status().message();
            EXPECT_EQ(again->lens.focus_distance, clean);
        }
        std::printf("focal: resolveLens with a focus pixel, %u threads: %llu allocations, each "
                    "failed in turn\n",
                    threads, static_cast<unsigned long long>(first));
    }
}

} // namespace
} // namespace focal::test
