#include <raster/task_pool.h>

#include <gtest/gtest.h>

#include <atomic>
#include <new>
#include <stdexcept>
#include <vector>

namespace {

TEST(TaskPool, RunsEveryIndexOnceForAnyThreadCount) {
    for (const uint32_t threads : {0u, 1u, 3u}) {
        raster::TaskPool pool(threads);
        std::vector<std::atomic<int>> hits(100);
        pool.parallelFor(100, [&](uint32_t i, uint32_t) { hits[i].fetch_add(1); });
        for (const std::atomic<int>& h : hits)
            EXPECT_EQ(h.load(), 1) << "threads " << threads;
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
