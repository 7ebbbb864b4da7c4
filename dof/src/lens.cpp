#include "out_of_memory.h"

#include <dof/lens.h>

#include <cmath>
#include <cstdio>
#include <new>
#include <string>

namespace dof {

using raster::Status;

ThinLens makeThinLens(const raster::View& view, float aperture_radius, float focus_distance) {
    ThinLens lens;
    lens.aperture_radius = aperture_radius;
    lens.focus_distance = focus_distance;
    lens.focal_length_px = raster::focalLengthPx(view);
    return lens;
}

glm::vec2 lensRayImageOffset(float coc_radius_px, glm::vec2 v) {
    // Camera y is up, pixel rows grow downwards: only x changes sign (docs/dof/lens.md, "Lens
    // samples and the sign convention").
    return {-coc_radius_px * v.x, coc_radius_px * v.y};
}

float apertureRadiusFromFStop(float focal_length_mm, float fstop) {
    return focal_length_mm * 1e-3f / (2.0f * fstop);
}

float yfovFromFocalLength(float focal_length_mm, float sensor_height_mm) {
    return 2.0f * std::atan(0.5f * sensor_height_mm / focal_length_mm);
}

namespace {

// 6 significant digits, without the 39 digits std::to_string gives 3e38.
std::string text(float v) {
    char buf[32];
    std::snprintf(buf, sizeof(buf), "%g", double(v));
    return buf;
}

} // namespace

Status validate(const ThinLens& lens, const raster::View& view) {
    if (!std::isfinite(lens.aperture_radius) || lens.aperture_radius < 0.0f)
        return Status::error("aperture_radius must be a finite number >= 0 (world units), got " +
                             text(lens.aperture_radius));
    if (!std::isfinite(lens.focus_distance) || lens.focus_distance <= 0.0f)
        return Status::error("focus_distance must be a finite number > 0 (world units), got " +
                             text(lens.focus_distance));
    if (view.zfar > 0.0f && lens.focus_distance > view.zfar)
        return Status::error("focus distance " + text(lens.focus_distance) +
                             " lies behind the far plane (" + text(view.zfar) +
                             "); nothing visible could be in focus");
    if (!std::isfinite(lens.focal_length_px) || lens.focal_length_px <= 0.0f)
        return Status::error("focal length in pixels must be finite and > 0");
    return {};
}

raster::Result<float> focusDistanceAtPixel(const raster::Frame& pinhole, const raster::View& view,
                                           uint32_t x, uint32_t y) try {
    if (x >= pinhole.width || y >= pinhole.height)
        return Status::error("focus_pixel " + std::to_string(x) + "," + std::to_string(y) +
                             " lies outside the " + std::to_string(pinhole.width) + "x" +
                             std::to_string(pinhole.height) + " image");
    const float stored = pinhole.depth.load(y * pinhole.width + x);
    const float d = raster::distanceFromDepth(view, stored);
    if (!(stored < raster::kFarDepth) || !std::isfinite(d) || d <= 0.0f)
        return Status::error("focus_pixel " + std::to_string(x) + "," + std::to_string(y) +
                             " shows only background; there is no depth to focus on");
    return d;
} catch (const std::bad_alloc&) {
    return detail::outOfMemory("reading the focus distance");
}

CocRange visibleCocRange(const ThinLens& lens, const raster::Frame& pinhole,
                         const raster::View& view) {
    CocRange r;
    const raster::VisibleDepthBounds b = raster::visibleDepthBounds(pinhole);
    if (!b.any)
        return r;
    // With E f_px > 0, C never decreases as d grows, nor d as D grows (distanceFromDepth), so
    // the stored depths' ends give C's: two evaluations instead of one per pixel, the same bits.
    const float lo = cocRadiusPx(lens, raster::distanceFromDepth(view, b.min));
    const float hi = cocRadiusPx(lens, raster::distanceFromDepth(view, b.max));
    const float scale = lens.aperture_radius * lens.focal_length_px;
    if (std::isfinite(scale) && scale > 0.0f && !std::isnan(lo) && !std::isnan(hi)) {
        r.min_px = lo;
        r.max_px = hi;
        r.covered = true;
    } else { // a zero or invalid lens: every pixel, in pixel order
        raster::forEachVisibleDepth(pinhole, [&](float stored) {
            const float c = cocRadiusPx(lens, raster::distanceFromDepth(view, stored));
            if (!r.covered) {
                r.min_px = r.max_px = c;
                r.covered = true;
            }
            r.min_px = std::fmin(r.min_px, c);
            r.max_px = std::fmax(r.max_px, c);
        });
    }
    r.max_abs_px = std::fmax(std::fabs(r.min_px), std::fabs(r.max_px));
    return r;
}

} // namespace dof
