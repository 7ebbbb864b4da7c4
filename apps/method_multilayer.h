// `focal render --method multilayer`: Selgrad et al. 2015 multi-layer filtering (dof/multilayer.h)
// as a method table entry. Collects per-pixel fragment lists with raster::Renderer, filters them
// into levels and accumulates; stage times "collect", "filter", "accumulate" (the paper's
// Table 1), counts per level in --stats.
#pragma once

#include "apps/dof_method.h"

namespace focal {

MethodEntry makeMultilayerMethod();

} // namespace focal
