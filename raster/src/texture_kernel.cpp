#include "texture_kernel.h"

#include <raster/simd.h>

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
    return useAvx2(simd) ? textureKernelAvx2() : &textureKernelScalar;
}

} // namespace raster
