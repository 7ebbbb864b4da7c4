#include "out_of_memory.h"

#include <dof/metrics.h>
#include <raster/check.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <new>
#include <string>

namespace dof {

using raster::Status;

namespace {

// RGB of pixel i (grey replicated for 1-2 channel images).
void rgbOf(const ImageRef& img, size_t i, double out[3]) {
    const float* p = img.pixels + i * img.channels;
    if (img.channels >= 3) {
        out[0] = double(p[0]), out[1] = double(p[1]), out[2] = double(p[2]);
    } else {
        out[0] = out[1] = out[2] = double(p[0]);
    }
}

double clamp01(double v) {
    return std::clamp(v, 0.0, 1.0);
}

double psnrFromMse(double mse) {
    return mse > 0.0 ? 10.0 * std::log10(1.0 / mse) : std::numeric_limits<double>::infinity();
}

// Luma of sRGB-encoded, clamped RGB for every pixel.
std::vector<double> lumaOf(const ImageRef& img) {
    const size_t n = size_t(img.width) * img.height;
    std::vector<double> y(n);
    for (size_t i = 0; i < n; ++i) {
        double c[3];
        rgbOf(img, i, c);
        y[i] = 0.2126 * srgbEncode(clamp01(c[0])) + 0.7152 * srgbEncode(clamp01(c[1])) +
               0.0722 * srgbEncode(clamp01(c[2]));
    }
    return y;
}

// Separable Gaussian window (normalised to sum 1).
std::vector<double> gaussianWindow() {
    std::vector<double> g(2 * kSsimRadius + 1);
    double sum = 0.0;
    for (int k = -kSsimRadius; k <= kSsimRadius; ++k) {
        g[size_t(k + kSsimRadius)] = std::exp(-double(k * k) / (2.0 * kSsimSigma * kSsimSigma));
        sum += g[size_t(k + kSsimRadius)];
    }
    for (double& v : g)
        v /= sum;
    return g;
}

// Gaussian-weighted local mean of `src` at every valid centre (horizontal pass then vertical).
std::vector<double> blurValid(const std::vector<double>& src, uint32_t w, uint32_t h,
                              const std::vector<double>& g) {
    const int r = kSsimRadius;
    const uint32_t ow = w - 2 * r, oh = h - 2 * r;
    std::vector<double> tmp(size_t(ow) * h), dst(size_t(ow) * oh);
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < ow; ++x) {
            double s = 0.0;
            for (int k = 0; k <= 2 * r; ++k)
                s += g[size_t(k)] * src[size_t(y) * w + x + uint32_t(k)];
            tmp[size_t(y) * ow + x] = s;
        }
    for (uint32_t y = 0; y < oh; ++y)
        for (uint32_t x = 0; x < ow; ++x) {
            double s = 0.0;
            for (int k = 0; k <= 2 * r; ++k)
                s += g[size_t(k)] * tmp[size_t(y + uint32_t(k)) * ow + x];
            dst[size_t(y) * ow + x] = s;
        }
    return dst;
}

} // namespace

double srgbEncode(double linear) {
    return linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055;
}

raster::Result<ErrorMetrics> compareImages(const ImageRef& a, const ImageRef& b,
                                           const std::vector<uint8_t>* mask) try {
    if (a.width != b.width || a.height != b.height)
        return Status::error("images differ in size: " + std::to_string(a.width) + "x" +
                             std::to_string(a.height) + " vs " + std::to_string(b.width) + "x" +
                             std::to_string(b.height));
    if (a.channels == 0 || b.channels == 0 || !a.pixels || !b.pixels)
        return Status::error("an image has no channels");
    const uint32_t w = a.width, h = a.height;
    if (w < 2 * kSsimRadius + 1 || h < 2 * kSsimRadius + 1)
        return Status::error("images must be at least 11x11 for SSIM's 11x11 window, got " +
                             std::to_string(w) + "x" + std::to_string(h));
    const size_t n = size_t(w) * h;
    if (mask && mask->size() != n)
        return Status::error("pixel mask does not match the image size");
    auto included = [&](size_t i) { return !mask || (*mask)[i] != 0; };

    // PSNR and absolute errors over the included pixels.
    ErrorMetrics m;
    double se_lin = 0.0, se_srgb = 0.0, abs_sum = 0.0, abs_max = 0.0;
    for (size_t i = 0; i < n; ++i) {
        double ca[3], cb[3];
        rgbOf(a, i, ca);
        rgbOf(b, i, cb);
        for (int c = 0; c < 3; ++c)
            if (!std::isfinite(ca[c]) || !std::isfinite(cb[c]))
                return Status::error("pixel " + std::to_string(i % w) + "," +
                                     std::to_string(i / w) + " is not a finite number");
        if (!included(i))
            continue;
        ++m.pixels;
        for (int c = 0; c < 3; ++c) {
            const double la = clamp01(ca[c]), lb = clamp01(cb[c]);
            se_lin += (la - lb) * (la - lb);
            const double sa = srgbEncode(la), sb = srgbEncode(lb);
            se_srgb += (sa - sb) * (sa - sb);
            const double e = std::fabs(ca[c] - cb[c]);
            abs_sum += e;
            abs_max = std::max(abs_max, e);
        }
    }
    if (m.pixels == 0)
        return Status::error("the pixel mask selects no pixels");
    const double count = 3.0 * double(m.pixels);
    m.psnr_linear_db = psnrFromMse(se_lin / count);
    m.psnr_srgb_db = psnrFromMse(se_srgb / count);
    m.mean_abs_error = abs_sum / count;
    m.max_abs_error = abs_max;

    // SSIM (Wang et al. 2004, Eq. 13 with local Gaussian statistics, Sec. III-C).
    const std::vector<double> ya = lumaOf(a), yb = lumaOf(b);
    std::vector<double> aa(n), bb(n), ab(n);
    for (size_t i = 0; i < n; ++i) {
        aa[i] = ya[i] * ya[i];
        bb[i] = yb[i] * yb[i];
        ab[i] = ya[i] * yb[i];
    }
    const std::vector<double> g = gaussianWindow();
    const std::vector<double> mu_a = blurValid(ya, w, h, g), mu_b = blurValid(yb, w, h, g);
    const std::vector<double> e_aa = blurValid(aa, w, h, g), e_bb = blurValid(bb, w, h, g),
                              e_ab = blurValid(ab, w, h, g);
    const double c1 = (kSsimK1 * 1.0) * (kSsimK1 * 1.0), c2 = (kSsimK2 * 1.0) * (kSsimK2 * 1.0);
    const uint32_t ow = w - 2 * kSsimRadius, oh = h - 2 * kSsimRadius;
    double ssim_sum = 0.0;
    for (uint32_t y = 0; y < oh; ++y)
        for (uint32_t x = 0; x < ow; ++x) {
            const size_t centre = size_t(y + kSsimRadius) * w + x + kSsimRadius;
            if (!included(centre))
                continue;
            const size_t k = size_t(y) * ow + x;
            const double ma = mu_a[k], mb = mu_b[k];
            const double va = e_aa[k] - ma * ma, vb = e_bb[k] - mb * mb, cov = e_ab[k] - ma * mb;
            ssim_sum += ((2.0 * ma * mb + c1) * (2.0 * cov + c2)) /
                        ((ma * ma + mb * mb + c1) * (va + vb + c2));
            ++m.ssim_windows;
        }
    m.ssim = m.ssim_windows ? ssim_sum / double(m.ssim_windows)
                            : std::numeric_limits<double>::quiet_NaN();
    return m;
} catch (const std::bad_alloc&) {
    return detail::outOfMemory("comparing images");
}

uint64_t countDifferingPixels(const ImageRef& a, const ImageRef& b, float tolerance) {
    FOCAL_CHECK(a.width == b.width && a.height == b.height);
    const uint32_t channels = std::min(a.channels, b.channels);
    const size_t n = size_t(a.width) * a.height;
    uint64_t differing = 0;
    for (size_t i = 0; i < n; ++i) {
        const float* pa = a.pixels + i * a.channels;
        const float* pb = b.pixels + i * b.channels;
        bool differs = false;
        for (uint32_t c = 0; c < channels && !differs; ++c)
            differs = std::bit_cast<uint32_t>(pa[c]) != std::bit_cast<uint32_t>(pb[c]) &&
                      !(std::fabs(pa[c] - pb[c]) <= tolerance);
        differing += differs;
    }
    return differing;
}

std::vector<uint8_t> discontinuityBand(const ImageRef& depth, float relative_jump,
                                       float radius_px) {
    const uint32_t w = depth.width, h = depth.height;
    const size_t n = size_t(w) * h;
    auto d = [&](uint32_t x, uint32_t y) {
        return depth.pixels[(size_t(y) * w + x) * depth.channels];
    };
    auto jump = [&](float p, float q) {
        const bool fp = std::isfinite(p) && p > 0.0f, fq = std::isfinite(q) && q > 0.0f;
        if (fp != fq)
            return true;
        if (!fp)
            return false;
        return std::fabs(p - q) > relative_jump * std::min(p, q);
    };
    std::vector<uint8_t> edge(n, 0);
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            const float p = d(x, y);
            if ((x + 1 < w && jump(p, d(x + 1, y))) || (x > 0 && jump(p, d(x - 1, y))) ||
                (y + 1 < h && jump(p, d(x, y + 1))) || (y > 0 && jump(p, d(x, y - 1))))
                edge[size_t(y) * w + x] = 1;
        }
    // Dilate by a disc of radius_px.
    const int r = std::max(0, int(std::floor(radius_px)));
    const float r2 = radius_px * radius_px;
    std::vector<uint8_t> band(n, 0);
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            if (!edge[size_t(y) * w + x])
                continue;
            for (int dy = -r; dy <= r; ++dy)
                for (int dx = -r; dx <= r; ++dx) {
                    if (float(dx * dx + dy * dy) > r2)
                        continue;
                    const int64_t bx = int64_t(x) + dx, by = int64_t(y) + dy;
                    if (bx < 0 || by < 0 || bx >= int64_t(w) || by >= int64_t(h))
                        continue;
                    band[size_t(by) * w + size_t(bx)] = 1;
                }
        }
    return band;
}

std::vector<float> falseColorDifference(const ImageRef& a, const ImageRef& b, float scale) {
    // Ramp stops (linear RGB): black, blue, magenta, orange, light yellow.
    static constexpr float kStops[5][3] = {{0.0f, 0.0f, 0.0f},
                                           {0.0f, 0.05f, 0.6f},
                                           {0.6f, 0.0f, 0.5f},
                                           {1.0f, 0.35f, 0.0f},
                                           {1.0f, 1.0f, 0.5f}};
    const size_t n = size_t(a.width) * a.height;
    std::vector<float> out(n * 3);
    for (size_t i = 0; i < n; ++i) {
        double ca[3], cb[3];
        rgbOf(a, i, ca);
        rgbOf(b, i, cb);
        double e = 0.0;
        for (int c = 0; c < 3; ++c)
            e = std::max(e, std::fabs(srgbEncode(clamp01(ca[c])) - srgbEncode(clamp01(cb[c]))));
        const double t = std::isfinite(e) ? std::clamp(e / double(scale), 0.0, 1.0) * 4.0 : 4.0;
        const int k = std::min(3, int(t));
        const double f = t - double(k);
        for (int c = 0; c < 3; ++c)
            out[i * 3 + size_t(c)] =
                float((1.0 - f) * double(kStops[k][c]) + f * double(kStops[k + 1][c]));
    }
    return out;
}

} // namespace dof
