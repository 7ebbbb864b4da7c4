// Texture decoding, mip chains, wrapping and filtering (issue 3, texture-filtering tests).
#include "support/test_util.h"

#include <raster/texture.h>

#include <glm/geometric.hpp>
#include <glm/gtc/type_precision.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
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

// An image of zero texels (every channel) with a few non-zero ones: colour only at (9, 2),
// alpha only at (1, 5), in 8 x 8 blocks (0, 0) and (1, 0).
TEST(Texture, MipChainMarksBlocksOfZeroTexels) {
    Image img;
    raster::MipLevel& level = img.levels.emplace_back();
    level.width = 16;
    level.height = 8;
    level.rgba8.assign(16 * 8 * 4, 0);
    level.rgba8[(2 * 16 + 9) * 4 + 1] = 5;
    level.rgba8[(5 * 16 + 1) * 4 + 3] = 200;
    raster::buildMipChain(img);
    static_assert(raster::kTexelBlockSide == 8);
    const raster::MipLevel& l0 = img.levels[0];
    ASSERT_EQ(l0.nonzero.size(), 2u);
    EXPECT_EQ(l0.nonzero[0], 2); // alpha only
    EXPECT_EQ(l0.nonzero[1], 1); // colour only
    EXPECT_TRUE(img.zero_colour_blocks);
    EXPECT_TRUE(raster::zeroTexels(l0, 0, 7, 0, 7, false));
    EXPECT_FALSE(raster::zeroTexels(l0, 0, 7, 0, 7, true));
    EXPECT_FALSE(raster::zeroTexels(l0, 7, 8, 0, 0, false)); // reaches into block (1, 0)
    const raster::MipLevel& top = img.levels.back(); // 1 x 1: zero unless the colour rounds up
    EXPECT_EQ(raster::zeroTexels(top, 0, 0, 0, 0, false),
              (top.rgba8[0] | top.rgba8[1] | top.rgba8[2]) == 0);
    // A level not made by buildMipChain knows nothing: never zero.
    raster::MipLevel bare = l0;
    bare.nonzero.clear();
    EXPECT_FALSE(raster::zeroTexels(bare, 0, 7, 0, 7, false));
}

// Lookups that read only zero texels are skipped (sampleLanes): the frame must be the one
// sampled in full, texel for texel. A sparse image (most texels zero in every channel, a few
// with colour, many with alpha only in one quarter) as base colour and emissive texture of opaque
// and blended quads seen minified, near 1:1 and magnified, with coordinates beyond [0, 1] (repeat),
// at every filter, with and without SIMD.
TEST(Texture, LookupsOfZeroTexelsAreSkippedWithTheSameBits) {
    Image img;
    raster::MipLevel& level = img.levels.emplace_back();
    level.width = level.height = 128;
    level.rgba8.assign(128 * 128 * 4, 0);
    // ~0.4 % of the texels have colour (with or without alpha); in the right quarter, 40 % more
    // have alpha only (blocks of zero colour that are not zero).
    uint32_t h = 12345;
    for (size_t t = 0; t < 128 * 128; ++t) {
        h = h * 1664525u + 1013904223u;
        uint8_t* px = &level.rgba8[t * 4];
        if ((h >> 22) < 4) {
            px[0] = uint8_t(h >> 8), px[1] = uint8_t(h >> 16);
            px[3] = (h >> 22) < 2 ? 255 : 0;
        } else if (t % 128 >= 96 && (h >> 24) >= 150) {
            px[3] = uint8_t(h >> 4) | 1;
        }
    }
    raster::buildMipChain(img);
    ASSERT_TRUE(img.zero_colour_blocks);
    ASSERT_TRUE(img.zero_blocks);

    raster::Scene s;
    s.images.push_back(img);
    raster::Material m = flatMaterial({1, 1, 1, 1});
    m.base_color_texture.image = 0;
    m.emissive_texture.image = 0;
    m.emissive_factor = {0.5f, 1.0f, 2.0f};
    const int32_t opaque = addMaterial(s, m);
    m.alpha_mode = raster::AlphaMode::Blend; // the texels' alpha counts: only all-zero is skipped
    const int32_t blend = addMaterial(s, m);
    const float sizes[3] = {6.0f, 30.0f, 90.0f}; // half-widths in pixels at the pixel plane
    const float x_at[3] = {-70.0f, -40.0f, 30.0f};
    for (const int32_t mat : {opaque, blend})
        for (int q = 0; q < 3; ++q) {
            const float r = sizes[q], cx = x_at[q], cy = mat == opaque ? -50.0f : 50.0f;
            raster::Primitive& p = addMesh(s,
                                           {{cx - r, cy - r, -64},
                                            {cx + r, cy - r, -64},
                                            {cx + r, cy + r, -64},
                                            {cx - r, cy + r, -64}},
                                           {0, 1, 2, 0, 2, 3}, mat);
            p.texcoords0 = {{-0.3f, 1.3f}, {1.3f, 1.2f}, {1.2f, -0.2f}, {-0.2f, -0.3f}};
        }
    // Coordinates far beyond any level (finite, but no integer type holds their texel index):
    // sampled, not asked about the blocks.
    raster::Primitive& huge =
        addMesh(s, {{60, 60, -64}, {100, 60, -64}, {100, 100, -64}, {60, 100, -64}},
                {0, 1, 2, 0, 2, 3}, opaque);
    huge.texcoords0 = {{1e30f, 1e30f}, {-1e30f, 1e30f}, {1e30f, 2e30f}, {3e30f, -1e30f}};
    raster::Scene unknown = s; // the same texels, no zero blocks known: everything is sampled
    unknown.images[0].zero_colour_blocks = unknown.images[0].zero_blocks = false;
    const raster::View v = pixelView(256, 256, 64.0f);
    for (const FilterOverride f : {FilterOverride::Sampler, FilterOverride::Nearest,
                                   FilterOverride::Bilinear, FilterOverride::Trilinear})
        for (const bool simd : {true, false}) {
            raster::RenderOptions o;
            o.texture_filter = f;
            o.simd = simd;
            const raster::Frame skipped = render(s, v, o), sampled = render(unknown, v, o);
            ASSERT_EQ(skipped.color.size(), sampled.color.size());
            size_t differ = 0;
            for (size_t i = 0; i < skipped.color.size(); ++i)
                differ += std::bit_cast<uint32_t>(skipped.color[i]) !=
                          std::bit_cast<uint32_t>(sampled.color[i]);
            EXPECT_EQ(differ, 0u) << "filter " << int(f) << " simd " << simd;
        }
}

// Each 2x2 quad selects its mip level from its own derivatives, and the tile raster packs the
// lanes of a triangle's quads for the texture kernel (tile_raster.cpp, FragmentQueue), so a lane
// must be filtered on its own quad's levels even when the quads before it in the queue read
// others. A plane turned away from the eye, cut into small triangles (whose ends empty the
// queue) or large ones (whose full pairs are shaded in place), with an image whose every level
// is one colour and nearest mip filtering: every pixel
// shows the level its quad's derivatives select, computed here from the plane's analytic
// texture coordinates (quads within 0.01 of a level boundary are not judged).
TEST(Texture, EachQuadReadsTheLevelOfItsOwnDerivatives) {
    constexpr uint32_t kTexels = 256, kW = 96, kH = 160;
    Image img = makeImage(kTexels, kTexels, false, [](uint32_t, uint32_t) { return 255; });
    auto levelColour = [](size_t k) {
        return glm::u8vec4(uint8_t(20 + 25 * k), uint8_t(235 - 20 * k), uint8_t(k % 2 ? 200 : 40),
                           255);
    };
    for (size_t k = 0; k < img.levels.size(); ++k) {
        raster::MipLevel& level = img.levels[k];
        const glm::u8vec4 c = levelColour(k);
        for (size_t t = 0; t < size_t(level.width) * level.height; ++t)
            for (int ch = 0; ch < 4; ++ch) {
                level.rgba8[4 * t + size_t(ch)] = c[ch];
                if (!level.linear.empty())
                    level.linear[4 * t + size_t(ch)] = float(int32_t(c[ch])) * (1.0f / 255.0f);
            }
    }
    img.zero_colour_blocks = img.zero_blocks = false;
    const float max_level = float(img.levels.size() - 1);

    Sampler nearest;
    nearest.mag = nearest.min = Filter::Nearest;
    nearest.mip = MipFilter::Nearest;
    raster::Material m = flatMaterial({1, 1, 1, 1});
    m.base_color_texture.image = 0;
    m.base_color_texture.sampler = 0;
    // The plane P(a, b) = (x0 + a lx, y0 + b ly, -(d0 + a kx + b lz)), a, b in [0, 1], with uv =
    // (su a, sv b), over the whole view, turned so the level changes along rows and columns,
    // cut into a grid of cells, two triangles each: small (1 to 10 pixels) or large ones.
    constexpr double x0 = -400.0, lx = 800.0, y0 = -150.0, ly = 750.0, d0 = 50.0, lz = 400.0;
    constexpr double kx = 300.0;
    constexpr double su = 8.0, sv = 24.0;
    auto planeScene = [&](uint32_t cells_a, uint32_t cells_b) {
        raster::Scene s;
        s.images.push_back(img);
        s.samplers.push_back(nearest);
        const int32_t mat = addMaterial(s, m);
        std::vector<glm::vec3> positions;
        std::vector<glm::vec2> uvs;
        std::vector<uint32_t> indices;
        for (uint32_t j = 0; j <= cells_b; ++j)
            for (uint32_t i = 0; i <= cells_a; ++i) {
                const double a = double(i) / cells_a, b = double(j) / cells_b;
                positions.emplace_back(float(x0 + a * lx), float(y0 + b * ly),
                                       float(-(d0 + a * kx + b * lz)));
                uvs.emplace_back(float(su * a), float(sv * b));
            }
        for (uint32_t j = 0; j < cells_b; ++j)
            for (uint32_t i = 0; i < cells_a; ++i) {
                const uint32_t v = j * (cells_a + 1) + i, up = v + cells_a + 1;
                indices.insert(indices.end(), {v, v + 1, up + 1, v, up + 1, up});
            }
        addMesh(s, positions, indices, mat).texcoords0 = uvs;
        return s;
    };
    raster::View view = pixelView(kW, kH, 64.0f);
    view.zfar = 1000.0f;

    // Where the eye ray through pixel centre (x + 1/2, y + 1/2), direction (x + 1/2 - W/2,
    // H/2 - y - 1/2, -64), meets the plane: (a, b) and the distance along the view axis.
    struct Hit {
        double a, b, depth;
    };
    auto hitAt = [&](double x, double y) {
        const double dx = x + 0.5 - kW / 2.0, dy = kH / 2.0 - y - 0.5, dz = 64.0;
        // lambda dx = x0 + a lx, lambda dy = y0 + b ly and lambda dz = d0 + a kx + b lz.
        const double lambda =
            (d0 - kx * x0 / lx - lz * y0 / ly) / (dz - kx * dx / lx - lz * dy / ly);
        return Hit{(lambda * dx - x0) / lx, (lambda * dy - y0) / ly, lambda * dz};
    };
    auto onPlane = [&](const Hit& h) {
        return h.a > 0.001 && h.a < 0.999 && h.b > 0.001 && h.b < 0.999 && h.depth < 990.0;
    };
    // The texture coordinates there, in texels.
    auto texelAt = [&](double x, double y) {
        const Hit h = hitAt(x, y);
        return glm::dvec2(su * h.a * kTexels, sv * h.b * kTexels);
    };
    int judged = 0;
    uint32_t seen = 0; // bit k: a judged pixel read level k
    for (const uint32_t cells : {100u, 4u})
        for (const bool simd : {true, false}) {
            raster::RenderOptions o;
            o.simd = simd;
            const raster::Frame f = render(planeScene(cells, cells * 6 / 5), view, o);
            for (uint32_t qy = 0; qy + 1 < kH; qy += 2)
                for (uint32_t qx = 0; qx + 1 < kW; qx += 2) {
                    const glm::dvec2 t0 = texelAt(qx, qy);
                    const glm::dvec2 ddx = texelAt(qx + 1, qy) - t0, ddy = texelAt(qx, qy + 1) - t0;
                    const double rho2 = std::max(glm::dot(ddx, ddx), glm::dot(ddy, ddy));
                    const double lod =
                        rho2 > 1.0 ? std::min(0.5 * std::log2(rho2), double(max_level)) : 0.0;
                    const double frac = lod - std::floor(lod);
                    if (rho2 > 1.0 && (std::fabs(frac - 0.5) < 0.01 || lod < 0.01))
                        continue;
                    const size_t k = size_t(std::floor(lod + 0.5));
                    const glm::u8vec4 c = levelColour(k);
                    const glm::vec4 want(float(int32_t(c.r)) / 255.0f, float(int32_t(c.g)) / 255.0f,
                                         float(int32_t(c.b)) / 255.0f, 1.0f);
                    for (uint32_t y = qy; y < qy + 2; ++y)
                        for (uint32_t x = qx; x < qx + 2; ++x) {
                            if (!onPlane(hitAt(x, y)))
                                continue;
                            const glm::vec4 got = pixel(f, x, y);
                            EXPECT_NEAR(got.r, want.r, 1e-6f)
                                << "pixel " << x << "," << y << " lod " << lod << " simd " << simd
                                << " cells " << cells;
                            EXPECT_NEAR(got.g, want.g, 1e-6f) << "pixel " << x << "," << y;
                            ++judged;
                            seen |= 1u << k;
                        }
                }
        }
    // Four renders of 96 x 160 pixels: the plane covers most, few quads lie at a boundary.
    EXPECT_GT(judged, 4 * 9000);
    EXPECT_GE(std::popcount(seen), 4); // the plane spans several levels
}

// The tile raster prepares the emissive lookup from the base colour's when both read the same
// coordinates and levels (sameFootprint: texture coordinates, transform, sampler, image size and
// levels): a frame with both textures must be, pixel by pixel, the sum of the frames with each
// alone (unlit: base colour + emissive), whichever of those the two textures share.
TEST(Texture, EmissiveReadsItsOwnCoordinatesAndLevels) {
    const Image a =
        makeImage(64, 64, true, [](uint32_t x, uint32_t y) { return (x * 7 + y * 3) % 256; });
    const Image b =
        makeImage(64, 64, true, [](uint32_t x, uint32_t y) { return (x * 5 + y * 11) % 256; });
    const Image small =
        makeImage(32, 64, true, [](uint32_t x, uint32_t y) { return (x * 9 + y) % 256; });
    glm::mat3 scaled(1.0f);
    scaled[0][0] = 2.0f;
    scaled[2][1] = 0.25f;
    struct Case {
        const Image* emissive;
        glm::mat3 transform;
        int32_t sampler;
    };
    const Case cases[] = {{&b, glm::mat3(1.0f), 0},     // shared
                          {&b, scaled, 0},              // another transform
                          {&small, glm::mat3(1.0f), 0}, // another size
                          {&b, glm::mat3(1.0f), 1}};    // another sampler
    Sampler nearest_mips;
    nearest_mips.mip = MipFilter::Nearest;
    int checked = 0, lit = 0;
    for (const Case& c : cases) {
        auto frame = [&](bool base, bool emissive) {
            raster::Scene s;
            s.images = {a, *c.emissive};
            s.samplers = {Sampler{}, nearest_mips};
            raster::Material m = flatMaterial(base ? glm::vec4(1.0f) : glm::vec4(0, 0, 0, 1));
            if (base) {
                m.base_color_texture.image = 0;
                m.base_color_texture.sampler = 0;
            }
            if (emissive) {
                m.emissive_factor = glm::vec3(1.0f);
                m.emissive_texture.image = 1;
                m.emissive_texture.sampler = c.sampler;
                m.emissive_texture.transform = c.transform;
            }
            // A quad turned away from the eye (several levels), in small and large triangles.
            raster::Primitive& p = addMesh(
                s, {{-60, -50, -70}, {60, -50, -70}, {60, 50, -200}, {-60, 50, -200}, {0, 0, -120}},
                {0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 4}, addMaterial(s, m));
            p.texcoords0 = {{0, 3}, {3, 3}, {3, 0}, {0, 0}, {1.5f, 1.2f}};
            return render(s, pixelView(96, 80, 64.0f));
        };
        const raster::Frame both = frame(true, true), base = frame(true, false),
                            emissive = frame(false, true);
        for (uint32_t y = 0; y < 80; ++y)
            for (uint32_t x = 0; x < 96; ++x) {
                const glm::vec4 sum = pixel(base, x, y) + pixel(emissive, x, y);
                const glm::vec4 got = pixel(both, x, y);
                ASSERT_EQ(got.r, sum.r) << x << "," << y << " case " << checked / (96 * 80);
                ASSERT_EQ(got.g, sum.g) << x << "," << y;
                ASSERT_EQ(got.b, sum.b) << x << "," << y;
                ++checked;
                lit += pixel(base, x, y).r > 0.0f && pixel(emissive, x, y).r > 0.0f;
            }
    }
    EXPECT_EQ(checked, 4 * 96 * 80);
    EXPECT_GT(lit, 4 * 96 * 40); // both textures seen on most pixels
}

} // namespace
} // namespace focal::test
