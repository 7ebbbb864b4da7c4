// MultilayerSettings described once (settings_table.h): Selgrad, Reintges, Penk, Wagner and
// Stamminger 2015, "Real-time Depth of Field Using Multi-layer Filtering", section by section.
#include <dof/multilayer.h>

#include <cmath>
#include <string>

namespace dof {

namespace {

using S = MultilayerSettings;
constexpr std::string_view kMethod = "multilayer";

constexpr ParamChoice kMergeDepth[] = {choice("mean", true), choice("nearest", false)};
constexpr ParamChoice kBlend[] = {choice("over", LayerBlend::Over),
                                  choice("additive", LayerBlend::Additive)};
constexpr ParamChoice kFilter[] = {choice("aperture", LevelFilter::Aperture),
                                   choice("box", LevelFilter::Box)};

const Param<S> kParams[] = {
    {{.name = "fragments_per_pixel",
      .flag = "fragments-per-pixel",
      .max = 1024.0,
      .paper = "Selgrad et al. 2015, §4",
      .help = "closest N fragments kept per pixel (0 = all)"},
     field<&S::fragments_per_pixel>()},
    {{.name = "skip_hidden",
      .flag = "skip-hidden",
      .type = ParamType::Switch,
      .paper = "Selgrad et al. 2015, §4",
      .help = "the closest N skip fragments within epsilon behind an opaque fragment of their "
              "pixel (off: the paper's closest N of all; no effect with fragments_per_pixel 0)"},
     field<&S::skip_hidden>()},
    {{.name = "mip_levels",
      .flag = "mip-levels",
      .max = double(kMaxFilterLevels),
      .paper = "Selgrad et al. 2015, §5.2 (the Y-map)",
      .help = "mip-mapping steps before the filter stack"},
     field<&S::mip_levels>()},
    {{.name = "stack_levels",
      .flag = "stack-levels",
      .max = double(kMaxFilterLevels),
      .special = {"auto", -1.0},
      .paper = "Selgrad et al. 2015, §5.2",
      .help = "stack filtering steps; auto: enough levels for the largest circle of confusion"},
     field<&S::stack_levels>()},
    {{.name = "epsilon",
      .flag = "epsilon",
      .max = 10.0,
      .paper = "Selgrad et al. 2015, §5.1",
      .help = "depth threshold for merging fragments, relative to depth"},
     field<&S::epsilon>()},
    {{.name = "truncate",
      .flag = "truncate",
      .type = ParamType::Switch,
      .paper = "Selgrad et al. 2015, §6.2",
      .help = "fragment list truncation"},
     field<&S::truncate>()},
    {{.name = "mean_depth",
      .flag = "merge-depth",
      .type = ParamType::Choice,
      .choices = kMergeDepth,
      .paper = "Selgrad et al. 2015, §5.1",
      .help = "the depth of a merged fragment: mean (weighted by opacity) or nearest (the "
              "paper's)"},
     field<&S::mean_depth>()},
    {{.name = "blend",
      .flag = "multilayer-blend",
      .type = ParamType::Choice,
      .choices = kBlend,
      .paper = "Selgrad et al. 2015, §6.1 and §7",
      .help = "front-to-back blending of the traversed slices"},
     field<&S::blend>()},
    {{.name = "additive_gap",
      .flag = "additive-gap",
      .max = kUnbounded,
      .special = {"inf", kUnbounded},
      .paper = "Selgrad et al. 2015, §7",
      .help = "additive blending within groups of slices whose depths are within a factor 1+G "
              "of the previous one, the over operator between groups (inf: the paper's one "
              "group)"},
     field<&S::additive_gap>()},
    {{.name = "filter",
      .flag = "level-filter",
      .type = ParamType::Choice,
      .choices = kFilter,
      .paper = "Selgrad et al. 2015, §2 and §5",
      .help = "the blur the traversed levels stand for: aperture (levels shaped like the lens "
              "aperture) or box (the paper's 2^S boxes)"},
     field<&S::filter>()},
    {{.name = "aperture_grids",
      .flag = "aperture-grids",
      .type = ParamType::List,
      .min = 2.0,
      .max = double(kMaxApertureGrid),
      .help = "taps per axis of the aperture levels built from each box level (increasing, each "
              "below twice the first; one level per grid and octave of blur)"},
     field<&S::aperture_grids>()},
    {{.name = "skip_unread_cells",
      .flag = "skip-unread-cells",
      .type = ParamType::Switch,
      .help = "merge aperture levels only in the cells the traversal can read (the same image; "
              "off: whole levels, for looking at them)"},
     field<&S::skip_unread_cells>()},
};

} // namespace

std::span<const Param<MultilayerSettings>> multilayerParams() {
    return kParams;
}

raster::Status validate(const MultilayerSettings& s) {
    if (raster::Status st = checkParams(kMethod, multilayerParams(), s); !st.ok())
        return st;
    const uint32_t stack = s.stack_levels < 0 ? 0u : uint32_t(s.stack_levels);
    if (s.mip_levels + stack > kMaxFilterLevels)
        return settingsError(kMethod, "mip_levels + stack_levels must be at most " +
                                          std::to_string(kMaxFilterLevels) + ", got " +
                                          std::to_string(s.mip_levels) + " + " +
                                          std::to_string(stack));
    if (!std::isfinite(s.aperture_second_moment) || !(s.aperture_second_moment > 0.0))
        return settingsError(kMethod, "aperture_second_moment must be positive and finite");
    if (s.node_capacity == 0)
        return settingsError(kMethod, "node_capacity must be at least 1");
    if (s.filter == LevelFilter::Aperture) {
        const std::vector<uint32_t>& g = s.aperture_grids;
        bool good = !g.empty() && g.size() <= kMaxApertureGridsPerBox;
        for (size_t i = 0; good && i < g.size(); ++i)
            good = g[i] < 2 * g[0] && (i == 0 || g[i] > g[i - 1]);
        if (!good)
            return settingsError(kMethod, "aperture_grids must be 1 to " +
                                              std::to_string(kMaxApertureGridsPerBox) +
                                              " increasing taps per axis, each below twice the "
                                              "first (e.g. 4,5,6)");
    }
    return {};
}

} // namespace dof
