#include "apps/bench_sweep.h"

#include "apps/settings_options.h"

#include <raster/check.h>

#include <utility>

namespace focal {

namespace {

// A setting named by the settings fields it sets (dof/settings_table.h), spelled as `focal
// render` options through the method's table.
Setting named(const std::string& method, std::string label,
              std::initializer_list<std::pair<std::string_view, std::string>> values) {
    Setting s{std::move(label), {}};
    for (const auto& [name, value] : values) {
        const std::string option = optionFor(method, name);
        FOCAL_CHECK(!option.empty()); // a sweep names a field its method's table does not have
        s.args.push_back(option);
        s.args.push_back(value);
    }
    return s;
}

} // namespace

// accum's N doubles from 4 to 256 so that every equal-error target between the cheapest and the
// best accum is bracketed by two neighbouring settings (apps/equal_error.h); the other methods
// cover their useful range. The studies keep the settings they had before the sweeps grew:
// accum N = 16 (quick: 8) for both; the others' first for scaling, last for temporal.
std::vector<Setting> settingsFor(const std::string& method, bool quick) {
    if (method == "accum") {
        const std::vector<int> ns =
            quick ? std::vector<int>{4, 8, 16, 32} : std::vector<int>{4, 8, 16, 32, 64, 128, 256};
        const int study = quick ? 8 : 16;
        std::vector<Setting> out;
        for (int n : ns) {
            const std::string v = std::to_string(n);
            out.push_back(named(method, "N=" + v, {{"samples", v}}));
            out.back().scaling = out.back().temporal = n == study;
        }
        return out;
    }
    if (method == "gather") {
        auto g = [&](const char* r) {
            return named(method, std::string("R=") + r, {{"max_radius_px", r}});
        };
        if (quick)
            return {g("16")};
        return {g("8"), g("16"), g("32")};
    }
    if (method == "multiview") {
        auto m = [&](const char* spacing, const char* samples) {
            return named(method, std::string("spacing=") + spacing + ",N=" + samples,
                         {{"layers", "0"}, {"layer_spacing_px", spacing}, {"samples", samples}});
        };
        if (quick)
            return {m("4", "16")};
        Setting first = m("4", "16");
        first.scaling = true;
        // N = 4 is the cheapest that still reaches SSIM 0.98 and 35 dB on demo (800x600).
        return {m("4", "4"), m("4", "8"), first, m("2", "32"), m("1", "64")};
    }
    if (method == "multilayer") {
        auto m = [&](const char* n) {
            return named(method, std::string("frags=") + n, {{"fragments_per_pixel", n}});
        };
        if (quick)
            return {m("4")};
        // The paper's box levels (Selgrad et al. 2015, §5): square bokeh, but about half the
        // aperture levels' time; where a scene's error allows it, the cheapest setting.
        Setting box =
            named(method, "frags=2,box", {{"fragments_per_pixel", "2"}, {"filter", "box"}});
        return {m("2"), box, m("4"), m("8")};
    }
    return {{"default", {}}}; // pinhole
}

Setting studySetting(const std::string& method, bool quick, bool Setting::*flag) {
    const std::vector<Setting> all = settingsFor(method, quick);
    for (const Setting& s : all)
        if (s.*flag)
            return s;
    return flag == &Setting::scaling ? all.front() : all.back();
}

} // namespace focal
