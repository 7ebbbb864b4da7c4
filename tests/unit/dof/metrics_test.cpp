// dof/metrics.h on known cases: identical images, a known noise level, shifted images, the
// SSIM formula on constant images, and the depth-discontinuity band.
#include <dof/metrics.h>

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace focal::test {
namespace {

struct Img {
    uint32_t w, h;
    std::vector<float> px; // RGB
    dof::ImageRef ref() const { return {px.data(), w, h, 3}; }
};

Img constant(uint32_t w, uint32_t h, float v) {
    return {w, h, std::vector<float>(w * h * 3, v)};
}

Img checker(uint32_t w, uint32_t h, uint32_t shift) {
    Img img = constant(w, h, 0.0f);
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c)
                img.px[(y * w + x) * 3 + c] = (((x + shift) / 4 + y / 4) & 1) ? 0.8f : 0.1f;
    return img;
}

TEST(Metrics, IdenticalImages) {
    const Img a = checker(32, 24, 0);
    const auto m = dof::compareImages(a.ref(), a.ref());
    ASSERT_TRUE(m.ok());
    EXPECT_TRUE(std::isinf(m->psnr_linear_db));
    EXPECT_TRUE(std::isinf(m->psnr_srgb_db));
    EXPECT_DOUBLE_EQ(m->ssim, 1.0);
    EXPECT_EQ(m->mean_abs_error, 0.0);
    EXPECT_EQ(m->max_abs_error, 0.0);
    EXPECT_EQ(m->pixels, 32u * 24u);
    EXPECT_EQ(m->ssim_windows, 22u * 14u);
}

TEST(Metrics, KnownNoiseLevel) {
    // +-0.1 on every channel: MSE = 0.01, PSNR = 20 dB exactly; mean |e| = max |e| = 0.1.
    const Img a = constant(40, 30, 0.5f);
    Img b = a;
    for (size_t i = 0; i < b.px.size(); ++i)
        b.px[i] += ((i / 3 + i / 120) & 1) ? 0.1f : -0.1f;
    const auto m = dof::compareImages(a.ref(), b.ref());
    ASSERT_TRUE(m.ok());
    EXPECT_NEAR(m->psnr_linear_db, 20.0, 1e-4);
    EXPECT_NEAR(m->mean_abs_error, 0.1, 1e-6);
    EXPECT_NEAR(m->max_abs_error, 0.1, 1e-6);
    EXPECT_LT(m->ssim, 0.5);
    // sRGB: |encode(0.6) - encode(0.5)| and |encode(0.4) - encode(0.5)|, averaged as squares.
    const double e1 = dof::srgbEncode(0.6) - dof::srgbEncode(0.5),
                 e2 = dof::srgbEncode(0.5) - dof::srgbEncode(0.4);
    EXPECT_NEAR(m->psnr_srgb_db, 10.0 * std::log10(1.0 / (0.5 * (e1 * e1 + e2 * e2))), 0.05);
}

TEST(Metrics, ClampsToTheUnitRangeForPsnr) {
    const Img a = constant(16, 16, 1.0f), b = constant(16, 16, 5.0f);
    const auto m = dof::compareImages(a.ref(), b.ref());
    ASSERT_TRUE(m.ok());
    EXPECT_TRUE(std::isinf(m->psnr_linear_db)); // both clamp to 1
    EXPECT_NEAR(m->max_abs_error, 4.0, 1e-6);   // absolute errors are unclamped
}

TEST(Metrics, SsimOfConstantImagesFollowsTheLuminanceTerm) {
    // Constant images: sigma = 0, so SSIM = (2 mu_a mu_b + C1) / (mu_a^2 + mu_b^2 + C1).
    const Img a = constant(16, 16, 0.2f), b = constant(16, 16, 0.4f);
    const auto m = dof::compareImages(a.ref(), b.ref());
    ASSERT_TRUE(m.ok());
    const double ya = dof::srgbEncode(0.2), yb = dof::srgbEncode(0.4), c1 = 0.01 * 0.01;
    EXPECT_NEAR(m->ssim, (2 * ya * yb + c1) / (ya * ya + yb * yb + c1), 1e-9);
}

TEST(Metrics, ShiftedImage) {
    const Img a = checker(48, 48, 0), b = checker(48, 48, 1), c = checker(48, 48, 2);
    const auto m1 = dof::compareImages(a.ref(), b.ref());
    const auto m2 = dof::compareImages(a.ref(), c.ref());
    ASSERT_TRUE(m1.ok() && m2.ok());
    // A one-pixel shift of 4-pixel squares changes 1/4 of the pixels by 0.7.
    EXPECT_NEAR(m1->mean_abs_error, 0.25 * 0.7, 1e-6);
    EXPECT_NEAR(m1->max_abs_error, 0.7, 1e-6);
    EXPECT_NEAR(m1->psnr_linear_db, 10.0 * std::log10(1.0 / (0.25 * 0.49)), 1e-4);
    // Shifting further makes everything worse.
    EXPECT_LT(m2->psnr_linear_db, m1->psnr_linear_db);
    EXPECT_LT(m2->ssim, m1->ssim);
    EXPECT_LT(m1->ssim, 0.95);
}

TEST(Metrics, Errors) {
    const Img a = constant(16, 16, 0.5f), b = constant(16, 17, 0.5f), tiny = constant(8, 8, 0.f);
    EXPECT_FALSE(dof::compareImages(a.ref(), b.ref()).ok());
    EXPECT_FALSE(dof::compareImages(tiny.ref(), tiny.ref()).ok());
    Img nan = a;
    nan.px[5] = NAN;
    EXPECT_FALSE(dof::compareImages(a.ref(), nan.ref()).ok());
    const std::vector<uint8_t> empty(16 * 16, 0);
    EXPECT_FALSE(dof::compareImages(a.ref(), a.ref(), &empty).ok());
}

TEST(Metrics, DiscontinuityBandAndMaskedMetrics) {
    // Depth 10 on the left half, 20 on the right (x >= 16): edges at x = 15 and 16.
    const uint32_t w = 32, h = 20;
    std::vector<float> depth(w * h);
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x)
            depth[y * w + x] = x < 16 ? 10.0f : 20.0f;
    const dof::ImageRef dref{depth.data(), w, h, 1};
    const std::vector<uint8_t> band = dof::discontinuityBand(dref, 0.05f, 2.0f);
    for (uint32_t x = 0; x < w; ++x)
        EXPECT_EQ(band[5 * w + x], (x >= 13 && x <= 18) ? 1 : 0) << x;
    // Below the threshold: no band.
    const std::vector<uint8_t> none = dof::discontinuityBand(dref, 1.5f, 2.0f);
    for (uint8_t v : none)
        EXPECT_EQ(v, 0);
    // Background (inf) next to geometry is an edge.
    depth[0] = INFINITY;
    EXPECT_EQ(dof::discontinuityBand(dref, 1.5f, 0.0f)[1], 1);

    // Errors only outside the band: masked metrics see identical images.
    const Img a = constant(w, h, 0.5f);
    Img b = a;
    for (uint32_t y = 0; y < h; ++y)
        for (int c = 0; c < 3; ++c)
            b.px[(y * w + 2) * 3 + c] = 0.9f;
    const auto masked = dof::compareImages(a.ref(), b.ref(), &band);
    ASSERT_TRUE(masked.ok());
    EXPECT_TRUE(std::isinf(masked->psnr_linear_db));
    EXPECT_EQ(masked->pixels, 6u * h);
    const auto all = dof::compareImages(a.ref(), b.ref());
    EXPECT_FALSE(std::isinf(all->psnr_linear_db));
}

TEST(Metrics, FalseColourDifference) {
    const Img a = constant(4, 4, 0.5f);
    Img b = a;
    b.px[0] = 1.0f;
    const std::vector<float> diff = dof::falseColorDifference(a.ref(), b.ref(), 0.1f);
    ASSERT_EQ(diff.size(), 4u * 4u * 3u);
    EXPECT_EQ(diff[3], 0.0f);                     // identical pixel: black
    EXPECT_GT(diff[0] + diff[1] + diff[2], 2.0f); // saturated: the light end of the ramp
}

} // namespace
} // namespace focal::test
