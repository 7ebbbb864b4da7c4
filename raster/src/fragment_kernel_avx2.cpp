// The AVX2 build of the fragment kernel (compiled with -mavx2; see raster/CMakeLists.txt).
#include "fragment_kernel.h"

#ifndef FOCAL_NO_SIMD
#if !defined(__AVX2__)
#error "fragment_kernel_avx2.cpp must be compiled with -mavx2"
#endif

namespace raster {

namespace {
#define FOCAL_FRAGMENT_KERNEL_NAME fragmentKernelAvx2Impl
#define FOCAL_FRAGMENT_KERNEL_FULL_WIDTH 1
#include "fragment_kernel.inl"
#undef FOCAL_FRAGMENT_KERNEL_FULL_WIDTH
#undef FOCAL_FRAGMENT_KERNEL_NAME
} // namespace

FragmentKernel fragmentKernelAvx2() {
    return &fragmentKernelAvx2Impl;
}

} // namespace raster
#endif
