// Colour and depth storage (raster/storage.h): what a resized buffer holds.
#include <raster/storage.h>

#include <gtest/gtest.h>

#include <cmath>

namespace focal::test {
namespace {

TEST(ColorBuffer, ResizeFillsEveryPixelWithTheClearColour) {
    // A +0 clear colour is left to the vector's value-initialisation; any other is stored per
    // pixel. Both must hold after the buffer held other values, in both formats.
    for (raster::ColorFormat format : {raster::ColorFormat::Half, raster::ColorFormat::Float32})
        for (glm::vec4 clear : {glm::vec4(0.0f), glm::vec4(0.25f, 0.5f, 1.0f, 0.0f),
                                glm::vec4(0.0f, 0.0f, -0.0f, 0.0f)}) {
            raster::ColorBuffer buffer;
            buffer.resize(format, 7, glm::vec4(3.0f));
            buffer.store(2, glm::vec4(-1.0f));
            buffer.resize(format, 5, clear);
            for (size_t i = 0; i < 5; ++i) {
                const glm::vec4 c = buffer.load(i);
                for (int ch = 0; ch < 4; ++ch) {
                    EXPECT_EQ(c[ch], clear[ch]) << i;
                    EXPECT_EQ(std::signbit(c[ch]), std::signbit(clear[ch])) << i;
                }
            }
        }
}

} // namespace
} // namespace focal::test
