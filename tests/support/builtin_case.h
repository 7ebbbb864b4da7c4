// A built-in scene ready for a depth-of-field test: its camera at w x h and the thin lens of its
// LensHint (the view's focus distance set to the lens's).
#pragma once

#include <dof/lens.h>
#include <raster/camera.h>
#include <raster/scene.h>

#include <cstdint>

namespace focal::test {

struct BuiltinCase {
    raster::Scene scene;
    raster::View view;
    dof::ThinLens lens;
};

// CHECKs that the scene exists (a missing built-in is a bug, not a test outcome).
BuiltinCase loadBuiltinCase(const char* name, uint32_t width, uint32_t height);

} // namespace focal::test
