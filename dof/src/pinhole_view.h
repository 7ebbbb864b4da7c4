// The pinhole view of a frame: the view through the lens centre, without sub-pixel shift, which
// every method's pinhole frame is rendered through (frame_renderer.cpp, frame_stages.cpp).
#pragma once

#include <raster/camera.h>

namespace dof::detail {

inline raster::View pinholeView(const raster::View& view) {
    raster::View v = view;
    v.lens_offset = glm::vec2(0.0f);
    v.pixel_shift = glm::vec2(0.0f);
    return v;
}

} // namespace dof::detail
