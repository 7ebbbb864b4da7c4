// FNV-1a, 64-bit (Fowler, Noll & Vo; http://www.isthe.com/chongo/tech/comp/fnv/): a byte-wise
// hash fed in order, used for pixel hashes and cache keys. Header-only, no state beyond the
// running value.
#pragma once

#include <cstddef>
#include <cstdint>

namespace focal {

// The standard FNV-1a 64 offset basis and prime.
inline constexpr uint64_t kFnv1a64Basis = 0xcbf29ce484222325ull;
inline constexpr uint64_t kFnv1a64Prime = 0x100000001b3ull;

struct Fnv1a64 {
    uint64_t value = kFnv1a64Basis;

    void mix(const void* data, size_t bytes) {
        const auto* p = static_cast<const unsigned char*>(data);
        for (size_t i = 0; i < bytes; ++i) {
            value ^= p[i];
            value *= kFnv1a64Prime;
        }
    }
    // A 32-bit value, little-endian whatever the host's byte order.
    void mixU32(uint32_t v) {
        const unsigned char le[4] = {
            static_cast<unsigned char>(v), static_cast<unsigned char>(v >> 8),
            static_cast<unsigned char>(v >> 16), static_cast<unsigned char>(v >> 24)};
        mix(le, sizeof le);
    }
};

} // namespace focal
