#include <raster/surface_shading.h>

#include "shading.h"

#include <glm/geometric.hpp>

namespace raster {

glm::vec3 defaultLightDirection(const View& view) {
    return glm::normalize(0.35f * view.right - 0.6f * view.up + 0.7f * view.forward);
}

glm::vec3 shadeSurface(const Scene& scene, const View& view, const GSample& g, glm::vec3 world,
                       glm::vec3 eye) {
    ShadeContext ctx;
    ctx.scene = &scene;
    ctx.eye = eye;
    ctx.default_light_dir = defaultLightDirection(view);
    return shadeSample(ctx, g, world, eye);
}

}  // namespace raster
