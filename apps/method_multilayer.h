// `focal render --method multilayer`: Selgrad et al. 2015 multi-layer filtering (dof/multilayer.h)
// as a method table entry: its options as a dof::MultilayerMethod (dof::FrameRenderer collects,
// filters and accumulates; stage times "collect", "filter", "accumulate", the paper's Table 1),
// --multilayer-levels-out and its --stats (counts per level).
#pragma once

#include "apps/dof_method.h"

namespace focal {

MethodEntry makeMultilayerMethod();

} // namespace focal
