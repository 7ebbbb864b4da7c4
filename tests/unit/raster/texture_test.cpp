// Texture decoding, mip chains, wrapping and filtering (issue 3, texture-filtering tests).
#include "support/test_util.h"

#include <raster/texture.h>

#include <gtest/gtest.h>

#include <cmath>

namespace focal::test {
namespace {

using raster::Filter;
using raster::FilterOverride;
using raster::Image;
using raster::MipFilter;
using raster::Sampler;
using raster::Wrap;

// A w x h image whose texel (x, y) has red = value(x, y) (0..255), green = x, blue = y.
template <class F> Image makeImage(uint32_t w, uint32_t h, bool srgb, F value) {
    Image img;
    img.srgb = srgb;
    raster::MipLevel& level = img.levels.emplace_back();
    level.width = w;
    level.height = h;
    level.rgba8.resize(size_t(w) * h * 4);
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            uint8_t* t = &level.rgba8[(size_t(y) * w + x) * 4];
            t[0] = uint8_t(value(x, y)), t[1] = uint8_t(x), t[2] = uint8_t(y), t[3] = 255;
        }
    raster::buildMipChain(img);
    return img;
}

Image checker(uint32_t size, bool srgb) {
    return makeImage(size, size, srgb,
                     [](uint32_t x, uint32_t y) { return (x + y) % 2 ? 255 : 0; });
}

TEST(Texture, SrgbTransferRoundTrips) {
    for (int i = 0; i <= 255; ++i) {
        const float v = float(i) / 255.0f;
        EXPECT_NEAR(raster::linearToSrgb(raster::srgbToLinear(v)), v, 1e-5f);
    }
    EXPECT_NEAR(raster::srgbToLinear(0.5f), 0.2140411f, 1e-6f);
}

TEST(Texture, MipChainAveragesInLinearLight) {
    const Image img = checker(4, true);
    ASSERT_EQ(img.levels.size(), 3u); // 4x4, 2x2, 1x1
    // Black and white average to linear 0.5, which sRGB encodes as 188 (not 128).
    EXPECT_EQ(img.levels[1].rgba8[0], 188);
    EXPECT_EQ(img.levels[2].rgba8[0], 188);
    const Image non_square = makeImage(8, 2, false, [](uint32_t, uint32_t) { return 7; });
    ASSERT_EQ(non_square.levels.size(), 4u); // 8x2, 4x1, 2x1, 1x1
    EXPECT_EQ(non_square.levels[1].width, 4u);
    EXPECT_EQ(non_square.levels[1].height, 1u);
    EXPECT_EQ(non_square.levels[3].width, 1u);
}

// Levels up to kLinearLevelMaxTexels keep their texels decoded as a lookup decodes them (sRGB
// colour through the table, alpha and linear images by 1/255); larger ones keep only bytes.
TEST(Texture, MipChainDecodesTheLevelsUpToTheLimit) {
    const Image srgb = makeImage(3, 2, true, [](uint32_t x, uint32_t y) { return 40 * x + y; });
    for (const raster::MipLevel& level : srgb.levels) {
        ASSERT_EQ(level.linear.size(), level.rgba8.size());
        for (size_t i = 0; i < level.rgba8.size(); ++i)
            EXPECT_EQ(level.linear[i], i % 4 == 3 ? float(level.rgba8[i]) * (1.0f / 255.0f)
                                                  : raster::srgbDecodeTable()[level.rgba8[i]])
                << i;
    }
    const Image linear = makeImage(2, 2, false, [](uint32_t x, uint32_t) { return 200 + x; });
    EXPECT_EQ(linear.levels[0].linear[4], 201.0f * (1.0f / 255.0f));
    // 2048 x 1024 = 2^21 texels: level 0 stays bytes only, level 1 (2^19) is decoded.
    const Image large = makeImage(2048, 1024, true, [](uint32_t, uint32_t) { return 9; });
    static_assert(raster::kLinearLevelMaxTexels == (uint64_t{1} << 20));
    EXPECT_TRUE(large.levels[0].linear.empty());
    EXPECT_EQ(large.levels[1].linear.size(), large.levels[1].rgba8.size());
}

TEST(Texture, NearestFetchesTexelsAndWrapModesWrap) {
    const Image img = makeImage(4, 4, false, [](uint32_t x, uint32_t) { return x * 80; });
    Sampler s;
    s.mag = s.min = Filter::Nearest;
    s.mip = MipFilter::None;
    auto red = [&](float u) {
        return raster::sampleImage(img, s, FilterOverride::Sampler, {u, 0.1f}, 0.0f).r;
    };
    EXPECT_FLOAT_EQ(red(0.125f), 0.0f);
    EXPECT_FLOAT_EQ(red(0.375f), 80.0f / 255.0f);
    EXPECT_FLOAT_EQ(red(1.375f), 80.0f / 255.0f); // repeat
    s.wrap_s = Wrap::ClampToEdge;
    EXPECT_FLOAT_EQ(red(1.375f), 240.0f / 255.0f);
    EXPECT_FLOAT_EQ(red(-3.0f), 0.0f);
    s.wrap_s = Wrap::MirroredRepeat;
    EXPECT_FLOAT_EQ(red(1.125f), 240.0f / 255.0f); // mirrored: 1.125 -> 0.875
    EXPECT_FLOAT_EQ(red(1.875f), 0.0f);
    EXPECT_FLOAT_EQ(red(-0.125f), 0.0f);
    // Non-finite and huge coordinates do not crash.
    EXPECT_TRUE(std::isfinite(red(NAN)));
    EXPECT_TRUE(std::isfinite(red(1e30f)));
}

TEST(Texture, BilinearAndTrilinearInterpolate) {
    const Image img = makeImage(2, 2, false, [](uint32_t x, uint32_t) { return x * 255; });
    Sampler s;
    s.wrap_s = s.wrap_t = Wrap::ClampToEdge;
    // Halfway between the texel centres 0.25 and 0.75.
    EXPECT_FLOAT_EQ(raster::sampleImage(img, s, FilterOverride::Bilinear, {0.5f, 0.5f}, 0.0f).r,
                    0.5f);
    EXPECT_FLOAT_EQ(raster::sampleImage(img, s, FilterOverride::Nearest, {0.3f, 0.5f}, 0.0f).r,
                    0.0f);
    // Level 1 is the 1x1 average, 127.5 stored as 128: lod 0.5 at uv 0.25 mixes 0 and 128/255.
    EXPECT_FLOAT_EQ(raster::sampleImage(img, s, FilterOverride::Trilinear, {0.25f, 0.25f}, 0.5f).r,
                    0.5f * 128.0f / 255.0f);
    // Bilinear ignores the mip chain.
    EXPECT_FLOAT_EQ(raster::sampleImage(img, s, FilterOverride::Bilinear, {0.25f, 0.25f}, 0.5f).r,
                    0.0f);
}

TEST(Texture, MinifiedCheckerAveragesToMidGreyWithTrilinear) {
    // A 256x256 black/white sRGB checker on a quad covering ~16x16 pixels: with trilinear
    // filtering every pixel reads the linear average 0.5; without mips it aliases to 0 or 1.
    raster::Scene s;
    s.images.push_back(checker(256, true));
    raster::Material m = flatMaterial({1, 1, 1, 1});
    m.base_color_texture.image = 0;
    const int32_t mat = addMaterial(s, m);
    raster::Primitive& p = addMesh(s, {{-8, -8, -64}, {8, -8, -64}, {8, 8, -64}, {-8, 8, -64}},
                                   {0, 1, 2, 0, 2, 3}, mat);
    p.texcoords0 = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
    const raster::View v = pixelView(64, 64, 64.0f);
    raster::RenderOptions o;
    o.texture_filter = FilterOverride::Trilinear;
    const raster::Frame tri = render(s, v, o);
    o.texture_filter = FilterOverride::Nearest;
    const raster::Frame nearest = render(s, v, o);
    for (uint32_t y = 26; y < 38; ++y)
        for (uint32_t x = 26; x < 38; ++x) {
            EXPECT_NEAR(pixel(tri, x, y).r, 0.5f, 0.01f) << x << "," << y;
            const float n = pixel(nearest, x, y).r;
            EXPECT_TRUE(n == 0.0f || n == 1.0f) << x << "," << y;
        }
}

} // namespace
} // namespace focal::test
