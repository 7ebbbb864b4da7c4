// Four floats as one SSE vector (a GCC/clang vector extension; on the baseline x86-64 target as
// on AVX2, and lowered to scalar code elsewhere), for arithmetic that is the same on each of four
// channels: RGBA colour, or the first four channels of a mipmap texel. The operations are
// element-wise, so each lane performs the IEEE operations of the scalar expression in the same
// order, and the bits are those of the scalar code (the determinism contract: no contraction,
// no reassociation).
#pragma once

namespace dof {

using Float4 = float __attribute__((vector_size(16)));

// Four consecutive floats from p (any alignment).
inline Float4 loadFloat4(const float* p) {
    Float4 v;
    __builtin_memcpy(&v, p, sizeof v);
    return v;
}

} // namespace dof
