#include <dof/n_buffer.h>

#include <algorithm>
#include <bit>
#include <cmath>

namespace dof {

void buildNBuffer(const float* depth, uint32_t width, uint32_t height, uint32_t max_level,
                  NBuffer& out) {
    out.width = width;
    out.height = height;
    uint32_t needed = 0;
    while ((uint64_t(1) << needed) < std::max<uint64_t>({width, height, 1}))
        ++needed;
    const uint32_t top = std::min(max_level, needed);
    out.levels.resize(top + 1);
    const size_t pixels = size_t(width) * height;
    out.levels[0].assign(depth, depth + pixels);
    for (uint32_t n = 1; n <= top; ++n) {
        // Level n from level n-1: the 2^n window at (x, y) is the union of four 2^(n-1) windows
        // at offsets 0 and h = 2^(n-1); offsets past the image are clamped to the last row or
        // column, which lies inside the clipped window, so the result stays exact.
        const std::vector<float>& prev = out.levels[n - 1];
        std::vector<float>& cur = out.levels[n];
        cur.resize(pixels);
        const uint32_t h = 1u << (n - 1);
        for (uint32_t y = 0; y < height; ++y) {
            const uint32_t y1 = std::min(y + h, height - 1);
            const float* r0 = prev.data() + size_t(y) * width;
            const float* r1 = prev.data() + size_t(y1) * width;
            float* o = cur.data() + size_t(y) * width;
            // Columns whose partner x + h lies inside the row need no clamp (a loop the
            // compiler vectorizes); the last h columns take the last column as partner.
            const uint32_t inner = width > h ? width - h : 0;
            for (uint32_t x = 0; x < inner; ++x)
                o[x] = std::min(std::min(r0[x], r0[x + h]), std::min(r1[x], r1[x + h]));
            for (uint32_t x = inner; x < width; ++x)
                o[x] = std::min(std::min(r0[x], r0[width - 1]), std::min(r1[x], r1[width - 1]));
        }
    }
}

uint32_t nBufferLevelFor(const NBuffer& nb, uint32_t size) {
    // floor(log2(size)) (0 for sizes 0 and 1), at most the last level.
    const uint32_t n = size > 1 ? uint32_t(std::bit_width(size)) - 1 : 0;
    return std::min(n, nb.levelCount() > 0 ? nb.levelCount() - 1 : 0);
}

float nBufferMin(const NBuffer& nb, int64_t x0, int64_t y0, int64_t size) {
    if (size <= 0 || nb.levels.empty())
        return INFINITY;
    // Clip the window to the image; an empty intersection has no minimum.
    const int64_t w = nb.width, h = nb.height;
    const int64_t cx0 = std::max<int64_t>(x0, 0), cy0 = std::max<int64_t>(y0, 0);
    const int64_t cx1 = std::min<int64_t>(x0 + size, w), cy1 = std::min<int64_t>(y0 + size, h);
    if (cx0 >= cx1 || cy0 >= cy1)
        return INFINITY;
    // Four overlapping squares of side s = 2^n covering the (clipped) window's corners. When the
    // clipped window is narrower than s on one axis, the corner lookups coincide and read a
    // window that extends past it: conservative, never too large.
    const int64_t side = std::max(cx1 - cx0, cy1 - cy0);
    const uint32_t n = nBufferLevelFor(nb, uint32_t(std::min<int64_t>(side, 1 << 30)));
    const int64_t s = int64_t(1) << n;
    const int64_t xa = cx0, ya = cy0;
    const int64_t xb = std::max(cx0, cx1 - s), yb = std::max(cy0, cy1 - s);
    const std::vector<float>& lv = nb.levels[n];
    auto at = [&](int64_t x, int64_t y) { return lv[size_t(y) * nb.width + size_t(x)]; };
    float m = std::min(std::min(at(xa, ya), at(xb, ya)), std::min(at(xa, yb), at(xb, yb)));
    if (s * 2 < side) {
        // Not enough levels were built to cover the window with four squares: tile it.
        for (int64_t y = cy0; y < cy1; y += s)
            for (int64_t x = cx0; x < cx1; x += s)
                m = std::min(m, at(std::min(x, xb), std::min(y, yb)));
    }
    return m;
}

NBufferWindow::NBufferWindow(const NBuffer& nb, int64_t size) : nb_(&nb), size_(size) {
    if (size <= 0 || nb.levels.empty() || size > int64_t(nb.width) || size > int64_t(nb.height))
        return;
    // nBufferMin's corner lookups for an unclipped window: side = size, squares of 2^n.
    const uint32_t n = nBufferLevelFor(nb, uint32_t(size));
    const int64_t s = int64_t(1) << n;
    if (s * 2 < size)
        return; // nBufferMin tiles the window: not enough levels for four squares
    level_ = nb.levels[n].data();
    width_ = nb.width;
    far_ = size - s;
    four_lookups_ = true;
}

float windowMinReference(const float* depth, uint32_t width, uint32_t height, int64_t x0,
                         int64_t y0, int64_t size) {
    float m = INFINITY;
    for (int64_t y = std::max<int64_t>(y0, 0); y < std::min<int64_t>(y0 + size, height); ++y)
        for (int64_t x = std::max<int64_t>(x0, 0); x < std::min<int64_t>(x0 + size, width); ++x)
            m = std::min(m, depth[size_t(y) * width + size_t(x)]);
    return m;
}

} // namespace dof
