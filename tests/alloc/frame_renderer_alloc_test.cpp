// Allocations of a second identical frame of dof::FrameRenderer, per method (issue 20 part 4).
// A program of its own: it replaces the global operator new, which would count every test of
// the executable it is linked into. The counts are printed and recorded (RecordProperty). The
// renderer, pinhole, accum, gather and multiview (with the shared samples and with Halton jitter)
// allocate nothing and are asserted to; multilayer's count is not yet zero (issue 20 part 4's
// goal) and is only printed.
#include "support/test_util.h"

#include <dof/frame_renderer.h>
#include <raster/check.h>
#include <raster/renderer.h>
#include <scenes/builtin.h>

#include <gtest/gtest.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <string>
#include <vector>

namespace {

std::atomic<bool> g_counting{false};
std::atomic<uint64_t> g_allocations{0};
std::atomic<uint64_t> g_bytes{0};

void* allocate(size_t size, size_t alignment) {
    if (g_counting.load(std::memory_order_relaxed)) {
        g_allocations.fetch_add(1, std::memory_order_relaxed);
        g_bytes.fetch_add(size, std::memory_order_relaxed);
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

TEST(FrameRendererAllocations, SecondIdenticalFramePerMethod) {
    raster::Result<raster::Scene> scene = scenes::makeBuiltinScene("demo");
    ASSERT_TRUE(scene.ok());
    raster::View view = raster::viewFromCamera(scene->cameras.at(0), 96, 64);
    view.focus_distance = scene->lens->focus_distance;
    const dof::ThinLens lens =
        dof::makeThinLens(view, scene->lens->aperture_radius, scene->lens->focus_distance);
    raster::Result<dof::LensSampleSet> samples =
        dof::LensSampleSet::create({}, dof::LensPattern::Hammersley, 16, 0);
    ASSERT_TRUE(samples.ok());
    dof::MultiviewSettings halton;
    halton.jitter = dof::JitterMode::Halton;
    const std::vector<std::pair<std::string, dof::MethodSettings>> methods = {
        {"pinhole", dof::PinholeMethod{}},
        {"accum", dof::AccumMethod{{}, &*samples, {}}},
        {"gather", dof::GatherMethod{}},
        {"multiview", dof::MultiviewMethod{{}, &*samples}},
        {"multiview_halton", dof::MultiviewMethod{halton, &*samples}},
        {"multilayer", dof::MultilayerMethod{{}, &*samples}}};
    std::vector<float> rgba(size_t(view.width) * view.height * 4);
    const dof::FrameImage image{rgba.data(), size_t(view.width) * 4, nullptr, 0};
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
        for (const auto& [name, method] : methods) {
            dof::FrameRenderer frames(pool);
            dof::FrameReport report;
            ASSERT_TRUE(frames.render(*scene, view, lens, {}, method, image, &report).ok());
            raster::Status second;
            const Count c = counted(
                [&] { second = frames.render(*scene, view, lens, {}, method, image, &report); });
            ASSERT_TRUE(second.ok()) << name << ": " << second.message();
            if (name != "multilayer") {
                EXPECT_EQ(c.allocations, 0u) << name << ", " << threads << " threads";
            }
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

} // namespace
} // namespace focal::test
