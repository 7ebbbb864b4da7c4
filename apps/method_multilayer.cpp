#include "apps/method_multilayer.h"

#include "apps/image_io.h"
#include "apps/settings_options.h"

#include <dof/multilayer.h>

#include <cmath>
#include <memory>
#include <string>
#include <variant>
#include <vector>

namespace focal {

namespace {

// Values of the multilayer options (owned by the entry, shared by its two functions).
struct MultilayerArgs {
    dof::MultilayerSettings settings; // the table's options (dof::multilayerParams)
    std::string levels_out;           // prefix of the per-level contribution images (Fig. 7)
};

raster::Result<dof::MethodSettings> multilayerSettings(const MultilayerArgs& args,
                                                       const MethodContext& in) {
    dof::MultilayerSettings settings = args.settings;
    settings.color_format = in.target_color.value_or(raster::ColorFormat::Half);
    settings.depth_format = in.target_depth.value_or(raster::DepthFormat::Float32);
    settings.level_contributions = !args.levels_out.empty();
    // dof::FrameRenderer takes the aperture, its second moment and the memory budget from the
    // lens samples and the raster options.
    return dof::MethodSettings(dof::MultilayerMethod{settings, &in.lens_samples});
}

raster::Status finishMultilayer(const MultilayerArgs& args, const dof::MethodSettings& method,
                                const dof::FrameRenderer& frames, const dof::FrameReport& report,
                                MethodOutput& out) {
    const dof::MultilayerSettings& settings = std::get<dof::MultilayerMethod>(method).settings;
    const dof::MultilayerStats& st = std::get<dof::MultilayerStats>(report.method_stats);
    const raster::FrameStats& raster_stats = report.collect;
    if (!args.levels_out.empty()) {
        // One image per level (premultiplied contribution) and the background's share.
        const dof::MultilayerImage& image = frames.multilayerImage();
        for (size_t s = 0; s < image.level_rgba.size(); ++s) {
            ImageData img{image.width, image.height, 4, image.level_rgba[s]};
            for (size_t i = 0; i < img.pixels.size() / 4; ++i)
                img.pixels[4 * i + 3] = 1.0f;
            const std::string name =
                s + 1 == image.level_rgba.size() ? "background" : "level" + std::to_string(s);
            const std::string path = args.levels_out + name + ".png";
            if (raster::Status w = writeImage(path, img); !w.ok())
                return w;
        }
    }

    out.params = settingsJson(dof::multilayerParams(), settings);
    out.params["mip_levels_used"] = st.mip_levels;
    out.params["stack_levels_used"] = st.stack_levels;
    out.params["second_moment"] = st.second_moment;
    out.params["color_format"] =
        settings.color_format == raster::ColorFormat::Half ? "half" : "float32";
    out.params["depth_format"] =
        settings.depth_format == raster::DepthFormat::Unorm16 ? "unorm16" : "float32";
    auto levelJson = [](const dof::MultilayerLevelStats& l) {
        nlohmann::json j = {{"level", l.index},
                            {"kind", dof::levelKindName(l.kind)},
                            {"width", l.width},
                            {"height", l.height},
                            {"dilation", l.dilation},
                            {"fragments", l.fragments},
                            {"max_list_length", l.max_list_length},
                            {"mean_list_length", l.mean_list_length},
                            {"truncated", l.truncated}};
        if (l.kind == dof::LevelKind::Aperture) {
            j["source"] = l.source;
            j["grid"] = l.grid;
            j["cells_skipped"] = l.cells_skipped;
        }
        return j;
    };
    nlohmann::json levels = nlohmann::json::array();
    for (const dof::MultilayerLevelStats& l : st.levels)
        levels.push_back(levelJson(l));
    nlohmann::json apertures = nlohmann::json::array();
    for (const dof::MultilayerLevelStats& l : st.apertures)
        apertures.push_back(levelJson(l));
    nlohmann::json traversal = nlohmann::json::array();
    for (const dof::MultilayerTraversalStats& t : st.traversal) {
        auto finite = [](float z) {
            return std::isfinite(z) ? nlohmann::json(z) : nlohmann::json(nullptr);
        };
        traversal.push_back({{"level", t.index},
                             {"kind", dof::levelKindName(t.kind)},
                             {"reads", t.level},
                             {"radius_px", t.radius_px},
                             {"z_near", finite(t.z_near)},
                             {"z_far", finite(t.z_far)}});
    }
    out.counts = {{"fragments_collected", st.fragments_collected},
                  {"fragments_rejected_early", st.fragments_rejected},
                  {"fragments_hidden", st.fragments_hidden},
                  {"skipped_hidden", st.skipped_hidden},
                  {"fragments_kept", st.fragments_kept},
                  {"max_list_length", st.max_list_length},
                  {"node_pool_grew", st.node_pool_grew},
                  {"max_coc_px", st.max_coc_px},
                  {"slices_blended", st.slices_blended},
                  {"ms_raster", raster_stats.ms_raster},
                  {"ms_resolve", raster_stats.ms_resolve},
                  {"asymmetric_aperture", st.asymmetric_aperture},
                  {"levels", levels},
                  {"aperture_levels", apertures},
                  {"traversal", traversal}};
    return {};
}

} // namespace

MethodEntry makeMultilayerMethod() {
    auto args = std::make_shared<MultilayerArgs>();
    MethodEntry e;
    e.name = "multilayer";
    e.summary = "Selgrad et al. 2015: filtered per-pixel fragment lists (docs/dof/multilayer.md)";
    e.add_options = [args](CLI::App& render) {
        addSettingsOptions(render, "multilayer", dof::multilayerParams(), args->settings);
        render.add_option("--multilayer-levels-out", args->levels_out,
                          "multilayer: write each level's contribution (Fig. 7) to "
                          "PREFIXlevelS.png and PREFIXbackground.png");
    };
    e.settings = [args](const MethodContext& in) { return multilayerSettings(*args, in); };
    e.finish = [args](const MethodContext&, const dof::MethodSettings& method,
                      const dof::FrameRenderer& frames, const dof::FrameReport& report,
                      const std::vector<float>&, MethodOutput& out) {
        return finishMultilayer(*args, method, frames, report, out);
    };
    return e;
}

} // namespace focal
