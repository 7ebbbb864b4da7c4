// The AVX2 build of the quad kernel (compiled with -mavx2; see raster/CMakeLists.txt).
#include "quad_kernel.h"

#ifndef FOCAL_NO_SIMD
#if !defined(__AVX2__)
#error "quad_kernel_avx2.cpp must be compiled with -mavx2"
#endif

namespace raster {

namespace {
#define FOCAL_QUAD_KERNEL_NAME quadKernelAvx2Impl
#include "quad_kernel.inl"
#undef FOCAL_QUAD_KERNEL_NAME
} // namespace

QuadKernel quadKernelAvx2() {
    return &quadKernelAvx2Impl;
}

} // namespace raster
#endif
