#include "support/builtin_case.h"

#include <raster/check.h>
#include <scenes/builtin.h>

#include <utility>

namespace focal::test {

BuiltinCase loadBuiltinCase(const char* name, uint32_t width, uint32_t height) {
    raster::Result<raster::Scene> scene = scenes::makeBuiltinScene(name);
    FOCAL_CHECK(scene.ok() && scene->lens && !scene->cameras.empty());
    BuiltinCase c{std::move(*scene), {}, {}};
    c.view = raster::viewFromCamera(c.scene.cameras[0], width, height);
    c.view.focus_distance = c.scene.lens->focus_distance;
    c.lens = dof::makeThinLens(c.view, c.scene.lens->aperture_radius, c.view.focus_distance);
    return c;
}

} // namespace focal::test
