// The AVX2 build of the texture kernel (compiled with -mavx2; see raster/CMakeLists.txt).
#include "texture_kernel.h"

#ifndef FOCAL_NO_SIMD
#if !defined(__AVX2__)
#error "texture_kernel_avx2.cpp must be compiled with -mavx2"
#endif

#include <immintrin.h>

namespace raster {

namespace {
#define FOCAL_TEXTURE_KERNEL_NAME textureKernelAvx2Impl
#define FOCAL_TEXTURE_KERNEL_AVX2 1
#include "texture_kernel.inl"
#undef FOCAL_TEXTURE_KERNEL_AVX2
#undef FOCAL_TEXTURE_KERNEL_NAME
} // namespace

TextureKernel textureKernelAvx2() {
    return &textureKernelAvx2Impl;
}

} // namespace raster
#endif
