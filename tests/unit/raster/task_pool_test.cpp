#include <raster/task_pool.h>

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <new>
#include <stdexcept>
#include <thread>
#include <vector>

namespace {

TEST(TaskPool, RunsEveryIndexOnceForAnyThreadCount) {
    for (const uint32_t threads : {0u, 1u, 2u, 3u}) {
        raster::TaskPool pool(threads);
        std::vector<std::atomic<int>> hits(100);
        pool.parallelFor(100, [&](uint32_t i, uint32_t) { hits[i].fetch_add(1); });
        for (const std::atomic<int>& h : hits)
            EXPECT_EQ(h.load(), 1) << "threads " << threads;
    }
}

// Calls back to back (the workers still spinning) and after pauses longer than the spin (the
// workers asleep on the condition variable): every call runs each index once, and returns only
// when all are done.
TEST(TaskPool, CallsAfterSpinningAndSleepingRunEveryIndexOnce) {
    for (const uint32_t threads : {1u, 2u}) {
        raster::TaskPool pool(threads);
        std::vector<std::atomic<int>> hits(64);
        for (int call = 0; call < 60; ++call) {
            if (call % 10 == 9)
                std::this_thread::sleep_for(std::chrono::milliseconds(2));
            pool.parallelFor(64, [&](uint32_t i, uint32_t) { hits[i].fetch_add(1); });
            for (const std::atomic<int>& h : hits)
                ASSERT_EQ(h.load(), call + 1) << "threads " << threads << ", call " << call;
        }
    }
}

// Out of memory on a worker used to end in std::terminate; it must reach the caller, and the
// pool must stay usable afterwards.
TEST(TaskPool, RethrowsAWorkersExceptionOnTheCaller) {
    for (const uint32_t threads : {0u, 1u, 4u}) {
        raster::TaskPool pool(threads);
        EXPECT_THROW(pool.parallelFor(64,
                                      [](uint32_t i, uint32_t) {
                                          if (i == 37)
                                              throw std::bad_alloc();
                                      }),
                     std::bad_alloc)
            << "threads " << threads;
        std::atomic<uint32_t> sum{0};
        pool.parallelFor(10, [&](uint32_t i, uint32_t) { sum.fetch_add(i); });
        EXPECT_EQ(sum.load(), 45u);
    }
}

} // namespace
