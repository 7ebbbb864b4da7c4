// Wall-clock stage timing for stats (never for decisions: times are not deterministic).
#pragma once

#include <chrono>

namespace raster {

// Milliseconds since `start`.
inline double msSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
        .count();
}

} // namespace raster
