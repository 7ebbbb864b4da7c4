#include "light_kernel.h"

#include <raster/simd.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>

namespace raster {

#define FOCAL_LIGHT_KERNEL_NAME lightKernelScalar
#define FOCAL_LIGHT_KERNEL_FULL_WIDTH 0
#include "light_kernel.inl"
#undef FOCAL_LIGHT_KERNEL_FULL_WIDTH
#undef FOCAL_LIGHT_KERNEL_NAME

#ifdef FOCAL_NO_SIMD
LightKernel lightKernelAvx2() {
    return nullptr;
}
#endif

LightKernel selectLightKernel(bool simd) {
    return useAvx2(simd) ? lightKernelAvx2() : &lightKernelScalar;
}

void prepareLights(const Scene& scene, glm::vec3 default_direction,
                   std::vector<PreparedLight>& out) {
    out.clear();
    auto set3 = [](float* dst, glm::vec3 v) { dst[0] = v.x, dst[1] = v.y, dst[2] = v.z; };
    if (scene.lights.empty()) {
        // A directional light whose irradiance makes a facing surface show its albedo.
        PreparedLight p;
        set3(p.radiance, glm::vec3(3.14159265358979f));
        set3(p.direction, glm::normalize(default_direction));
        out.push_back(p);
        return;
    }
    for (const Light& light : scene.lights) {
        PreparedLight p;
        p.type = light.type;
        set3(p.radiance, light.color * light.intensity);
        set3(p.direction, glm::normalize(light.direction));
        set3(p.position, light.position);
        p.inv_range2 = light.range > 0.0f ? 1.0f / (light.range * light.range) : 0.0f;
        if (light.type == Light::Type::Spot) {
            p.cos_outer = std::cos(light.outer_cone_angle);
            const float cos_inner = std::cos(light.inner_cone_angle);
            p.inv_cone_width = 1.0f / std::max(cos_inner - p.cos_outer, 1e-4f);
        }
        out.push_back(p);
    }
}

} // namespace raster
