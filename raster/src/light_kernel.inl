// Body of the lighting kernel (light_kernel.h); included by light_kernel.cpp and
// light_kernel_avx2.cpp. Branch-free lane loops, no library calls (see quad_kernel.inl).
#ifndef FOCAL_LIGHT_KERNEL_NAME
#error "define FOCAL_LIGHT_KERNEL_NAME before including light_kernel.inl"
#endif
// 1: compute every one of the kLightLanes lanes whatever `lanes` says (the SIMD build: one
// vector pass instead of a scalar loop over a partial vector); 0: only lanes [0, lanes).
#ifndef FOCAL_LIGHT_KERNEL_FULL_WIDTH
#error "define FOCAL_LIGHT_KERNEL_FULL_WIDTH before including light_kernel.inl"
#endif

namespace {

constexpr float kPi = 3.14159265358979f;
// Constant ambient light (fraction of the base colour) so surfaces facing away stay visible.
constexpr float kAmbient = 0.12f;

inline float asFloat(int32_t i) {
    return __builtin_bit_cast(float, i);
}
inline int32_t asInt(float f) {
    return __builtin_bit_cast(int32_t, f);
}

// log2(x) for normal x > 0: x = m 2^e with m in [sqrt(1/2), sqrt(2)), then
// log2(m) = 2/ln2 * atanh(t), t = (m-1)/(m+1), |t| < 0.172: five odd terms give ~1e-8.
inline float log2Positive(float x) {
    const int32_t bits = asInt(x);
    int32_t e = ((bits >> 23) & 0xff) - 127;
    float m = asFloat((bits & 0x007fffff) | 0x3f800000); // [1, 2)
    const bool high = m > 1.41421356f;
    m = high ? m * 0.5f : m;
    e = high ? e + 1 : e;
    const float t = (m - 1.0f) / (m + 1.0f);
    const float t2 = t * t;
    const float series =
        t * (1.0f + t2 * (1.0f / 3.0f + t2 * (1.0f / 5.0f + t2 * (1.0f / 7.0f + t2 / 9.0f))));
    return float(e) + series * 2.88539008f; // 2/ln(2)
}

// 2^y for y <= 0: y = n + f with n = trunc(y) and f in (-1, 0]; 2^f by its Taylor series in
// f*ln2 to the 9th power (~1e-8 relative); 2^n by building the exponent bits. Below -127 the
// exponent field is 0 and the result is 0.
inline float exp2NonPositive(float y) {
    const float yc = y > -127.0f ? y : -127.0f;
    const int32_t n = int32_t(yc);
    const float f = (yc - float(n)) * 0.693147181f;
    const float p =
        1.0f +
        f * (1.0f +
             f * (1.0f / 2.0f +
                  f * (1.0f / 6.0f +
                       f * (1.0f / 24.0f +
                            f * (1.0f / 120.0f +
                                 f * (1.0f / 720.0f +
                                      f * (1.0f / 5040.0f +
                                           f * (1.0f / 40320.0f + f * (1.0f / 362880.0f)))))))));
    return p * asFloat((n + 127) << 23);
}

// x^s for x in [0, 1] and s >= 0; 0^s = 0. (x + 1e-30 is x itself for every x the lighting
// produces above 1e-30, and keeps log2 finite at 0; the product with 0 or 1, rather than a
// select, keeps the compiler from turning the pow into a branch.)
inline float powUnit(float x, float s) {
    const float r = exp2NonPositive(s * log2Positive(x + 1e-30f));
    return r * (x > 0.0f ? 1.0f : 0.0f);
}

} // namespace

// __restrict: io never overlaps the lights, the material or the eye, which lets the lane loops
// keep the light constants in registers.
void FOCAL_LIGHT_KERNEL_NAME(const PreparedLight* __restrict lights, uint32_t light_count,
                             const LightMaterial& __restrict material, const float* __restrict eye,
                             LightLanes& __restrict io, int lanes) {
    const int n_lanes = FOCAL_LIGHT_KERNEL_FULL_WIDTH ? kLightLanes : lanes;
    const float metallic = material.metallic < 0.0f   ? 0.0f
                           : material.metallic > 1.0f ? 1.0f
                                                      : material.metallic;
    const float r2 = material.roughness * material.roughness;
    const float alpha = r2 > 0.02f ? r2 : 0.02f;
    // Blinn-Phong exponent matching a GGX-like lobe of roughness alpha (Walter et al. 2007).
    const float shininess = 2.0f / (alpha * alpha) - 2.0f;
    const float spec_norm = (shininess + 8.0f) / (8.0f * kPi);
    const float diffuse_scale = (1.0f - metallic) * (1.0f / kPi);

    alignas(32) float n[3][kLightLanes], v[3][kLightLanes], diffuse[3][kLightLanes],
        f0[3][kLightLanes];
    for (int l = 0; l < n_lanes; ++l) {
        const float nx = io.normal[0][l], ny = io.normal[1][l], nz = io.normal[2][l];
        const float len2 = nx * nx + ny * ny + nz * nz;
        const float inv_len = len2 > 0.0f ? 1.0f / __builtin_sqrtf(len2) : 0.0f;
        n[0][l] = len2 > 0.0f ? nx * inv_len : 0.0f;
        n[1][l] = len2 > 0.0f ? ny * inv_len : 0.0f;
        n[2][l] = len2 > 0.0f ? nz * inv_len : 1.0f;
        const float vx = eye[0] - io.world[0][l], vy = eye[1] - io.world[1][l],
                    vz = eye[2] - io.world[2][l];
        const float inv_v = 1.0f / __builtin_sqrtf(vx * vx + vy * vy + vz * vz);
        v[0][l] = vx * inv_v;
        v[1][l] = vy * inv_v;
        v[2][l] = vz * inv_v;
        diffuse[0][l] = io.albedo[0][l] * diffuse_scale;
        diffuse[1][l] = io.albedo[1][l] * diffuse_scale;
        diffuse[2][l] = io.albedo[2][l] * diffuse_scale;
        f0[0][l] = 0.04f + (io.albedo[0][l] - 0.04f) * metallic;
        f0[1][l] = 0.04f + (io.albedo[1][l] - 0.04f) * metallic;
        f0[2][l] = 0.04f + (io.albedo[2][l] - 0.04f) * metallic;
        io.rgb[0][l] = io.emissive[0][l] + kAmbient * io.albedo[0][l];
        io.rgb[1][l] = io.emissive[1][l] + kAmbient * io.albedo[1][l];
        io.rgb[2][l] = io.emissive[2][l] + kAmbient * io.albedo[2][l];
    }
    // Adds one light's contribution at lane l: direction to the light (lx, ly, lz), unit, and
    // the fraction of its radiance that arrives.
    auto accumulate = [&](const PreparedLight& light, int l, float lx, float ly, float lz,
                          float attenuation) {
        const float n_dot_l = n[0][l] * lx + n[1][l] * ly + n[2][l] * lz;
        const float hx = lx + v[0][l], hy = ly + v[1][l], hz = lz + v[2][l];
        const float h2 = hx * hx + hy * hy + hz * hz;
        const float inv_h = h2 > 0.0f ? 1.0f / __builtin_sqrtf(h2) : 0.0f;
        const float ndh = (n[0][l] * hx + n[1][l] * hy + n[2][l] * hz) * inv_h;
        const float n_dot_h = ndh > 0.0f ? (ndh < 1.0f ? ndh : 1.0f) : 0.0f;
        const float spec = spec_norm * powUnit(n_dot_h, shininess);
        const float k = n_dot_l > 0.0f ? n_dot_l * attenuation : 0.0f;
        io.rgb[0][l] += (diffuse[0][l] + f0[0][l] * spec) * (light.radiance[0] * k);
        io.rgb[1][l] += (diffuse[1][l] + f0[1][l] * spec) * (light.radiance[1] * k);
        io.rgb[2][l] += (diffuse[2][l] + f0[2][l] * spec) * (light.radiance[2] * k);
    };
    for (uint32_t li = 0; li < light_count; ++li) {
        const PreparedLight& L = lights[li];
        if (L.type == Light::Type::Directional) {
            for (int l = 0; l < n_lanes; ++l)
                accumulate(L, l, -L.direction[0], -L.direction[1], -L.direction[2], 1.0f);
            continue;
        }
        // Point and spot lights (a point light's cone constants make the cone factor 1).
        for (int l = 0; l < n_lanes; ++l) {
            const float tx = L.position[0] - io.world[0][l], ty = L.position[1] - io.world[1][l],
                        tz = L.position[2] - io.world[2][l];
            const float d2raw = tx * tx + ty * ty + tz * tz;
            const float dist2 = d2raw > 1e-8f ? d2raw : 1e-8f;
            const float inv_d = 1.0f / __builtin_sqrtf(dist2);
            const float lx = tx * inv_d, ly = ty * inv_d, lz = tz * inv_d;
            // KHR_lights_punctual: inverse square with a smooth window at `range`, and the
            // spot cone's smooth falloff, squared.
            const float rr = dist2 * L.inv_range2;
            const float window = 1.0f - rr * rr;
            const float cd = -(L.direction[0] * lx + L.direction[1] * ly + L.direction[2] * lz);
            const float tc = (cd - L.cos_outer) * L.inv_cone_width;
            const float cone = tc < 0.0f ? 0.0f : (tc > 1.0f ? 1.0f : tc);
            const float attenuation =
                (1.0f / dist2) * (window < 0.0f ? 0.0f : window) * (cone * cone);
            accumulate(L, l, lx, ly, lz, attenuation);
        }
    }
}
