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

// Counts below, at and above the worker count: the shares (some empty) cover every index once.
TEST(TaskPool, SharesCoverEveryIndexOnceForAnyCount) {
    for (const uint32_t threads : {2u, 3u, 5u, 8u})
        for (const uint32_t count : {1u, 2u, 3u, 4u, 7u, 8u, 9u, 63u, 130u}) {
            raster::TaskPool pool(threads);
            std::vector<std::atomic<int>> hits(count);
            pool.parallelFor(count, [&](uint32_t i, uint32_t) { hits[i].fetch_add(1); });
            for (uint32_t i = 0; i < count; ++i)
                EXPECT_EQ(hits[i].load(), 1)
                    << "threads " << threads << ", count " << count << ", index " << i;
        }
}

// The caller (worker 0, which always starts on its own share) stalled in its first index: the
// other workers take the rest of its share (from its back), so the job finishes. Without
// stealing that share would wait for the caller, and the stall, which waits for every other
// index, would end only at its timeout.
TEST(TaskPool, OtherWorkersFinishAStalledWorkersShare) {
    constexpr uint32_t kCount = 60;
    raster::TaskPool pool(3);
    std::vector<std::atomic<int>> hits(kCount);
    std::atomic<uint32_t> done{0};
    std::atomic<bool> timed_out{false};
    std::atomic<bool> stalled{false};
    pool.parallelFor(kCount, [&](uint32_t i, uint32_t worker) {
        if (worker == 0 && !stalled.exchange(true)) {
            const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(20);
            while (done.load() < kCount - 1)
                if (std::chrono::steady_clock::now() > until) {
                    timed_out = true;
                    break;
                }
        }
        hits[i].fetch_add(1);
        done.fetch_add(1);
    });
    EXPECT_FALSE(timed_out.load());
    for (uint32_t i = 0; i < kCount; ++i)
        EXPECT_EQ(hits[i].load(), 1) << "index " << i;
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
