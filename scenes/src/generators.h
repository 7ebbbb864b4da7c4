// One generator per built-in scene (private to scenes/); builtin.cpp dispatches by name.
// Each returns a complete Scene except `source`, which makeBuiltinScene fills in.
#pragma once

#include <raster/scene.h>

namespace scenes::detail {

raster::Scene makeDemoScene();
raster::Scene makeRailingScene();
raster::Scene makeBranchesScene();
raster::Scene makeBokehScene();
raster::Scene makeFoliageScene();
raster::Scene makeGlassScene();
raster::Scene makeDenseScene();
raster::Scene makeReflectiveScene();
raster::Scene makeNearSurfaceScene();
raster::Scene makeNearFoliageScene();
raster::Scene makePerforatedScene();

} // namespace scenes::detail
