#include "quad_kernel.h"

#include <raster/simd.h>

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
    return useAvx2(simd) ? quadKernelAvx2() : &quadKernelScalar;
}

} // namespace raster
