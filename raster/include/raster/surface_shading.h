// Re-shading a stored surface sample (a G-buffer texel) from any eye position, with the same
// lighting kernel the rasterizer shades fragments with: Lambert + energy-normalised Blinn-Phong
// over the scene's punctual lights (or the default light of the view), constant ambient,
// emissive. Used by methods that shade per lens ray (Lee et al. 2009 §5).
#pragma once

#include <raster/camera.h>
#include <raster/layered_target.h>
#include <raster/scene.h>

#include <glm/vec3.hpp>

#include <memory>

namespace raster {

// Prepared once per frame (lights, kernel choice); shade() is thread-safe and allocation-free.
// The Scene must outlive it (or the next prepare()).
class SurfaceShader {
public:
    // Not prepared: call prepare() before shade().
    SurfaceShader() noexcept;
    SurfaceShader(const Scene& scene, const View& view, bool simd = true);
    ~SurfaceShader();
    SurfaceShader(SurfaceShader&&) noexcept;
    SurfaceShader& operator=(SurfaceShader&&) noexcept;

    // Prepares for a frame of `scene` through `view` (as the constructor does), reusing this
    // shader's memory: the same number of lights as last time allocates nothing, so a shader
    // kept between frames can be prepared again every frame.
    void prepare(const Scene& scene, const View& view, bool simd = true);

    // Linear RGB leaving `world` towards `eye` for the surface `g` (g.unlit: base colour +
    // emissive; the shading mode was applied when the sample was written).
    glm::vec3 shade(const GSample& g, glm::vec3 world, glm::vec3 eye) const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

// The direction of travel of the default light for `view` (from above-left, behind the viewer).
glm::vec3 defaultLightDirection(const View& view);

} // namespace raster
