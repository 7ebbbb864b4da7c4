// N-buffer (Décoret 2005) as used by Lee et al. 2009 §4.3: four lookups give the exact minimum
// of any square window inside the image, and never more than the true minimum elsewhere.
#include <dof/lens_samples.h>
#include <dof/n_buffer.h>

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace {

std::vector<float> hashedDepth(uint32_t w, uint32_t h) {
    std::vector<float> d(size_t(w) * h);
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x)
            d[size_t(y) * w + x] = dof::hashToUnit(dof::hashWords(x, y, 17));
    return d;
}

TEST(NBuffer, LevelNHoldsTheMinimumOfTheTwoToTheNWindow) {
    const uint32_t w = 37, h = 23;
    const std::vector<float> d = hashedDepth(w, h);
    dof::NBuffer nb;
    dof::buildNBuffer(d.data(), w, h, 5, nb);
    ASSERT_EQ(nb.levelCount(), 6u);
    for (uint32_t n = 0; n < nb.levelCount(); ++n)
        for (uint32_t y = 0; y < h; ++y)
            for (uint32_t x = 0; x < w; ++x)
                ASSERT_EQ(nb.at(n, x, y), dof::windowMinReference(d.data(), w, h, x, y, 1 << n))
                    << n << " " << x << "," << y;
}

TEST(NBuffer, SquareQueryIsExactInsideAndConservativeOutside) {
    const uint32_t w = 41, h = 29;
    const std::vector<float> d = hashedDepth(w, h);
    dof::NBuffer nb;
    dof::buildNBuffer(d.data(), w, h, 16, nb);
    for (int64_t size = 1; size <= 29; ++size)
        for (int64_t y = -5; y < int64_t(h); y += 3)
            for (int64_t x = -5; x < int64_t(w); x += 2) {
                const float ref = dof::windowMinReference(d.data(), w, h, x, y, size);
                const float q = dof::nBufferMin(nb, x, y, size);
                if (x >= 0 && y >= 0 && x + size <= w && y + size <= h)
                    ASSERT_EQ(q, ref) << size << " at " << x << "," << y;
                else
                    ASSERT_LE(q, ref) << size << " at " << x << "," << y;
            }
    EXPECT_EQ(dof::nBufferMin(nb, -10, -10, 5), INFINITY); // entirely outside
}

TEST(NBuffer, TooFewLevelsStayConservative) {
    const uint32_t w = 64, h = 64;
    const std::vector<float> d = hashedDepth(w, h);
    dof::NBuffer nb;
    dof::buildNBuffer(d.data(), w, h, 1, nb);
    for (int64_t size : {5, 17, 64})
        EXPECT_EQ(dof::nBufferMin(nb, 0, 0, size),
                  dof::windowMinReference(d.data(), w, h, 0, 0, size));
}

// NBufferWindow (one size, many positions) returns nBufferMin's value for every window inside
// the image, with levels enough for four lookups and with too few (nBufferMin then tiles).
TEST(NBuffer, WindowOfOneSizeMatchesTheQueryInsideTheImage) {
    const uint32_t w = 41, h = 29;
    const std::vector<float> d = hashedDepth(w, h);
    for (uint32_t max_level : {16u, 1u}) {
        dof::NBuffer nb;
        dof::buildNBuffer(d.data(), w, h, max_level, nb);
        for (int64_t size = 1; size <= 29; ++size) {
            const dof::NBufferWindow window(nb, size);
            for (int64_t y = 0; y + size <= int64_t(h); ++y)
                for (int64_t x = 0; x + size <= int64_t(w); ++x) {
                    ASSERT_EQ(window.minInside(x, y), dof::nBufferMin(nb, x, y, size))
                        << size << " at " << x << "," << y << ", levels to " << max_level;
                    ASSERT_EQ(window.minInside(x, y),
                              dof::windowMinReference(d.data(), w, h, x, y, size));
                }
        }
    }
}

} // namespace
