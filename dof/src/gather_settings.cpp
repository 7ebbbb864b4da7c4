// GatherSettings described once (settings_table.h): Zhou, Chen & Pullen 2007, "Accurate Depth
// of Field Simulation in Real Time", §4.
#include <dof/gather.h>

#include <cmath>
#include <string>

namespace dof {

namespace {

using S = GatherSettings;
constexpr std::string_view kMethod = "gather";

const Param<S> kParams[] = {
    {{.name = "max_radius_px",
      .flag = "gather-max-radius",
      .min = 1.0,
      .max = 256.0,
      .paper = "Zhou et al. 2007, §4.2",
      .help = "largest CoC radius honoured, pixels; larger CoCs are clamped to it"},
     field<&S::max_radius_px>()},
    {{.name = "leak_scale",
      .flag = "gather-leak-scale",
      .max = kUnbounded,
      .paper = "Zhou et al. 2007, §4.2",
      .help = "leakage control L = min(1, scale * r_centre) for samples behind the focal plane "
              "(per pixel of centre CoC)"},
     field<&S::leak_scale>()},
    {{.name = "min_radius_px",
      .flag = "gather-min-radius",
      .max = 1.0,
      .min_open = true,
      .paper = "Zhou et al. 2007, §4.2",
      .help = "intensity I(r) = 1/max(r, this)^2, pixels"},
     field<&S::min_radius_px>()},
    {{.name = "skip_tiles",
      .flag = "gather-skip-tiles",
      .type = ParamType::Switch,
      .help = "copy tiles no CoC of half a pixel or more can reach, and bound each row's loop "
              "(off: filter every tile over the full reach; the same output, slower)"},
     field<&S::skip_tiles>()},
};

} // namespace

std::span<const Param<GatherSettings>> gatherParams() {
    return kParams;
}

raster::Status validate(const GatherSettings& s) {
    if (raster::Status st = checkParams(kMethod, gatherParams(), s); !st.ok())
        return st;
    if (s.tile_size < 8 || s.tile_size > 256 || s.tile_size % 8 != 0)
        return settingsError(kMethod, "tile_size must be a multiple of 8 in [8, 256], got " +
                                          std::to_string(s.tile_size));
    return {};
}

} // namespace dof
