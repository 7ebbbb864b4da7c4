// Body of the quad kernel (quad_kernel.h); included by quad_kernel.cpp and
// quad_kernel_avx2.cpp with different instruction sets. Branch-free lane loops over fixed-size
// arrays, so the compiler vectorizes them; every lane does the same IEEE operations in the same
// order as in the scalar build. No calls to inline library templates here: the AVX2 copy of such
// a template could be the one the linker keeps for the whole program.
#ifndef FOCAL_QUAD_KERNEL_NAME
#error "define FOCAL_QUAD_KERNEL_NAME before including quad_kernel.inl"
#endif

void FOCAL_QUAD_KERNEL_NAME(const QuadInput& in, QuadOutput& out) {
    constexpr int n = kQuadLanes;
    alignas(32) static constexpr double kDx[n] = {0, 1, 0, 1, 2, 3, 2, 3};
    alignas(32) static constexpr double kDy[n] = {0, 0, 1, 1, 0, 0, 1, 1};
    alignas(32) double e0[n], e1[n], e2[n];
    alignas(32) int32_t inside[n];
    for (int l = 0; l < n; ++l) {
        e0[l] = in.edge[0] + kDx[l] * in.step_x[0] + kDy[l] * in.step_y[0];
        e1[l] = in.edge[1] + kDx[l] * in.step_x[1] + kDy[l] * in.step_y[1];
        e2[l] = in.edge[2] + kDx[l] * in.step_x[2] + kDy[l] * in.step_y[2];
        inside[l] = int32_t(e0[l] + in.bias[0] >= 0.0) & int32_t(e1[l] + in.bias[1] >= 0.0) &
                    int32_t(e2[l] + in.bias[2] >= 0.0);
    }
    uint32_t mask = 0;
    for (int l = 0; l < n; ++l)
        mask |= uint32_t(inside[l]) << l;
    out.mask = mask & in.valid;
    if (out.mask == 0)
        return;
    for (int l = 0; l < n; ++l) {
        const float l0 = float(e0[l] * in.inv_area2);
        const float l1 = float(e1[l] * in.inv_area2);
        const float l2 = float(e2[l] * in.inv_area2);
        const float q0 = l0 * in.inv_w[0], q1 = l1 * in.inv_w[1], q2 = l2 * in.inv_w[2];
        const float sum = q0 + q1 + q2;
        const float inv = sum != 0.0f ? 1.0f / sum : 0.0f;
        const float z = l0 * in.z[0] + l1 * in.z[1] + l2 * in.z[2];
        out.persp[0][l] = q0 * inv;
        out.persp[1][l] = q1 * inv;
        out.persp[2][l] = q2 * inv;
        out.distance[l] = inv;
        out.z[l] = z < kNearDepth ? kNearDepth : (z > kFarDepth ? kFarDepth : z);
    }
}
