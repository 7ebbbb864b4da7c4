#pragma once

// Consumes: the caller's SIMD switch. Produces: whether to run the AVX2 build of a kernel written
// once and compiled twice (the raster's quad, lighting and texture kernels, multiview's tracer).
// Both builds give the same bits; the scalar one is the reference.

namespace raster {

// True when `simd` asks for SIMD (RenderOptions::simd; `focal render --no-simd` turns it off),
// this is an x86-64 build with SIMD (not FOCAL_NO_SIMD) and the CPU has AVX2.
inline bool useAvx2(bool simd) {
#if defined(__x86_64__) && !defined(FOCAL_NO_SIMD)
    return simd && __builtin_cpu_supports("avx2");
#else
    (void)simd;
    return false;
#endif
}

} // namespace raster
