// Error metrics between two images: what every DOF method is measured with against `accum`.
// Consumes plain float images (linear light, interleaved, top row first) and optionally a depth
// image; produces PSNR, SSIM and absolute errors over all pixels or a pixel mask, the
// depth-discontinuity band mask, and a false-colour difference image. Results are owned by the
// caller. Deterministic: fixed summation order, double accumulators.
#pragma once

#include <raster/status.h>

#include <cstdint>
#include <vector>

namespace dof {

// A read-only image: `channels` floats per pixel (1 = grey, 2 = grey+alpha, >= 3 = RGB first).
struct ImageRef {
    const float* pixels = nullptr;
    uint32_t width = 0;
    uint32_t height = 0;
    uint32_t channels = 0;
};

struct ErrorMetrics {
    uint64_t pixels = 0;       // pixels the metrics cover
    double psnr_linear_db = 0; // linear RGB clamped to [0,1]; +inf when identical there
    double psnr_srgb_db = 0;   // sRGB-encoded RGB (of the clamped values); +inf when identical
    double ssim = 1;           // mean SSIM of the luma of sRGB values (see below)
    uint64_t ssim_windows = 0; // window centres averaged (pixels >= 5 px from the border)
    double mean_abs_error = 0; // linear RGB, unclamped, mean over pixels and 3 channels
    double max_abs_error = 0;  // linear RGB, unclamped, largest channel difference
};

// SSIM parameters of Wang, Bovik, Sheikh & Simoncelli 2004, Sec. III-C: 11x11 circular-symmetric
// Gaussian window, sigma 1.5, K1 = 0.01, K2 = 0.03, dynamic range L = 1. The luma is
// Y = 0.2126 R' + 0.7152 G' + 0.0722 B' of sRGB-encoded, clamped values. Windows must fit
// inside the image (their 'valid' convolution), so SSIM is averaged over centres at least 5 px
// from every border.
constexpr int kSsimRadius = 5;
constexpr double kSsimSigma = 1.5;
constexpr double kSsimK1 = 0.01;
constexpr double kSsimK2 = 0.03;

// Compares `a` with `b` (same size; RGB read as in ImageRef). With `mask` (width*height bytes,
// nonzero = included), every metric covers only masked pixels (SSIM: masked window centres).
// Fails on mismatched sizes, images smaller than 11x11, non-finite values, or an empty mask.
raster::Result<ErrorMetrics> compareImages(const ImageRef& a, const ImageRef& b,
                                           const std::vector<uint8_t>* mask = nullptr);

// The pixels where `a` and `b` (same size) differ by more than `tolerance` in some channel,
// alpha included (channels beyond the smaller count are ignored). Samples with equal bits never
// differ; a NaN differs from anything but its own bits. Values as stored (linear, unclamped).
uint64_t countDifferingPixels(const ImageRef& a, const ImageRef& b, float tolerance);

// Depth-discontinuity band. A pixel is an edge pixel when one of its 4-neighbours' depths
// differs by more than `relative_jump` times the smaller of the two (infinite or non-positive
// depth, i.e. background, differs from any finite depth). The band is every pixel within
// Euclidean distance `radius_px` of an edge pixel (both sides of the edge). `depth` holds one
// distance per pixel (channel 0 of `depth` is used). Allocates the returned mask and its work
// arrays: std::bad_alloc when that fails, as from the vector (a helper for comparisons and
// benchmarks; no frame calls it).
std::vector<uint8_t> discontinuityBand(const ImageRef& depth, float relative_jump, float radius_px);

// False-colour difference: per pixel the largest |a - b| over RGB of sRGB-encoded values,
// divided by `scale` and clamped, through a black-blue-magenta-orange-yellow ramp. Returns RGB
// floats (width*height*3, linear values for an EXR or PNG writer). Allocates the returned
// image: std::bad_alloc when that fails, as from the vector (no frame calls it).
std::vector<float> falseColorDifference(const ImageRef& a, const ImageRef& b, float scale);

// sRGB transfer function (IEC 61966-2-1) for values in [0,1].
double srgbEncode(double linear);

} // namespace dof
