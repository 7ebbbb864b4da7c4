// The AVX2 build of the lighting kernel (compiled with -mavx2; see raster/CMakeLists.txt).
#include "light_kernel.h"

#ifndef FOCAL_NO_SIMD
#if !defined(__AVX2__)
#error "light_kernel_avx2.cpp must be compiled with -mavx2"
#endif

namespace raster {

namespace {
#define FOCAL_LIGHT_KERNEL_NAME lightKernelAvx2Impl
#define FOCAL_LIGHT_KERNEL_FULL_WIDTH 1
#include "light_kernel.inl"
#undef FOCAL_LIGHT_KERNEL_FULL_WIDTH
#undef FOCAL_LIGHT_KERNEL_NAME
} // namespace

LightKernel lightKernelAvx2() {
    return &lightKernelAvx2Impl;
}

} // namespace raster
#endif
