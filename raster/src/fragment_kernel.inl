// Body of the fragment kernel (fragment_kernel.h); included by fragment_kernel.cpp and
// fragment_kernel_avx2.cpp. Lane loops over fixed-size arrays with the per-triangle choices as
// selects, no library calls (see quad_kernel.inl). Each lane computes what the one-fragment code
// did with glm: (b0 * a0 + b1 * a1) + b2 * a2 per component, then factor x colour x texel. An
// untextured lane multiplies by a texel of exactly 1, which leaves every bit as it is.
#ifndef FOCAL_FRAGMENT_KERNEL_NAME
#error "define FOCAL_FRAGMENT_KERNEL_NAME before including fragment_kernel.inl"
#endif
// 1: compute all kQuadLanes lanes (one vector pass); 0: lanes up to the highest one asked for.
#ifndef FOCAL_FRAGMENT_KERNEL_FULL_WIDTH
#error "define FOCAL_FRAGMENT_KERNEL_FULL_WIDTH before including fragment_kernel.inl"
#endif

// __restrict: the outputs never overlap the inputs, which lets the lane loops vectorize.
uint32_t FOCAL_FRAGMENT_KERNEL_NAME(const FragmentTriangle& __restrict tri,
                                    const float (*__restrict persp)[kQuadLanes],
                                    const float (*__restrict base_texel)[kQuadLanes],
                                    const float (*__restrict emissive_texel)[kQuadLanes],
                                    uint32_t lanes, LightLanes& __restrict out,
                                    float* __restrict alpha) {
    constexpr int kAll = kQuadLanes;
    alignas(32) static constexpr float kWhite[4][kAll] = {{1, 1, 1, 1, 1, 1, 1, 1},
                                                          {1, 1, 1, 1, 1, 1, 1, 1},
                                                          {1, 1, 1, 1, 1, 1, 1, 1},
                                                          {1, 1, 1, 1, 1, 1, 1, 1}};
    const float(*__restrict const tex)[kAll] = base_texel ? base_texel : kWhite;
    const float(*__restrict const etex)[kAll] = emissive_texel ? emissive_texel : kWhite;
    const int n = FOCAL_FRAGMENT_KERNEL_FULL_WIDTH ? kAll : 32 - __builtin_clz(lanes | 1u);
    const float(*__restrict const b)[kAll] = persp;
    // Base colour: factor x vertex colour (exactly white without colours) x texel.
    alignas(32) float a[kAll];
    for (int c = 0; c < 4; ++c) {
        const float c0 = tri.color[c][0], c1 = tri.color[c][1], c2 = tri.color[c][2];
        const float factor = tri.base_factor[c];
        float* __restrict dst = c < 3 ? out.albedo[c] : a;
        if (tri.has_colors)
            for (int l = 0; l < n; ++l)
                dst[l] = (factor * ((b[0][l] * c0 + b[1][l] * c1) + b[2][l] * c2)) * tex[c][l];
        else
            for (int l = 0; l < n; ++l)
                dst[l] = (factor * 1.0f) * tex[c][l];
    }
    // Alpha test: MASK drops alpha below the cutoff, BLEND drops opacity 0 (NaN fails both).
    const int32_t mask = tri.mask, blend = tri.blend;
    const float cutoff = tri.alpha_cutoff;
    alignas(32) int32_t keep[kAll];
    for (int l = 0; l < n; ++l) {
        keep[l] = int32_t(!(mask & int32_t(!(a[l] >= cutoff)))) &
                  int32_t(!(blend & int32_t(!(a[l] > 0.0f))));
        alpha[l] = blend ? (a[l] < 0.0f ? 0.0f : (1.0f < a[l] ? 1.0f : a[l])) : 1.0f;
    }
    for (int c = 0; c < 3; ++c) {
        // Emissive: the factor, times the texel when textured.
        const float e = tri.emissive_factor[c];
        for (int l = 0; l < n; ++l)
            out.emissive[c][l] = e * etex[c][l];
        // World position.
        const float w0 = tri.world[c][0], w1 = tri.world[c][1], w2 = tri.world[c][2];
        for (int l = 0; l < n; ++l)
            out.world[c][l] = (b[0][l] * w0 + b[1][l] * w1) + b[2][l] * w2;
        // Normal: interpolated (negated on back faces) or the face normal.
        const float n0 = tri.normal[c][0], n1 = tri.normal[c][1], n2 = tri.normal[c][2];
        if (!tri.has_normals)
            for (int l = 0; l < n; ++l)
                out.normal[c][l] = tri.face_normal[c];
        else if (tri.flip_normal)
            for (int l = 0; l < n; ++l)
                out.normal[c][l] = -((b[0][l] * n0 + b[1][l] * n1) + b[2][l] * n2);
        else
            for (int l = 0; l < n; ++l)
                out.normal[c][l] = (b[0][l] * n0 + b[1][l] * n1) + b[2][l] * n2;
    }
    uint32_t passed = 0;
    for (int l = 0; l < n; ++l)
        passed |= uint32_t(keep[l]) << l;
    return passed & lanes;
}
