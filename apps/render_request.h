// `focal render`'s options turned into what the library takes: the raster options, the view, the
// lens request (dof/lens_resolution.h), the lens samples' aperture and pattern, the storage of
// layered targets and fragment lists. Consumes RenderArgs; produces values the caller owns; reads
// only the aperture image file. Library messages name settings fields; withOptionNames
// (apps/settings_options.h) maps them back to this command's options.
#pragma once

#include "apps/render_command.h"

#include <dof/lens_resolution.h>
#include <dof/lens_samples.h>
#include <raster/camera.h>
#include <raster/renderer.h>
#include <raster/scene.h>
#include <raster/status.h>

#include <optional>
#include <string>

namespace focal {

// Storage of the layered target / fragment lists (--precision, --target-color, --target-depth);
// unset: the method's own default.
struct TargetStorage {
    std::optional<raster::ColorFormat> color;
    std::optional<raster::DepthFormat> depth;
};

// The values the parser cannot judge: --tile a multiple of 8, --depth-out an EXR, the lens values
// finite and in range (dof::validate(LensRequest)), --focus-pixel X,Y, a finite
// --aperture-rotation.
raster::Status checkRenderArgs(const RenderArgs& args);

// True when an option that only a lens uses was given (for the pinhole method's warning).
bool hasLensOptions(const RenderArgs& args);

raster::RenderOptions renderOptionsOf(const RenderArgs& args);
TargetStorage targetStorageOf(const RenderArgs& args);

// The camera: explicit --eye/--target, a glTF camera (--camera), or one framing the scene's
// bounds, with --yfov/--near/--far applied. Its focus distance is the camera's default; the lens
// resolution decides the frame's.
raster::Result<raster::View> resolveView(const raster::Scene& scene, const RenderArgs& args);

// The lens options as the library's request. Fails only on a malformed --focus-pixel.
raster::Result<dof::LensRequest> lensRequestOf(const RenderArgs& args);

// The aperture shape of --aperture-shape/-blades/-rotation/-image (reads the image).
raster::Result<dof::ApertureShape> resolveAperture(const RenderArgs& args);

dof::LensPattern lensPatternOf(const std::string& name);

// A pixel "X,Y" (integers >= 0) given to `option`; the message names the option.
raster::Result<glm::uvec2> parsePixel(const std::string& option, const std::string& text);

} // namespace focal
