// `focal render --method multiview`: Lee, Eisemann & Seidel 2009 (dof/multiview.h) on the
// command line. Adds the method's options to the render command and runs it from a MethodInput.
#pragma once

#include "apps/dof_method.h"

namespace focal {

MethodEntry makeMultiviewMethod();

} // namespace focal
