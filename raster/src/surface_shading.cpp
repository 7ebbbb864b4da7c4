#include "light_kernel.h"
#include "shading.h"

#include <raster/surface_shading.h>

#include <glm/geometric.hpp>

#include <vector>

namespace raster {

glm::vec3 defaultLightDirection(const View& view) {
    return glm::normalize(0.35f * view.right - 0.6f * view.up + 0.7f * view.forward);
}

struct SurfaceShader::Impl {
    std::vector<PreparedLight> lights;
    ShadeContext ctx;
};

SurfaceShader::SurfaceShader() noexcept = default;

SurfaceShader::SurfaceShader(const Scene& scene, const View& view, bool simd) {
    prepare(scene, view, simd);
}

void SurfaceShader::prepare(const Scene& scene, const View& view, bool simd) {
    if (!impl_)
        impl_ = std::make_unique<Impl>();
    prepareLights(scene, defaultLightDirection(view), impl_->lights);
    impl_->ctx.scene = &scene;
    impl_->ctx.lights = impl_->lights.data();
    impl_->ctx.light_count = uint32_t(impl_->lights.size());
    impl_->ctx.light_kernel = selectLightKernel(simd);
}

SurfaceShader::~SurfaceShader() = default;
SurfaceShader::SurfaceShader(SurfaceShader&&) noexcept = default;
SurfaceShader& SurfaceShader::operator=(SurfaceShader&&) noexcept = default;

glm::vec3 SurfaceShader::shade(const GSample& g, glm::vec3 world, glm::vec3 eye) const {
    return shadeSample(impl_->ctx, g, world, eye);
}

} // namespace raster
