// Lens resolution: the thin lens one frame is rendered with. Consumes what the caller asks for (a
// LensRequest: an aperture radius or photographic f-stop and focal length, a focus distance or a
// pixel to focus on), the scene's lens hint, the view and, for autofocus, the pinhole frame
// (through a callback, so a FrameRenderer renders it once and its methods reuse it); produces a
// ResolvedLens: the ThinLens, which owns the focus distance, the view derived from it, and where
// each value came from. Plain values; the caller owns everything.
//
// Precedence (docs/dof/lens.md, "Options and defaults of `focal render`"):
//   aperture  request.aperture_radius, else E = focal_length_mm * 1e-3 / (2 fstop) (Blender/Cycles,
//             world units taken as metres), else the scene's hint, else 0 (a pinhole).
//   focus     request.focus_distance, else the depth the pinhole frame shows at focus_pixel, else
//             the view's own (view_focus: e.g. a look-at target), else the scene's hint, else
//             autofocus: the depth at the image centre, else the distance to the centre of the
//             scene's bounds, else the view's focus distance.
#pragma once

#include <dof/lens.h>
#include <raster/camera.h>
#include <raster/frame.h>
#include <raster/scene.h>
#include <raster/status.h>

#include <glm/vec2.hpp>

#include <functional>
#include <optional>

namespace dof {

// The sensor height when the request gives a focal length but no sensor (a full-frame 35 mm
// camera's 24 mm, vertical fit).
inline constexpr float kDefaultSensorHeightMm = 24.0f;

// What the caller asks of the lens; unset values come from the scene and the defaults above.
// Messages about a field name it as written here (aperture_radius, fstop, ...).
struct LensRequest {
    std::optional<float> aperture_radius;  // E, world units, >= 0
    std::optional<float> fstop;            // N > 0; needs focal_length_mm, excludes E
    std::optional<float> focal_length_mm;  // > 0; also sets the view's yfov
    std::optional<float> sensor_height_mm; // > 0; only with focal_length_mm
    std::optional<float> focus_distance;   // d_f > 0, world units along the view axis
    std::optional<glm::uvec2> focus_pixel; // excludes focus_distance
    // The view's focus distance is the caller's choice (the distance to the point a look-at
    // camera aims at): it comes before the scene's hint and autofocus.
    bool view_focus = false;
    // The frame is the pinhole image, which no lens changes: no autofocus render, and the lens
    // is checked only when the request sets one of its values.
    bool pinhole_image = false;
};

enum class ApertureSource { Request, FStop, Scene, Default };
enum class FocusSource { Request, FocusPixel, ViewFocus, Scene, Autofocus, Bounds, ViewDefault };

struct ResolvedLens {
    ThinLens lens;
    // The caller's view with the request's yfov (focal length) and the lens's focus distance:
    // the view to render the frame with. Equal to photographicView(view, request) but for
    // focus_distance.
    raster::View view;
    ApertureSource aperture_source = ApertureSource::Default;
    FocusSource focus_source = FocusSource::ViewDefault;
    double ms_focus = 0.0; // time spent getting the pinhole frame for focusing (0: none needed)
};

// Renders (or returns a kept) pinhole frame through `view`, for autofocus and focus_pixel. The
// frame must stay valid until the resolution returns.
using PinholeSource = std::function<raster::Result<const raster::Frame*>(const raster::View&)>;

// Rejects NaN/inf, a negative aperture radius, an f-stop, focal length, sensor height or focus
// distance <= 0, an f-stop without a focal length, a sensor height without one, and both of
// aperture_radius/fstop or focus_distance/focus_pixel.
[[nodiscard]] raster::Status validate(const LensRequest& request);

// `view` with yfov = 2 atan(sensor_height_mm / (2 focal_length_mm)) when the request has a focal
// length (Blender's vertical sensor fit); unchanged otherwise. Needs no rendering, so a caller
// can check the view and its memory before resolving the lens.
raster::View photographicView(const raster::View& view, const LensRequest& request);

// The lens for `request`. `pinhole` may be empty (e.g. a dry run): focus_pixel and autofocus then
// fall back to the bounds, then the view. The caller checks the view (raster::validate); the
// pinhole render checks it too. Fails on an invalid request, a failed pinhole render, a focus pixel
// outside the image or showing only background, and (unless a pinhole image was asked for with no
// lens value) a lens validate(ThinLens, View) rejects.
[[nodiscard]] raster::Result<ResolvedLens> resolveLens(const LensRequest& request,
                                                       const raster::Scene& scene,
                                                       const raster::View& view,
                                                       const PinholeSource& pinhole);

} // namespace dof
