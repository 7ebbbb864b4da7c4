#include <raster/memory_budget.h>

#include <gtest/gtest.h>

#include <limits>

namespace {

TEST(MemoryBudget, NamesWhatNeededHowMuch) {
    const raster::MemoryBudget budget{uint64_t{1} << 30};
    EXPECT_TRUE(raster::checkMemory(budget, "frame", uint64_t{1} << 30).ok());
    const raster::Status s = raster::checkMemory(budget, "multiview scratch", uint64_t{3} << 30);
    ASSERT_FALSE(s.ok());
    EXPECT_EQ(s.message(), "multiview scratch needs 3.0 GiB, more than the memory budget of "
                           "1.0 GiB (memory_budget)");
    EXPECT_TRUE(raster::checkMemory(raster::MemoryBudget{}, "anything", ~uint64_t{0}).ok());
}

TEST(MemoryBudget, ArithmeticSaturatesInsteadOfWrapping) {
    constexpr uint64_t kMax = std::numeric_limits<uint64_t>::max();
    EXPECT_EQ(raster::mulBytes(uint64_t{1} << 40, uint64_t{1} << 40), kMax);
    EXPECT_EQ(raster::addBytes(kMax - 1, 2), kMax);
    EXPECT_EQ(raster::mulBytes(16384ull * 16384, 16), 16384ull * 16384 * 16);
    EXPECT_FALSE(raster::checkMemory(raster::MemoryBudget{kMax - 1}, "x", kMax).ok());
}

TEST(MemoryBudget, DefaultIsHalfOfPhysicalMemory) {
    const uint64_t physical = raster::physicalMemoryBytes();
    ASSERT_GT(physical, 0u); // Linux reports it
    EXPECT_EQ(raster::defaultMemoryBudget().bytes, physical / 2);
}

TEST(MemoryBudget, FormatsBytesForPeople) {
    EXPECT_EQ(raster::formatBytes(17), "17 bytes");
    EXPECT_EQ(raster::formatBytes(300 * 1024), "300 KiB");
    EXPECT_EQ(raster::formatBytes(uint64_t{3} << 29), "1.5 GiB");
}

} // namespace
