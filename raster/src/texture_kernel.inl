// Body of the texture kernel (texture_kernel.h); included by texture_kernel.cpp and
// texture_kernel_avx2.cpp. Lane loops over fixed-size arrays doing, per lane, the operations of
// texture.cpp's sampleLevel in the same order, so the results are its bits; branches only on
// what the lanes share. No calls to inline library templates (see quad_kernel.inl). The table
// loads (texel words, the sRGB table) go through gatherLanes: AVX2 gathers in the AVX2 build,
// which loads a level's decoded texels instead where it has them (loadLinearLanes). The AVX2 file
// asks for its intrinsics with FOCAL_TEXTURE_KERNEL_AVX2 (not __AVX2__, so that the reference
// stays scalar under -march flags that enable AVX2).
#ifndef FOCAL_TEXTURE_KERNEL_NAME
#error "define FOCAL_TEXTURE_KERNEL_NAME before including texture_kernel.inl"
#endif

namespace {

constexpr int kLanes = kTextureLanes;

// texture.cpp's texelCoord: u * size - 1/2 in double (exact: a float times an integer below
// 2^22), 0 for non-finite u, clamped to +-2^30 so the integer part fits int32. Written as three
// selects on doubles, one after the other (a non-finite u gives an infinite or NaN x that the
// last select replaces), which vectorize as compare and blend pairs.
inline double texelCoordLane(float u, double size) {
    const double d = double(u);
    double x = d * size - 0.5;
    x = x < -1073741824.0 ? -1073741824.0 : x;
    x = 1073741824.0 < x ? 1073741824.0 : x;
    return __builtin_fabs(d) <= double(__FLT_MAX__) ? x : 0.0;
}

#ifdef FOCAL_TEXTURE_KERNEL_AVX2
inline __m256i loadLanes(const int32_t* p) {
    return _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p));
}
inline void storeLanes(int32_t* p, __m256i v) {
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(p), v);
}
#endif

// texture.cpp's wrapIndex of i and of i + 1, for |i| <= 2^30 and 0 < n <= kTextureKernelMaxSide.
// The period's multiple is floor(i / period) in double, exact: the quotient's rounding error
// (< 2^-22) is smaller than its distance (>= 1/period) from the next integer above.
// The AVX2 build writes these integer lane loops with intrinsics: GCC 12 leaves them scalar (a
// quarter of the kernel's instructions on demo, callgrind); integers, so the same values.
inline void wrapLanes(const int32_t* i, int32_t n, Wrap mode, int32_t* w0, int32_t* w1) {
#ifdef FOCAL_TEXTURE_KERNEL_AVX2
    const __m256i vi = loadLanes(i);
    if (mode == Wrap::ClampToEdge) {
        // a < 0 ? 0 : min(a, n - 1) is max(0, min(a, n - 1)) for n >= 1.
        const __m256i zero = _mm256_setzero_si256(), last = _mm256_set1_epi32(n - 1);
        storeLanes(w0, _mm256_max_epi32(zero, _mm256_min_epi32(vi, last)));
        storeLanes(w1,
                   _mm256_max_epi32(
                       zero, _mm256_min_epi32(_mm256_add_epi32(vi, _mm256_set1_epi32(1)), last)));
        return;
    }
#else
    if (mode == Wrap::ClampToEdge) {
        for (int l = 0; l < kLanes; ++l) {
            const int32_t a = i[l], b = i[l] + 1;
            w0[l] = a < 0 ? 0 : (a > n - 1 ? n - 1 : a);
            w1[l] = b < 0 ? 0 : (b > n - 1 ? n - 1 : b);
        }
        return;
    }
#endif
    const int32_t period = mode == Wrap::Repeat ? n : 2 * n;
    if ((period & (period - 1)) == 0) {
        // A power-of-two period (most textures): i mod period is the low bits of i in two's
        // complement, the same integer without the division; so is i + 1's, which is w0 + 1
        // wrapped to 0 at the period.
#ifdef FOCAL_TEXTURE_KERNEL_AVX2
        const __m256i low = _mm256_set1_epi32(period - 1);
        storeLanes(w0, _mm256_and_si256(vi, low));
        storeLanes(w1, _mm256_and_si256(_mm256_add_epi32(vi, _mm256_set1_epi32(1)), low));
#else
        for (int l = 0; l < kLanes; ++l) {
            w0[l] = i[l] & (period - 1);
            w1[l] = (i[l] + 1) & (period - 1);
        }
#endif
    } else {
        const double period_d = double(period);
        for (int l = 0; l < kLanes; ++l)
            w0[l] = i[l] - period * int32_t(__builtin_floor(double(i[l]) / period_d));
        for (int l = 0; l < kLanes; ++l)
            w1[l] = w0[l] + 1 == period ? 0 : w0[l] + 1;
    }
    if (mode == Wrap::MirroredRepeat) {
#ifdef FOCAL_TEXTURE_KERNEL_AVX2
        // w < n ? w : period - 1 - w
        const __m256i top = _mm256_set1_epi32(period - 1), vn = _mm256_set1_epi32(n);
        const auto mirror = [&](int32_t* w) {
            const __m256i v = loadLanes(w);
            storeLanes(w,
                       _mm256_blendv_epi8(_mm256_sub_epi32(top, v), v, _mm256_cmpgt_epi32(vn, v)));
        };
        mirror(w0);
        mirror(w1);
#else
        for (int l = 0; l < kLanes; ++l) {
            w0[l] = w0[l] < n ? w0[l] : period - 1 - w0[l];
            w1[l] = w1[l] < n ? w1[l] : period - 1 - w1[l];
        }
#endif
    }
}

// out[l] = table[index[l]] for every lane, each index valid, for any 4-byte T (texel words,
// the sRGB table's floats): one 8-lane gather of 32-bit words in the AVX2 build (GCC 12 does not
// vectorize these loads by itself), a lane loop in the scalar reference.
template <class T> void gatherLanes(const T* table, const int32_t* index, T* out) {
    static_assert(sizeof(T) == 4);
#ifdef FOCAL_TEXTURE_KERNEL_AVX2
    const __m256i i = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(index));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(out),
                        _mm256_i32gather_epi32(reinterpret_cast<const int*>(table), i, 4));
#else
    for (int l = 0; l < kLanes; ++l)
        out[l] = table[index[l]];
#endif
}

#ifdef FOCAL_TEXTURE_KERNEL_AVX2
// The decoded texels at `index` of every lane, channel by channel: eight 16-byte loads (lanes l
// and l + 4 into the two halves of one register) and a 4x4 transpose within each half.
inline void loadLinearLanes(const float* linear, const int32_t* index, float (*rgba)[kLanes]) {
    __m256 t[4];
    for (int l = 0; l < 4; ++l)
        t[l] = _mm256_loadu2_m128(linear + 4 * size_t(index[l + 4]), linear + 4 * size_t(index[l]));
    const __m256 rg01 = _mm256_unpacklo_ps(t[0], t[1]), ba01 = _mm256_unpackhi_ps(t[0], t[1]);
    const __m256 rg23 = _mm256_unpacklo_ps(t[2], t[3]), ba23 = _mm256_unpackhi_ps(t[2], t[3]);
    _mm256_storeu_ps(rgba[0], _mm256_shuffle_ps(rg01, rg23, _MM_SHUFFLE(1, 0, 1, 0)));
    _mm256_storeu_ps(rgba[1], _mm256_shuffle_ps(rg01, rg23, _MM_SHUFFLE(3, 2, 3, 2)));
    _mm256_storeu_ps(rgba[2], _mm256_shuffle_ps(ba01, ba23, _MM_SHUFFLE(1, 0, 1, 0)));
    _mm256_storeu_ps(rgba[3], _mm256_shuffle_ps(ba01, ba23, _MM_SHUFFLE(3, 2, 3, 2)));
}
#endif

// Texel (x, y) of every lane as linear RGBA (texture.cpp's fetch). Indices are int32, below
// kTextureKernelMaxTexels: the gathers' indices.
inline void fetchLanes(const TextureLevel& level, const float* lut, const int32_t* x,
                       const int32_t* y, float (*rgba)[kLanes]) {
    alignas(32) int32_t index[kLanes];
#ifdef FOCAL_TEXTURE_KERNEL_AVX2
    storeLanes(index,
               _mm256_add_epi32(_mm256_mullo_epi32(loadLanes(y), _mm256_set1_epi32(level.width)),
                                loadLanes(x)));
#else
    for (int l = 0; l < kLanes; ++l)
        index[l] = y[l] * level.width + x[l];
#endif
#ifdef FOCAL_TEXTURE_KERNEL_AVX2
    if (level.linear) {
        loadLinearLanes(level.linear, index, rgba);
        return;
    }
#endif
    alignas(32) uint32_t t[kLanes];
    gatherLanes(level.texels, index, t);
    if (lut) {
        alignas(32) int32_t byte[3][kLanes];
        for (int c = 0; c < 3; ++c)
            for (int l = 0; l < kLanes; ++l)
                byte[c][l] = int32_t((t[l] >> (8 * c)) & 0xffu);
        for (int c = 0; c < 3; ++c)
            gatherLanes(lut, byte[c], rgba[c]);
        for (int l = 0; l < kLanes; ++l)
            rgba[3][l] = float(int32_t(t[l] >> 24)) * (1.0f / 255.0f);
        return;
    }
    for (int c = 0; c < 4; ++c)
        for (int l = 0; l < kLanes; ++l)
            rgba[c][l] = float(int32_t((t[l] >> (8 * c)) & 0xffu)) * (1.0f / 255.0f);
}

// J levels (1, or the 2 of a trilinear lookup), nearest or bilinear, at every lane
// (texture.cpp's sampleLevel on each). The levels' steps are written side by side, so that the
// core works on both levels' chains (coordinates, wrap, index, loads, mixing) at once.
template <int J>
inline void sampleLevelLanes(const TextureQuery& q, const TextureLevel* const (&levels)[J],
                             const float* u, const float* v, float (*const (&rgba)[J])[kLanes]) {
    alignas(32) int32_t ix[J][kLanes], iy[J][kLanes];
    alignas(32) float ax[J][kLanes], ay[J][kLanes];
    for (int j = 0; j < J; ++j) {
        const double w = double(levels[j]->width), h = double(levels[j]->height);
        for (int l = 0; l < kLanes; ++l) {
            const double x = texelCoordLane(u[l], w), y = texelCoordLane(v[l], h);
            const double fx = __builtin_floor(q.nearest ? x + 0.5 : x);
            const double fy = __builtin_floor(q.nearest ? y + 0.5 : y);
            ax[j][l] = float(x - fx);
            ay[j][l] = float(y - fy);
            ix[j][l] = int32_t(fx);
            iy[j][l] = int32_t(fy);
        }
    }
    alignas(32) int32_t x0[J][kLanes], x1[J][kLanes], y0[J][kLanes], y1[J][kLanes];
    for (int j = 0; j < J; ++j) {
        wrapLanes(ix[j], levels[j]->width, q.wrap_s, x0[j], x1[j]);
        wrapLanes(iy[j], levels[j]->height, q.wrap_t, y0[j], y1[j]);
    }
    if (q.nearest) {
        for (int j = 0; j < J; ++j)
            fetchLanes(*levels[j], q.srgb_lut, x0[j], y0[j], rgba[j]);
        return;
    }
    alignas(32) float c00[J][4][kLanes], c10[J][4][kLanes], c01[J][4][kLanes], c11[J][4][kLanes];
    for (int j = 0; j < J; ++j) {
        fetchLanes(*levels[j], q.srgb_lut, x0[j], y0[j], c00[j]);
        fetchLanes(*levels[j], q.srgb_lut, x1[j], y0[j], c10[j]);
        fetchLanes(*levels[j], q.srgb_lut, x0[j], y1[j], c01[j]);
        fetchLanes(*levels[j], q.srgb_lut, x1[j], y1[j], c11[j]);
    }
    // glm::mix(a, b, t) = a * (1 - t) + b * t: across, then down.
    for (int j = 0; j < J; ++j)
        for (int c = 0; c < 4; ++c)
            for (int l = 0; l < kLanes; ++l) {
                const float top = c00[j][c][l] * (1.0f - ax[j][l]) + c10[j][c][l] * ax[j][l];
                const float bottom = c01[j][c][l] * (1.0f - ax[j][l]) + c11[j][c][l] * ax[j][l];
                rgba[j][c][l] = top * (1.0f - ay[j][l]) + bottom * ay[j][l];
            }
}

} // namespace

void FOCAL_TEXTURE_KERNEL_NAME(const TextureQuery& query, TextureLanes& io) {
    if (!query.mix_levels) {
        sampleLevelLanes<1>(query, {&query.level[0]}, io.u, io.v, {io.rgba});
        return;
    }
    alignas(32) float upper[4][kLanes];
    sampleLevelLanes<2>(query, {&query.level[0], &query.level[1]}, io.u, io.v, {io.rgba, upper});
    for (int c = 0; c < 4; ++c)
        for (int l = 0; l < kLanes; ++l)
            io.rgba[c][l] = io.rgba[c][l] * (1.0f - io.weight[l]) + upper[c][l] * io.weight[l];
}
