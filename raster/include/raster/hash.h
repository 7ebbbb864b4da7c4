// Counter-based hashing: the only source of "randomness" in focal (docs/architecture.md, "The
// determinism contract"). A value is a pure function of its inputs (pixel, sample index, seed,
// ...), never of shared state.
#pragma once

#include <cstdint>

namespace raster {

// 32-bit integer finaliser (xorshift-multiply, the "lowbias32" constants of Chris Wellons' hash
// search): full avalanche, cheap, and a pure function.
constexpr uint32_t hash32(uint32_t x) {
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

} // namespace raster
