// `focal render --method multiview`: Lee, Eisemann & Seidel 2009 (dof/multiview.h) on the
// command line: its options as a dof::MultiviewMethod (rendered by dof::FrameRenderer), the
// --multiview-debug-out pictures and its --stats.
#pragma once

#include "apps/dof_method.h"

namespace focal {

MethodEntry makeMultiviewMethod();

} // namespace focal
