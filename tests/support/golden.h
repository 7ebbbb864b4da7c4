// Golden references for the golden test tier (docs/testing.md): consumes a rendered Frame, its
// hash and a case name; compares the hash exactly against a store's hashes.txt and the 8-bit
// sRGB image against the store's images/NAME.png within 1 LSB per channel. On a mismatch it
// writes NAME_actual.png and NAME_diff.png to goldenDiffDir() and names them in the failure
// message. With FOCAL_UPDATE_GOLDENS=1 in the environment it rewrites the hash line and the
// image instead. Two stores: the pinhole renders (tests/golden) and the depth-of-field methods
// (tests/golden/dof), which differ in what their hashes cover.
#pragma once

#include <raster/frame.h>

#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <map>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace focal::test {

// The largest per-channel difference, in 8-bit sRGB steps, the image check accepts (the hash
// check accepts none). One step absorbs 8-bit rounding of a colour that moved by a hair.
inline constexpr int kGoldenImageTolerance = 1;

// The command that regenerates every golden (printed in failure messages).
inline constexpr const char* kGoldenUpdateCommand =
    "FOCAL_UPDATE_GOLDENS=1 ctest --preset release -L golden";

// True when FOCAL_UPDATE_GOLDENS is set to anything but "" or "0".
bool updatingGoldens();

// One set of golden references: DIR/hashes.txt ("NAME HEX16" lines) and DIR/images/NAME.png.
struct GoldenStore {
    std::filesystem::path dir;
    std::string hash_definition; // what each hash covers; the first lines of hashes.txt
    std::filesystem::path hashFile() const { return dir / "hashes.txt"; }
    std::filesystem::path imagePath(const std::string& name) const {
        return dir / "images" / (name + ".png");
    }
};

// <source>/tests/golden: pinhole renders, hashed with hashFrame (colour and stored depth).
const GoldenStore& pinholeGoldens();
// <source>/tests/golden/dof: depth-of-field renders, hashed as `focal hash` hashes the EXR that
// `focal render` writes (apps/pixel_hash.h).
const GoldenStore& dofGoldens();
// Where mismatches are written: $FOCAL_GOLDEN_DIFF_DIR, else <working dir>/golden-diff (CTest
// runs the tests in <build>/tests, so <build>/tests/golden-diff). Created on demand.
std::filesystem::path goldenDiffDir();

// Reads "NAME HEX16" lines ('#' starts a comment). A missing file reads as empty; a malformed
// line adds a message to *errors.
std::map<std::string, uint64_t> readGoldenHashes(const std::filesystem::path& file,
                                                 std::vector<std::string>* errors = nullptr);

// Under a machine-wide lock (CTest may run cases in parallel), applies `set` and removes every
// name in `remove`, then rewrites the store's hash file atomically, sorted by name.
void updateGoldenHashes(const GoldenStore& store, const std::map<std::string, uint64_t>& set,
                        const std::vector<std::string>& remove = {});

// The store holds exactly the cases `names`: one valid hash line and one PNG each, nothing
// stale. While updating goldens, stale entries and images are deleted instead.
::testing::AssertionResult holdsExactly(const GoldenStore& store,
                                        const std::vector<std::string>& names);

// The frame's colour as the PNG writer encodes it (apps/image_io.cpp): RGB sRGB-encoded, alpha
// linear, clamped to [0,1] and rounded to 8 bits. RGBA, top row first.
std::vector<uint8_t> toSrgb8(const raster::Frame& frame);

// Reads an 8-bit RGBA PNG as its exact bytes. False, with a message, when it is missing,
// unreadable or not RGBA.
bool readPngRgba8(const std::filesystem::path& path, uint32_t& width, uint32_t& height,
                  std::vector<uint8_t>& rgba, std::string& error);

// Each pair of cases in `pairs` has different stored hashes in `store`: the option that tells a
// variant from its base changes the pixels, so the variant pins something of its own.
::testing::AssertionResult
variantsDiffer(const GoldenStore& store,
               std::span<const std::pair<const char*, const char*>> pairs);

// Compares `frame`, whose hash is `hash`, with the golden called `name` in `store` (see the top
// of this file), or updates it.
::testing::AssertionResult matchesGolden(const GoldenStore& store, const std::string& name,
                                         const raster::Frame& frame, uint64_t hash);

// For two renders that should have been identical: writes NAME_actual.png (from `actual`) and
// NAME_diff.png (against `expected`) to goldenDiffDir(); returns lines describing the
// difference and naming both files.
std::string describeFrameDifference(const std::string& name, const raster::Frame& expected,
                                    const raster::Frame& actual);

} // namespace focal::test
