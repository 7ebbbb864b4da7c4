// `focal render --method gather`: Zhou, Chen & Pullen 2007 (dof/gather.h) as a method table
// entry. Renders the pinhole frame with raster::Renderer, then runs the two-pass filter on its
// colour and stored depth; stage times "render", "coc", "vertical", "horizontal".
#pragma once

#include "apps/dof_method.h"

namespace focal {

MethodEntry makeGatherMethod();

} // namespace focal
