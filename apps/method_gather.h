// `focal render --method gather`: Zhou, Chen & Pullen 2007 (dof/gather.h) as a method table
// entry: its options as a dof::GatherMethod (dof::FrameRenderer filters the shared pinhole frame;
// stage times "render", "coc", "vertical", "horizontal"), --gather-coc-out and its --stats.
#pragma once

#include "apps/dof_method.h"

namespace focal {

MethodEntry makeGatherMethod();

} // namespace focal
