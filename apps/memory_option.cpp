#include "apps/memory_option.h"

#include <cmath>
#include <cstdlib>
#include <utility>

namespace focal {

raster::Result<raster::MemoryBudget> parseMemoryBudget(const std::string& text) {
    if (text == "auto")
        return raster::defaultMemoryBudget();
    auto bad = [&](const std::string& why) {
        return raster::Status::error("--memory-budget expects auto, a size such as 8G or 512MiB, "
                                     "or a percentage of physical memory such as 25%; got '" +
                                     text + "'" + why);
    };
    const char* begin = text.c_str();
    char* end = nullptr;
    const double value = std::strtod(begin, &end);
    if (end == begin || !std::isfinite(value) || !(value > 0.0))
        return bad("");
    const std::string unit(end);
    double bytes = 0.0;
    if (unit == "%") {
        if (value > 100.0)
            return bad(" (more than 100%)");
        bytes = double(raster::physicalMemoryBytes()) * value / 100.0;
    } else {
        static const std::pair<const char*, int> kUnits[] = {
            {"", 0},    {"B", 0}, {"K", 1},   {"KiB", 1}, {"M", 2},
            {"MiB", 2}, {"G", 3}, {"GiB", 3}, {"T", 4},   {"TiB", 4}};
        int power = -1;
        for (const auto& [name, p] : kUnits)
            if (unit == name)
                power = p;
        if (power < 0)
            return bad(" (unknown unit '" + unit + "')");
        bytes = value * std::pow(1024.0, power);
    }
    constexpr double kMin = 1024.0 * 1024.0;
    if (bytes < kMin)
        return bad(" (less than 1 MiB)");
    if (bytes >= 18e18) // beyond uint64_t
        return bad(" (too large)");
    return raster::MemoryBudget{uint64_t(bytes)};
}

} // namespace focal
