// View: everything the rasterizer needs to see a scene from one eye, and the projection focal
// uses everywhere. Built by the app from a glTF camera, the command line or the scene bounds;
// the accumulation reference derives sheared views from it (lens_offset, focus_distance).
//
// Depth convention: d is the distance along the view axis (camera space -z). The depth buffer
// stores D = -(1/d - 1/f) / (1/n - 1/f) in [-1, 0]: -1 at the near plane, 0 at the far plane
// (f = inf gives D = -n/d). D is affine in 1/d, like the circle of confusion, and grows with d
// (the depth test is LESS, the nearest depth the smallest). It is reversed-Z with the sign
// flipped: the far distances sit next to 0, where a float is densest, so float D resolves every
// distance to about 2^-24 of itself instead of rounding far surfaces onto the far plane (the
// classic 1 - n/d does that from about n * 2^24 on). docs/targets.md, "Depth precision".
#pragma once

#include <raster/scene.h>

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include <cmath>
#include <cstdint>

namespace raster {

struct View {
    glm::vec3 eye{0.0f};
    glm::vec3 forward{0.0f, 0.0f, -1.0f}; // unit view axis
    glm::vec3 right{1.0f, 0.0f, 0.0f};    // unit, image +x
    glm::vec3 up{0.0f, 1.0f, 0.0f};       // unit, image -y (pixel rows grow downwards)
    float yfov = 0.8f;                    // vertical field of view, radians
    uint32_t width = 800;
    uint32_t height = 600;
    float znear = 0.1f;
    float zfar = 0.0f; // 0: infinite far plane

    // Off-axis shifts for the accumulation reference (Haeberli & Akeley 1990): the eye moves by
    // lens_offset (world units along right/up) while the frustum is sheared so that the plane at
    // focus_distance keeps its pixels; pixel_shift moves the image by a sub-pixel amount.
    glm::vec2 lens_offset{0.0f};
    float focus_distance = 1.0f;
    glm::vec2 pixel_shift{0.0f}; // pixels, +x right, +y down

    // Every field equal (bit for bit, but -0 == +0): the same projection and image.
    friend bool operator==(const View&, const View&) = default;
};

// Focal length in pixels: f_px = (H/2) / tan(yfov/2).
float focalLengthPx(const View& view);

// World -> camera space (right, up, -forward), with the eye moved by lens_offset.
glm::mat4 viewMatrix(const View& view);
// Camera -> clip space: the off-axis frustum described above, z_clip/w_clip = D (see top).
glm::mat4 projectionMatrix(const View& view);

// Stored depth D <-> distance d along the view axis. distanceFromDepth is inline: the
// fragment-list collection and resolve and multilayer's levels call it per fragment.
float depthFromDistance(const View& view, float d);
inline float distanceFromDepth(const View& view, float stored_depth) {
    const float inv_far = view.zfar > 0.0f ? 1.0f / view.zfar : 0.0f;
    const float inv_d = inv_far - stored_depth * (1.0f / view.znear - inv_far);
    return inv_d > 0.0f ? 1.0f / inv_d : INFINITY;
}
// The smallest stored depth D with distanceFromDepth(view, D) >= d, or 1 (the cleared value)
// when no D below 1 reaches d. distanceFromDepth never decreases as D grows (each of its
// rounded steps is monotone), so for every stored D < 1 the test distanceFromDepth(view, D) >= d
// has the same outcome as D >= firstDepthAtDistance(view, d): a per-pixel test on distances
// becomes a compare of stored depths, without the division.
float firstDepthAtDistance(const View& view, float d);

// The view through scene.cameras[index] for an image of width x height. Non-square glTF
// aspect ratios keep yfov (vertical fit), as glTF specifies.
View viewFromCamera(const Camera& camera, uint32_t width, uint32_t height);
// A view that frames the whole bounds from the +z side, looking slightly down.
View viewFramingBounds(const Bounds& bounds, uint32_t width, uint32_t height);
// A view from eye to target; up is made orthogonal to the view axis.
View viewLookAt(glm::vec3 eye, glm::vec3 target, glm::vec3 up, float yfov, uint32_t width,
                uint32_t height, float znear, float zfar);

} // namespace raster
