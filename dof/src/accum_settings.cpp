// AccumSettings described once (settings_table.h): the accumulation buffer of Haeberli & Akeley
// 1990, the reference of all three papers.
#include <dof/accum.h>

namespace dof {

namespace {

using S = AccumSettings;

const Param<S> kParams[] = {
    {{.name = "pixel_jitter",
      .flag = "pixel-jitter",
      .type = ParamType::Flag,
      .help = "also jitter the sub-pixel position per view (box-filter anti-aliasing)"},
     field<&S::pixel_jitter>()},
};

} // namespace

std::span<const Param<AccumSettings>> accumParams() {
    return kParams;
}

} // namespace dof
