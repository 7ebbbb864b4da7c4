#include "apps/pixel_hash.h"

#include "apps/fnv1a.h"

#include <bit>
#include <cinttypes>
#include <cstdio>

namespace focal {

// The samples are hashed as stored in memory, which is the definition's byte order only on a
// little-endian host (a big-endian port must swap each sample first).
static_assert(std::endian::native == std::endian::little);

uint64_t pixelHash(const ImageSamples& image) {
    Fnv1a64 h;
    h.mixU32(image.width);
    h.mixU32(image.height);
    h.mixU32(image.channels);
    h.mixU32(image.bytes_per_sample);
    h.mix(image.bytes.data(), image.bytes.size());
    return h.value;
}

std::string hashHex(uint64_t hash) {
    char buf[17];
    std::snprintf(buf, sizeof buf, "%016" PRIx64, hash);
    return buf;
}

} // namespace focal
