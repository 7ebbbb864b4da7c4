#include "quad_kernel.h"

namespace raster {

#define FOCAL_QUAD_KERNEL_NAME quadKernelScalar
#include "quad_kernel.inl"
#undef FOCAL_QUAD_KERNEL_NAME

#ifdef FOCAL_NO_SIMD
QuadKernel quadKernelAvx2() {
    return nullptr;
}
#endif

QuadKernel selectQuadKernel(bool simd) {
#if defined(__x86_64__) && !defined(FOCAL_NO_SIMD)
    if (simd && __builtin_cpu_supports("avx2"))
        return quadKernelAvx2();
#else
    (void)simd;
#endif
    return &quadKernelScalar;
}

} // namespace raster
