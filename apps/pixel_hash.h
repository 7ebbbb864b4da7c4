// The pixel hash `focal hash` prints (docs/hash.md): a 64-bit FNV-1a of an image's decoded
// samples, not of its file bytes, so the same pixels hash the same whatever the encoder's
// metadata or compression. Consumes ImageSamples (apps/image_io.h); produces a number.
#pragma once

#include "apps/image_io.h"

#include <cstdint>
#include <string>

namespace focal {

// Bumped whenever the definition below changes (it never changes silently).
inline constexpr int kPixelHashVersion = 1;

// FNV-1a 64 (basis 0xcbf29ce484222325, prime 0x100000001b3) over, in order: width, height,
// channels and bytes per sample as little-endian uint32, then every sample little-endian
// (rows top to bottom, pixels left to right, channels in file order).
uint64_t pixelHash(const ImageSamples& image);

// The hash as `focal hash` prints it: 16 lowercase hex digits.
std::string hashHex(uint64_t hash);

} // namespace focal
