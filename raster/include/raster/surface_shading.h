// Re-shading a stored surface sample (a G-buffer texel) from any eye position, with the same
// model the rasterizer shades fragments with: Lambert + energy-normalised Blinn-Phong over the
// scene's punctual lights (or the default light of `view`), constant ambient, emissive.
// Used by methods that shade per lens ray (Lee et al. 2009 §5). Reads the Scene; stateless.
#pragma once

#include <raster/camera.h>
#include <raster/layered_target.h>
#include <raster/renderer.h>
#include <raster/scene.h>

#include <glm/vec3.hpp>

namespace raster {

// Linear RGB leaving `world` towards `eye` for the surface `g` (g.unlit: base colour+emissive;
// the shading mode was applied when the sample was written).
// `view` supplies the default light when the scene has none (as Renderer::render does).
glm::vec3 shadeSurface(const Scene& scene, const View& view, const GSample& g, glm::vec3 world,
                       glm::vec3 eye);

// The direction of travel of the default light for `view` (from above-left, behind the viewer).
glm::vec3 defaultLightDirection(const View& view);

}  // namespace raster
