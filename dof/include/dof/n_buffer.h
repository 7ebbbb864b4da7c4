// N-buffer (Décoret 2005, "N-buffers for efficient depth map query"), used by Lee et al. 2009
// §4.3 "Early Layer Culling": every level has the full resolution of the source depth map, and
// level n holds, at pixel (x, y), the minimum over the 2^n x 2^n window [x, x+2^n) x [y, y+2^n)
// (clipped to the image). The minimum over any square window then takes four lookups into one
// level. Consumes a float depth map (any monotonic depth, e.g. stored D; empty pixels hold a
// value above every real one); produces the levels, owned by the NBuffer.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace dof {

struct NBuffer {
    uint32_t width = 0;
    uint32_t height = 0;
    // levels[0] is a copy of the source; levels[n] as described above. All width*height.
    std::vector<std::vector<float>> levels;

    uint32_t levelCount() const { return uint32_t(levels.size()); }
    float at(uint32_t level, uint32_t x, uint32_t y) const {
        return levels[level][size_t(y) * width + x];
    }
};

// Builds levels 0..max_level (level n from level n-1 with four lookups, Décoret 2005 §3).
// `depth` holds width*height values, row-major. `max_level` is clamped to what the image size
// needs (2^n >= max(width, height) covers everything). Resizes `out`'s levels in place:
// std::bad_alloc when that fails, as from the vectors (renderMultiview turns it into a Status).
void buildNBuffer(const float* depth, uint32_t width, uint32_t height, uint32_t max_level,
                  NBuffer& out);

// The level a square window of `size` pixels queries with: floor(log2(size)), at most the last
// level built.
uint32_t nBufferLevelFor(const NBuffer& nb, uint32_t size);

// Minimum depth over the square window [x0, x0+size) x [y0, y0+size) clipped to the image:
// four lookups into level n = nBufferLevelFor(size) at the window's corners (Décoret 2005 §3).
// Conservative when size exceeds the built levels or the window leaves the image (it may then
// return the minimum of a larger window, never a larger value than the true minimum).
// Returns +inf when the clipped window is empty.
float nBufferMin(const NBuffer& nb, int64_t x0, int64_t y0, int64_t size);

// nBufferMin for many windows of one size (per-pixel culling over a tile): the level and the
// far corners' offset are worked out once, so a window that lies inside the image is four
// lookups. minInside(x0, y0) == nBufferMin(nb, x0, y0, size) for every window
// [x0, x0+size) x [y0, y0+size) inside the image (the caller checks that; outside it, ask
// nBufferMin).
class NBufferWindow {
public:
    NBufferWindow() = default;
    NBufferWindow(const NBuffer& nb, int64_t size);
    float minInside(int64_t x0, int64_t y0) const {
        if (!four_lookups_)
            return nBufferMin(*nb_, x0, y0, size_);
        const float* r0 = level_ + size_t(y0) * width_ + size_t(x0);
        const float* r1 = r0 + size_t(far_) * width_;
        return std::min(std::min(r0[0], r0[far_]), std::min(r1[0], r1[far_]));
    }

private:
    const NBuffer* nb_ = nullptr;
    const float* level_ = nullptr;
    size_t width_ = 0;
    int64_t size_ = 0;
    int64_t far_ = 0; // size - 2^n: the far corners' offset
    bool four_lookups_ = false;
};

// The same minimum by brute force (the reference the tests compare with).
float windowMinReference(const float* depth, uint32_t width, uint32_t height, int64_t x0,
                         int64_t y0, int64_t size);

} // namespace dof
