#include "fragment_kernel.h"

#include <raster/simd.h>

namespace raster {

#define FOCAL_FRAGMENT_KERNEL_NAME fragmentKernelScalar
#define FOCAL_FRAGMENT_KERNEL_FULL_WIDTH 0
#include "fragment_kernel.inl"
#undef FOCAL_FRAGMENT_KERNEL_FULL_WIDTH
#undef FOCAL_FRAGMENT_KERNEL_NAME

#ifdef FOCAL_NO_SIMD
FragmentKernel fragmentKernelAvx2() {
    return nullptr;
}
#endif

FragmentKernel selectFragmentKernel(bool simd) {
    return useAvx2(simd) ? fragmentKernelAvx2() : &fragmentKernelScalar;
}

} // namespace raster
