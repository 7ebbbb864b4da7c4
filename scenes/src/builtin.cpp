#include "generators.h"

#include <scenes/builtin.h>

#include <array>
#include <string>
#include <utility>

namespace scenes {
namespace {

struct Entry {
    BuiltinInfo info;
    raster::Scene (*make)();
};

constexpr std::array<Entry, 11> kEntries = {{
    {{"demo", "the overview: checker ground, objects at several depths (textured, coloured, "
              "emissive) and a thin out-of-focus railing in front of in-focus detail"},
     detail::makeDemoScene},
    {{"railing", "strong near-field blur: thin bars close to the camera in front of in-focus "
                 "text and a checker (Selgrad et al. 2015, Fig. 1)"},
     detail::makeRailingScene},
    {{"branches", "focal plane between two thin crossing branches, one blurred in front and one "
                  "behind (Lee, Eisemann & Seidel 2009, Fig. 8, second row)"},
     detail::makeBranchesScene},
    {{"bokeh", "small bright emitters (emissive >> 1) far behind the focal plane make bokeh "
               "discs; an in-focus object in front"},
     detail::makeBokehScene},
    {{"foliage", "many alpha-masked double-sided leaf quads (MASK): high depth complexity "
                 "(Selgrad et al. 2015, Fig. 10)"},
     detail::makeFoliageScene},
    {{"glass", "semi-transparent coloured panes (BLEND) at several depths in front of a "
               "textured wall and objects"},
     detail::makeGlassScene},
    {{"dense", "performance: more than 1M triangles (finely tessellated spheres and tori over "
               "a tessellated ground)"},
     detail::makeDenseScene},
    {{"reflective", "view-dependent shading: shiny metallic spheres of varying roughness under "
                    "point lights (Lee, Eisemann & Seidel 2009, Sec. 5)"},
     detail::makeReflectiveScene},
    {{"nearsurface", "a large smooth shaded machine part 0.17-0.34 m from the lens, blurred "
                     "17-40 px over an in-focus brick wall and sign"},
     detail::makeNearSurfaceScene},
    {{"nearfoliage", "large alpha-masked (MASK) leaves 0.3-1 m from the lens, blurred up to "
                     "50 px over an in-focus wall, sign and sphere"},
     detail::makeNearFoliageScene},
    {{"perforated", "thin machined parts: a perforated grill blurred 25 px in front, gears with "
                    "thin teeth in front of, at and behind the focal plane"},
     detail::makePerforatedScene},
}};

constexpr std::array<BuiltinInfo, kEntries.size()> makeInfos() {
    std::array<BuiltinInfo, kEntries.size()> infos{};
    for (size_t i = 0; i < kEntries.size(); ++i)
        infos[i] = kEntries[i].info;
    return infos;
}

constexpr std::array<BuiltinInfo, kEntries.size()> kInfos = makeInfos();

} // namespace

std::span<const BuiltinInfo> builtinScenes() {
    return kInfos;
}

raster::Result<raster::Scene> makeBuiltinScene(std::string_view name) {
    constexpr std::string_view kPrefix = "builtin:";
    if (name.substr(0, kPrefix.size()) == kPrefix)
        name.remove_prefix(kPrefix.size());
    for (const Entry& entry : kEntries) {
        if (entry.info.name != name)
            continue;
        raster::Scene scene = entry.make();
        scene.source.assign(kPrefix);
        scene.source.append(name);
        return scene;
    }
    std::string message = "unknown built-in scene '" + std::string(name) + "' (valid names:";
    for (const Entry& entry : kEntries) {
        message += ' ';
        message += entry.info.name;
    }
    message += ")";
    return raster::Status::error(std::move(message));
}

} // namespace scenes
