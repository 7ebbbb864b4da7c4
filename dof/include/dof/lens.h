// The thin lens: the one camera-lens model every DOF method in focal shares (docs/dof/lens.md).
// Consumes a raster::View (for f_px and the clip planes) plus aperture radius and focus distance;
// produces the signed circle of confusion and the lens-ray image offset. Plain values, no memory
// owned.
//
// Units and signs
//   E     aperture (lens) radius, world units, >= 0 (0 = pinhole).
//   d_f   focus distance, world units along the view axis, > 0.
//   f_px  focal length in pixels, (H/2) / tan(yfov/2) (raster::focalLengthPx).
//   d     depth: distance along the view axis (camera -z), world units.
//   C(d) = E * f_px * (1/d_f - 1/d)    signed CoC radius in pixels,
//          negative in front of the focal plane (d < d_f), positive behind it, 0 at d = d_f,
//          tending to E * f_px / d_f at infinity.
//   This is Lee et al. 2009 Eq. 3 with the image plane at the pinhole's f_px (u_f -> f_px when
//   F << d_f), Zhou et al. 2007 Eq. 2 (there a diameter, with D = 2E), and Selgrad et al. 2015's
//   Coc(z) = F |z - z_f| written in pixels and signed.
//
// Lens samples v live in the unit disk (or the aperture shape's bounds [-1,1]^2) with v.x along
// View::right and v.y along View::up. The lens point is eye + E*(v.x*right + v.y*up). The lens
// ray through pixel p (x right, y down) meets depth d where the pinhole image shows
//   p + C(d) * (-v.x, +v.y)                      (lensRayImageOffset)
// i.e. p - C(d)*v with the y flip between camera space (y up) and pixel rows (y down).
// Consequence: the blur of a point behind the focal plane (C > 0) is the aperture shape, upright
// as drawn with +y up; in front of the focal plane (C < 0) it is rotated by 180 degrees.
#pragma once

#include <raster/camera.h>
#include <raster/frame.h>
#include <raster/status.h>

#include <glm/vec2.hpp>

#include <cmath>
#include <cstdint>

namespace dof {

// The lens owns the focus distance: a raster::View's focus_distance is only a copy, which the
// lens-moved views of accum (accum.h, lensView) take from here. lens_resolution.h chooses it.
struct ThinLens {
    float aperture_radius = 0.0f; // E, world units
    float focus_distance = 1.0f;  // d_f, world units along the view axis
    float focal_length_px = 1.0f; // f_px, pixels
};

// The lens for `view` (f_px from its yfov and height).
ThinLens makeThinLens(const raster::View& view, float aperture_radius, float focus_distance);

// Signed circle-of-confusion radius in pixels, C(d) = E*f_px*(1/d_f - 1/d); C(inf) = E*f_px/d_f
// (Lee et al. 2009 Eq. 3 in pixels). Inline: multilayer calls it per slice and per fragment.
inline float cocRadiusPx(const ThinLens& lens, float depth) {
    const float inv_d = std::isinf(depth) ? 0.0f : 1.0f / depth;
    return lens.aperture_radius * lens.focal_length_px * (1.0f / lens.focus_distance - inv_d);
}

// Where the lens ray through a pixel, from lens sample v, meets depth d, relative to that
// pixel in the pinhole image (pixels, x right, y down): C(d) * (-v.x, v.y).
glm::vec2 lensRayImageOffset(float coc_radius_px, glm::vec2 v);

// Photographic input (Blender/Cycles convention, vertical sensor fit):
//   E = focal_length_mm * 1e-3 / (2 * fstop)     (world units taken as metres)
//   yfov = 2 * atan(sensor_height_mm / (2 * focal_length_mm))
float apertureRadiusFromFStop(float focal_length_mm, float fstop);
float yfovFromFocalLength(float focal_length_mm, float sensor_height_mm);

// Rejects NaN/inf, E < 0, d_f <= 0, d_f beyond a finite far plane, f_px <= 0. Messages name the
// fields (aperture_radius, focus_distance); a command line maps them to its options.
raster::Status validate(const ThinLens& lens, const raster::View& view);

// The focus distance seen at pixel (x, y) of a pinhole frame rendered through `view`: the depth
// buffer's distance along the view axis. Fails outside the image or where the pixel shows only
// background (nothing to focus on); the messages call the pixel focus_pixel.
raster::Result<float> focusDistanceAtPixel(const raster::Frame& pinhole, const raster::View& view,
                                           uint32_t x, uint32_t y);

// Range of C(d) over the pixels of `pinhole` that show geometry (stored depth < 1). Pixels
// showing background are skipped; `covered` is false when none shows geometry.
struct CocRange {
    float min_px = 0.0f;
    float max_px = 0.0f;
    float max_abs_px = 0.0f;
    bool covered = false;
};
CocRange visibleCocRange(const ThinLens& lens, const raster::Frame& pinhole,
                         const raster::View& view);

} // namespace dof
