#include "out_of_memory.h"

#include <dof/lens_resolution.h>

#include <glm/geometric.hpp>

#include <chrono>
#include <cmath>
#include <new>
#include <string>

namespace dof {

using raster::Status;

namespace {

Status checkPositive(const char* field, const std::optional<float>& v, bool allow_zero) {
    if (v && (!std::isfinite(*v) || *v < 0.0f || (!allow_zero && *v == 0.0f)))
        return Status::error(std::string(field) + " must be a finite number " +
                             (allow_zero ? ">= 0" : "> 0") + ", got " + std::to_string(*v));
    return {};
}

// The distance along the view axis to the centre of the scene's bounds, when it lies in front.
std::optional<float> boundsFocusDistance(const raster::Scene& scene, const raster::View& view) {
    const raster::Bounds b = raster::worldBounds(scene);
    const float along = glm::dot(0.5f * (b.min + b.max) - view.eye, view.forward);
    if (b.empty || !(along > 0.0f))
        return std::nullopt;
    return along;
}

bool setsLens(const LensRequest& r) {
    return r.aperture_radius || r.fstop || r.focus_distance || r.focus_pixel;
}

// The aperture radius: the request's, its f-stop's, the scene's hint's, else 0.
float resolveAperture(const LensRequest& request, const raster::Scene& scene,
                      ApertureSource& source) {
    if (request.aperture_radius) {
        source = ApertureSource::Request;
        return *request.aperture_radius;
    }
    if (request.fstop) {
        source = ApertureSource::FStop;
        return apertureRadiusFromFStop(*request.focal_length_mm, *request.fstop);
    }
    if (scene.lens) {
        source = ApertureSource::Scene;
        return scene.lens->aperture_radius;
    }
    source = ApertureSource::Default;
    return 0.0f;
}

// The depth the pinhole frame shows at the focus pixel (else the image centre); none where the
// centre shows background. Times the pinhole in r.ms_focus.
raster::Result<std::optional<float>> pinholeFocus(const LensRequest& request,
                                                  const PinholeSource& pinhole, ResolvedLens& r) {
    const auto t0 = std::chrono::steady_clock::now();
    raster::Result<const raster::Frame*> frame = pinhole(r.view);
    if (!frame.ok())
        return frame.status();
    r.ms_focus =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    const glm::uvec2 at =
        request.focus_pixel.value_or(glm::uvec2(r.view.width / 2, r.view.height / 2));
    raster::Result<float> d = focusDistanceAtPixel(**frame, r.view, at.x, at.y);
    // Without a focus pixel, a centre without depth falls back to the bounds; running out of
    // memory does not.
    if ((request.focus_pixel || detail::isOutOfMemory(d.status())) && !d.ok())
        return d.status();
    return d.ok() ? std::optional<float>(*d) : std::nullopt;
}

// The focus distance, in the order of the header's precedence; r.focus_source says which.
raster::Result<float> resolveFocus(const LensRequest& request, const raster::Scene& scene,
                                   const PinholeSource& pinhole, ResolvedLens& r) {
    if (request.focus_distance) {
        r.focus_source = FocusSource::Request;
        return *request.focus_distance;
    }
    // The pinhole frame is needed for a focus pixel, and for autofocus when nothing else names
    // a focus distance; it does not depend on the lens.
    if (request.focus_pixel || (!request.pinhole_image && !request.view_focus && !scene.lens)) {
        // Without a frame (a dry run) the bounds stand in for it.
        std::optional<float> seen;
        if (pinhole) {
            raster::Result<std::optional<float>> d = pinholeFocus(request, pinhole, r);
            if (!d.ok())
                return d.status();
            seen = *d;
        }
        if (seen) {
            r.focus_source = request.focus_pixel ? FocusSource::FocusPixel : FocusSource::Autofocus;
            return *seen;
        }
        if (const std::optional<float> bounds_d = boundsFocusDistance(scene, r.view)) {
            r.focus_source = FocusSource::Bounds;
            return *bounds_d;
        }
    } else if (request.view_focus) {
        r.focus_source = FocusSource::ViewFocus;
        return r.view.focus_distance;
    } else if (scene.lens) {
        r.focus_source = FocusSource::Scene;
        return scene.lens->focus_distance;
    }
    r.focus_source = FocusSource::ViewDefault;
    return r.view.focus_distance;
}

} // namespace

Status validate(const LensRequest& request) {
    for (const Status& s : {checkPositive("aperture_radius", request.aperture_radius, true),
                            checkPositive("fstop", request.fstop, false),
                            checkPositive("focal_length_mm", request.focal_length_mm, false),
                            checkPositive("sensor_height_mm", request.sensor_height_mm, false),
                            checkPositive("focus_distance", request.focus_distance, false)})
        if (!s.ok())
            return s;
    if (request.fstop && !request.focal_length_mm)
        return Status::error("fstop needs focal_length_mm");
    if (request.sensor_height_mm && !request.focal_length_mm)
        return Status::error("sensor_height_mm needs focal_length_mm");
    if (request.aperture_radius && request.fstop)
        return Status::error("aperture_radius and fstop exclude each other");
    if (request.focus_distance && request.focus_pixel)
        return Status::error("focus_distance and focus_pixel exclude each other");
    return {};
}

raster::View photographicView(const raster::View& view, const LensRequest& request) {
    raster::View v = view;
    if (request.focal_length_mm)
        v.yfov = yfovFromFocalLength(*request.focal_length_mm,
                                     request.sensor_height_mm.value_or(kDefaultSensorHeightMm));
    return v;
}

raster::Result<ResolvedLens> resolveLens(const LensRequest& request, const raster::Scene& scene,
                                         const raster::View& view,
                                         const PinholeSource& pinhole) try {
    if (Status s = validate(request); !s.ok())
        return s;
    ResolvedLens r;
    r.view = photographicView(view, request);
    const float aperture_radius = resolveAperture(request, scene, r.aperture_source);
    raster::Result<float> focus_distance = resolveFocus(request, scene, pinhole, r);
    if (!focus_distance.ok())
        return focus_distance.status();
    // The lens owns the focus distance; the view's copy is derived from it here and nowhere else.
    r.lens = makeThinLens(r.view, aperture_radius, *focus_distance);
    r.view.focus_distance = *focus_distance;
    if (!request.pinhole_image || setsLens(request))
        if (Status s = validate(r.lens, r.view); !s.ok())
            return s;
    return r;
} catch (const std::bad_alloc&) {
    return detail::outOfMemory("resolving the lens");
}

} // namespace dof
