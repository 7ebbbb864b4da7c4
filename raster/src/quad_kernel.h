// The SIMD kernel of the tile raster: coverage, barycentrics, perspective correction and depth
// for a pair of 2x2 quads (8 pixels) at once. Written once (quad_kernel.inl) as lane loops and
// compiled twice: plain (the scalar reference, always built) and with AVX2 (quad_kernel_avx2.cpp),
// chosen at run time. Edge functions are integers below 2^50 (geometry.h), exact in double, and
// the build never contracts a*b+c into an FMA, so both variants produce the same bits
// (tests/unit/raster/simd_test.cpp).
#pragma once

#include <raster/storage.h>

#include <cstdint>

namespace raster {

constexpr int kQuadLanes = 8; // two horizontally adjacent 2x2 quads; lane = quad*4 + dy*2 + dx

struct QuadInput {
    double edge[3];   // edge function values at the first pixel centre (exact integers)
    double step_x[3]; // change of each edge function per pixel in x
    double step_y[3]; // per pixel in y
    double bias[3];   // 0 or -1: the top-left rule
    double inv_area2; // 1 / (2 * area)
    float inv_w[3];   // per vertex
    float z[3];       // stored depth D per vertex
    uint32_t valid;   // lanes inside the viewport
};

struct QuadOutput {
    uint32_t mask;              // covered lanes
    float persp[3][kQuadLanes]; // perspective-correct barycentrics
    float distance[kQuadLanes]; // view distance d = w
    float z[kQuadLanes];        // stored depth D, clamped to [-1, 0]
};

using QuadKernel = void (*)(const QuadInput&, QuadOutput&);

// The number of lanes set in a quad pair's mask, without a call: the baseline x86-64 build has
// no popcnt instruction, so std::popcount is a library call there (1 % of a demo frame).
constexpr uint32_t laneCount(uint32_t mask) {
    static_assert(kQuadLanes == 8);
    mask = mask - ((mask >> 1) & 0x55u);
    mask = (mask & 0x33u) + ((mask >> 2) & 0x33u);
    return (mask + (mask >> 4)) & 0x0fu;
}

void quadKernelScalar(const QuadInput& in, QuadOutput& out);
// The AVX2 build of the same kernel; nullptr when not compiled in (FOCAL_NO_SIMD).
QuadKernel quadKernelAvx2();
// The fastest kernel this CPU runs, or the scalar reference when `simd` is false.
QuadKernel selectQuadKernel(bool simd);

} // namespace raster
