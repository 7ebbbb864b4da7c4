#include "texture_kernel.h"

namespace raster {

#define FOCAL_TEXTURE_KERNEL_NAME textureKernelScalar
#include "texture_kernel.inl"
#undef FOCAL_TEXTURE_KERNEL_NAME

#ifdef FOCAL_NO_SIMD
TextureKernel textureKernelAvx2() {
    return nullptr;
}
#endif

TextureKernel selectTextureKernel(bool simd) {
#if defined(__x86_64__) && !defined(FOCAL_NO_SIMD)
    if (simd && __builtin_cpu_supports("avx2"))
        return textureKernelAvx2();
#else
    (void)simd;
#endif
    return &textureKernelScalar;
}

} // namespace raster
