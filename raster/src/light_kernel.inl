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

// J powers at once (J independent inputs: lights, or lights x blocks), each the same operations
// in the same order as for one: the J dependency chains (about 40 steps of log2, exp2 and their
// divisions) are written step by step side by side, so the core works on J of them at a time
// instead of waiting on one. The coefficients are plain arrays: no library template (such as
// std::initializer_list) in this file (see quad_kernel.inl).
constexpr float kLog2Series[] = {1.0f / 7.0f, 1.0f / 5.0f, 1.0f / 3.0f};
constexpr float kExp2Series[] = {1.0f / 40320.0f, 1.0f / 5040.0f, 1.0f / 720.0f, 1.0f / 120.0f,
                                 1.0f / 24.0f,    1.0f / 6.0f,    1.0f / 2.0f,   1.0f};

// log2(x) for normal x > 0: x = m 2^e with m in [sqrt(1/2), sqrt(2)), then
// log2(m) = 2/ln2 * atanh(t), t = (m-1)/(m+1), |t| < 0.172: five odd terms give ~1e-8.
template <int J> inline void log2Positive(const float (&x)[J], float (&out)[J]) {
    int32_t e[J];
    float t[J], t2[J], q[J];
    for (int j = 0; j < J; ++j) {
        const int32_t bits = asInt(x[j]);
        const float m = asFloat((bits & 0x007fffff) | 0x3f800000); // [1, 2)
        const bool high = m > 1.41421356f;
        const float mh = high ? m * 0.5f : m;
        e[j] = ((bits >> 23) & 0xff) - 127 + (high ? 1 : 0);
        t[j] = (mh - 1.0f) / (mh + 1.0f);
    }
    // t * (1 + t2 (1/3 + t2 (1/5 + t2 (1/7 + t2/9)))), innermost first.
    for (int j = 0; j < J; ++j)
        t2[j] = t[j] * t[j];
    for (int j = 0; j < J; ++j)
        q[j] = t2[j] / 9.0f;
    for (const float c : kLog2Series) {
        for (int j = 0; j < J; ++j)
            q[j] = c + q[j];
        for (int j = 0; j < J; ++j)
            q[j] = t2[j] * q[j];
    }
    for (int j = 0; j < J; ++j)
        out[j] = float(e[j]) + (t[j] * (1.0f + q[j])) * 2.88539008f; // 2/ln(2)
}

// 2^y for y <= 0: y = n + f with n = trunc(y) and f in (-1, 0]; 2^f by its Taylor series in
// f*ln2 to the 9th power (~1e-8 relative); 2^n by building the exponent bits. Below -127 the
// exponent field is 0 and the result is 0.
template <int J> inline void exp2NonPositive(const float (&y)[J], float (&out)[J]) {
    int32_t n[J];
    float f[J], p[J];
    for (int j = 0; j < J; ++j) {
        const float yc = y[j] > -127.0f ? y[j] : -127.0f;
        n[j] = int32_t(yc);
        f[j] = (yc - float(n[j])) * 0.693147181f;
    }
    // 1 + f (1 + f (1/2 + f (1/6 + ... + f (1/40320 + f/362880)))), innermost first.
    for (int j = 0; j < J; ++j)
        p[j] = f[j] * (1.0f / 362880.0f);
    for (const float c : kExp2Series) {
        for (int j = 0; j < J; ++j)
            p[j] = c + p[j];
        for (int j = 0; j < J; ++j)
            p[j] = f[j] * p[j];
    }
    for (int j = 0; j < J; ++j)
        out[j] = (1.0f + p[j]) * asFloat((n[j] + 127) << 23);
}

// What the lanes share: the material's lighting constants.
struct MaterialTerms {
    float metallic, shininess, spec_norm, diffuse_scale;
};

MaterialTerms materialTerms(const LightMaterial& material) {
    MaterialTerms t;
    t.metallic = material.metallic < 0.0f   ? 0.0f
                 : material.metallic > 1.0f ? 1.0f
                                            : material.metallic;
    const float r2 = material.roughness * material.roughness;
    const float alpha = r2 > 0.02f ? r2 : 0.02f;
    // Blinn-Phong exponent matching a GGX-like lobe of roughness alpha (Walter et al. 2007).
    t.shininess = 2.0f / (alpha * alpha) - 2.0f;
    t.spec_norm = (t.shininess + 8.0f) / (8.0f * kPi);
    t.diffuse_scale = (1.0f - t.metallic) * (1.0f / kPi);
    return t;
}

// Shades lanes [0, width) of the G blocks io[0 .. G). With G = 2 every step of a light is
// written for both blocks side by side, as for two lights (log2Positive): the core then has
// twice the independent chains to work on. __restrict: io never overlaps the lights or the eye,
// which lets the lane loops keep the light constants in registers.
template <int G>
void shadeBlocks(const PreparedLight* __restrict lights, uint32_t light_count,
                 const MaterialTerms& mt, const float* __restrict eye, LightLanes* __restrict io,
                 int width) {
    alignas(32) float n[G][3][kLightLanes], v[G][3][kLightLanes], diffuse[G][3][kLightLanes],
        f0[G][3][kLightLanes];
    for (int g = 0; g < G; ++g)
        for (int l = 0; l < width; ++l) {
            LightLanes& b = io[g];
            const float nx = b.normal[0][l], ny = b.normal[1][l], nz = b.normal[2][l];
            const float len2 = nx * nx + ny * ny + nz * nz;
            const float inv_len = len2 > 0.0f ? 1.0f / __builtin_sqrtf(len2) : 0.0f;
            n[g][0][l] = len2 > 0.0f ? nx * inv_len : 0.0f;
            n[g][1][l] = len2 > 0.0f ? ny * inv_len : 0.0f;
            n[g][2][l] = len2 > 0.0f ? nz * inv_len : 1.0f;
            const float vx = eye[0] - b.world[0][l], vy = eye[1] - b.world[1][l],
                        vz = eye[2] - b.world[2][l];
            const float inv_v = 1.0f / __builtin_sqrtf(vx * vx + vy * vy + vz * vz);
            v[g][0][l] = vx * inv_v;
            v[g][1][l] = vy * inv_v;
            v[g][2][l] = vz * inv_v;
            for (int c = 0; c < 3; ++c) {
                diffuse[g][c][l] = b.albedo[c][l] * mt.diffuse_scale;
                f0[g][c][l] = 0.04f + (b.albedo[c][l] - 0.04f) * mt.metallic;
                b.rgb[c][l] = b.emissive[c][l] + kAmbient * b.albedo[c][l];
            }
        }
    // Where each light comes from at each lane (unit direction to it) and the fraction of its
    // radiance that arrives: light j of the pair being shaded.
    alignas(32) float to_light[2][G][3][kLightLanes], arriving[2][G][kLightLanes];
    auto incidence = [&](const PreparedLight& L, int j) {
        for (int g = 0; g < G; ++g) {
            if (L.type == Light::Type::Directional) {
                for (int l = 0; l < width; ++l) {
                    to_light[j][g][0][l] = -L.direction[0];
                    to_light[j][g][1][l] = -L.direction[1];
                    to_light[j][g][2][l] = -L.direction[2];
                    arriving[j][g][l] = 1.0f;
                }
                continue;
            }
            // Point and spot lights (a point light's cone constants make the cone factor 1).
            const LightLanes& b = io[g];
            for (int l = 0; l < width; ++l) {
                const float tx = L.position[0] - b.world[0][l], ty = L.position[1] - b.world[1][l],
                            tz = L.position[2] - b.world[2][l];
                const float d2raw = tx * tx + ty * ty + tz * tz;
                const float dist2 = d2raw > 1e-8f ? d2raw : 1e-8f;
                const float inv_d = 1.0f / __builtin_sqrtf(dist2);
                const float lx = tx * inv_d, ly = ty * inv_d, lz = tz * inv_d;
                to_light[j][g][0][l] = lx;
                to_light[j][g][1][l] = ly;
                to_light[j][g][2][l] = lz;
                // KHR_lights_punctual: inverse square with a smooth window at `range`, and the
                // spot cone's smooth falloff, squared.
                const float rr = dist2 * L.inv_range2;
                const float window = 1.0f - rr * rr;
                const float cd = -(L.direction[0] * lx + L.direction[1] * ly + L.direction[2] * lz);
                const float tc = (cd - L.cos_outer) * L.inv_cone_width;
                const float cone = tc < 0.0f ? 0.0f : (tc > 1.0f ? 1.0f : tc);
                arriving[j][g][l] =
                    (1.0f / dist2) * (window < 0.0f ? 0.0f : window) * (cone * cone);
            }
        }
    };
    // Adds the contributions of lights[first .. first + J) (their incidence filled), in light
    // order at every lane: J x G chains (stream s: light s % J of block s / J) side by side.
    // The specular power (n.h)^s is exp2(s log2(n.h + 1e-30)) times (n.h > 0): n.h + 1e-30 is
    // n.h itself above 1e-30 and keeps log2 finite at 0, and the product with 0 or 1, rather
    // than a select, keeps the compiler from making it a branch.
    auto shadeLights = [&]<int J>(uint32_t first) {
        constexpr int S = J * G;
        for (int l = 0; l < width; ++l) {
            float n_dot_l[S], n_dot_h[S], x[S], y[S], power[S];
            for (int s = 0; s < S; ++s) {
                const int j = s % J, g = s / J;
                const float lx = to_light[j][g][0][l], ly = to_light[j][g][1][l],
                            lz = to_light[j][g][2][l];
                const float nx = n[g][0][l], ny = n[g][1][l], nz = n[g][2][l];
                n_dot_l[s] = nx * lx + ny * ly + nz * lz;
                const float hx = lx + v[g][0][l], hy = ly + v[g][1][l], hz = lz + v[g][2][l];
                const float h2 = hx * hx + hy * hy + hz * hz;
                const float inv_h = h2 > 0.0f ? 1.0f / __builtin_sqrtf(h2) : 0.0f;
                const float ndh = (nx * hx + ny * hy + nz * hz) * inv_h;
                n_dot_h[s] = ndh > 0.0f ? (ndh < 1.0f ? ndh : 1.0f) : 0.0f;
                x[s] = n_dot_h[s] + 1e-30f;
            }
            log2Positive<S>(x, y);
            for (int s = 0; s < S; ++s)
                y[s] = mt.shininess * y[s];
            exp2NonPositive<S>(y, power);
            for (int s = 0; s < S; ++s) {
                const int j = s % J, g = s / J;
                const PreparedLight& L = lights[first + j];
                const float spec = mt.spec_norm * (power[s] * (n_dot_h[s] > 0.0f ? 1.0f : 0.0f));
                const float k = n_dot_l[s] > 0.0f ? n_dot_l[s] * arriving[j][g][l] : 0.0f;
                for (int c = 0; c < 3; ++c)
                    io[g].rgb[c][l] +=
                        (diffuse[g][c][l] + f0[g][c][l] * spec) * (L.radiance[c] * k);
            }
        }
    };
    uint32_t li = 0;
    for (; li + 2 <= light_count; li += 2) {
        incidence(lights[li], 0);
        incidence(lights[li + 1], 1);
        shadeLights.template operator()<2>(li);
    }
    if (li < light_count) {
        incidence(lights[li], 0);
        shadeLights.template operator()<1>(li);
    }
}

} // namespace

void FOCAL_LIGHT_KERNEL_NAME(const PreparedLight* lights, uint32_t light_count,
                             const LightMaterial& material, const float* eye, LightLanes* io,
                             int blocks, int lanes) {
    const MaterialTerms mt = materialTerms(material);
#if FOCAL_LIGHT_KERNEL_FULL_WIDTH
    (void)lanes;
    if (blocks == 2)
        shadeBlocks<2>(lights, light_count, mt, eye, io, kLightLanes);
    else
        shadeBlocks<1>(lights, light_count, mt, eye, io, kLightLanes);
#else
    for (int b = 0; b < blocks; ++b)
        shadeBlocks<1>(lights, light_count, mt, eye, io + b, b + 1 == blocks ? lanes : kLightLanes);
#endif
}
