#include <raster/memory_budget.h>

#include <cstdio>
#include <limits>
#include <unistd.h>

namespace raster {

uint64_t physicalMemoryBytes() {
    const long pages = ::sysconf(_SC_PHYS_PAGES);
    const long page_size = ::sysconf(_SC_PAGESIZE);
    if (pages <= 0 || page_size <= 0)
        return 0;
    return mulBytes(uint64_t(pages), uint64_t(page_size));
}

MemoryBudget defaultMemoryBudget() {
    const uint64_t physical = physicalMemoryBytes();
    return MemoryBudget{physical > 0 ? physical / 2 : uint64_t{4} << 30};
}

std::string formatBytes(uint64_t bytes) {
    if (bytes == std::numeric_limits<uint64_t>::max())
        return "more than 16 EiB";
    static constexpr const char* kUnits[] = {"KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
    if (bytes < 1024)
        return std::to_string(bytes) + (bytes == 1 ? " byte" : " bytes");
    double value = double(bytes) / 1024.0;
    int unit = 0;
    while (value >= 1024.0 && unit < 5) {
        value /= 1024.0;
        ++unit;
    }
    char text[32];
    std::snprintf(text, sizeof(text), value < 10.0 ? "%.1f %s" : "%.0f %s", value, kUnits[unit]);
    return text;
}

Status checkMemory(const MemoryBudget& budget, std::string_view what, uint64_t needed) {
    if (!budget.limited() || needed <= budget.bytes)
        return {};
    return Status::error(std::string(what) + " needs " + formatBytes(needed) +
                         ", more than the memory budget of " + formatBytes(budget.bytes) +
                         " (memory_budget)");
}

uint64_t mulBytes(uint64_t a, uint64_t b) {
    uint64_t product = 0;
    return __builtin_mul_overflow(a, b, &product) ? std::numeric_limits<uint64_t>::max() : product;
}

uint64_t addBytes(uint64_t a, uint64_t b) {
    uint64_t sum = 0;
    return __builtin_add_overflow(a, b, &sum) ? std::numeric_limits<uint64_t>::max() : sum;
}

} // namespace raster
