#include "apps/method_multilayer.h"

#include "apps/image_io.h"

#include <dof/multilayer.h>

#include <charconv>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <variant>
#include <vector>

namespace focal {

namespace {

// Values of the multilayer options (owned by the entry, shared by its two functions).
struct MultilayerArgs {
    dof::MultilayerSettings settings;
    std::string stack_levels = "auto";
    std::string truncate = "on";
    std::string skip_hidden = "on";
    std::string blend = "additive";
    std::string filter = "aperture";
    std::string merge_depth = "mean";
    std::string additive_gap = "1";
    std::string levels_out; // prefix of the per-level contribution images (Fig. 7)
};

const char* kindName(dof::LevelKind k) {
    switch (k) {
    case dof::LevelKind::Base:
        return "base";
    case dof::LevelKind::Mip:
        return "mip";
    case dof::LevelKind::Stack:
        return "stack";
    case dof::LevelKind::Aperture:
        return "aperture";
    }
    return "?";
}

raster::Result<dof::MethodSettings> multilayerSettings(const MultilayerArgs& args,
                                                       const MethodContext& in) {
    dof::MultilayerSettings settings = args.settings;
    if (args.stack_levels == "auto") {
        settings.stack_levels = -1;
    } else {
        uint32_t v = 0;
        const char* first = args.stack_levels.data();
        const char* last = first + args.stack_levels.size();
        const std::from_chars_result r = std::from_chars(first, last, v);
        if (r.ec != std::errc() || r.ptr != last || v > dof::kMaxFilterLevels)
            return raster::Status::error("--stack-levels must be a count in [0, " +
                                         std::to_string(dof::kMaxFilterLevels) +
                                         "] or 'auto', got '" + args.stack_levels + "'");
        settings.stack_levels = int32_t(v);
    }
    settings.truncate = args.truncate == "on";
    settings.skip_hidden = args.skip_hidden == "on";
    settings.blend = args.blend == "additive" ? dof::LayerBlend::Additive : dof::LayerBlend::Over;
    settings.filter =
        args.filter == "aperture" ? dof::LevelFilter::Aperture : dof::LevelFilter::Box;
    settings.mean_depth = args.merge_depth == "mean";
    if (args.additive_gap == "inf") {
        settings.additive_gap = std::numeric_limits<float>::infinity();
    } else {
        const char* first = args.additive_gap.data();
        const char* last = first + args.additive_gap.size();
        // The range is checked with the other settings (dof::validate).
        const std::from_chars_result r = std::from_chars(first, last, settings.additive_gap);
        if (r.ec != std::errc() || r.ptr != last)
            return raster::Status::error("--additive-gap must be a relative depth gap >= 0 or "
                                         "'inf', got '" +
                                         args.additive_gap + "'");
    }
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

    out.params = {
        {"fragments_per_pixel", settings.fragments_per_pixel},
        {"skip_hidden", settings.skip_hidden},
        {"mip_levels", st.mip_levels},
        {"stack_levels", st.stack_levels},
        {"stack_levels_option", args.stack_levels},
        {"epsilon", settings.epsilon},
        {"truncate", settings.truncate},
        {"blend", args.blend},
        {"level_filter", args.filter},
        {"merge_depth", args.merge_depth},
        {"additive_gap", args.additive_gap},
        {"aperture_grids", settings.aperture_grids},
        {"second_moment", st.second_moment},
        {"color_format", settings.color_format == raster::ColorFormat::Half ? "half" : "float32"},
        {"depth_format",
         settings.depth_format == raster::DepthFormat::Unorm16 ? "unorm16" : "float32"}};
    auto levelJson = [](const dof::MultilayerLevelStats& l) {
        nlohmann::json j = {{"level", l.index},
                            {"kind", kindName(l.kind)},
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
                             {"kind", kindName(t.kind)},
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
        *args = MultilayerArgs{}; // each new command line starts from the defaults
        render
            .add_option("--fragments-per-pixel", args->settings.fragments_per_pixel,
                        "multilayer: closest N fragments kept per pixel (§4; 0 = all)")
            ->default_val(4);
        render
            .add_option("--mip-levels", args->settings.mip_levels,
                        "multilayer: mip-mapping steps before the filter stack (§5.2 Y-map)")
            ->default_val(1);
        render
            .add_option("--stack-levels", args->stack_levels,
                        "multilayer: stack filtering steps, or 'auto' (enough levels for the "
                        "largest circle of confusion)")
            ->default_val("auto");
        render
            .add_option("--epsilon", args->settings.epsilon,
                        "multilayer: depth threshold for merging fragments, relative to depth "
                        "(§5.1)")
            ->default_val(0.2f);
        render
            .add_option("--skip-hidden", args->skip_hidden,
                        "multilayer: the closest N skip fragments within --epsilon behind an "
                        "opaque fragment of their pixel (off: the paper's closest N of all, §4; "
                        "no effect with --fragments-per-pixel 0)")
            ->check(CLI::IsMember({"on", "off"}))
            ->default_val("on");
        render
            .add_option("--truncate", args->truncate, "multilayer: fragment list truncation (§6.2)")
            ->check(CLI::IsMember({"on", "off"}))
            ->default_val("on");
        render
            .add_option("--multilayer-blend", args->blend,
                        "multilayer: front-to-back blending of the traversed slices (§6.1, §7)")
            ->check(CLI::IsMember({"over", "additive"}))
            ->default_val("additive");
        render
            .add_option("--additive-gap", args->additive_gap,
                        "multilayer: additive blending within groups of slices whose depths are "
                        "within a factor 1+G of the previous one, the over operator between "
                        "groups ('inf': the paper's one group)")
            ->default_val("1");
        render
            .add_option("--merge-depth", args->merge_depth,
                        "multilayer: the depth of a merged fragment: mean (weighted by opacity) "
                        "or nearest (the paper's, §5.1)")
            ->check(CLI::IsMember({"mean", "nearest"}))
            ->default_val("mean");
        render
            .add_option("--level-filter", args->filter,
                        "multilayer: the blur the traversed levels stand for: aperture (levels "
                        "shaped like the lens aperture, --aperture-shape) or box (the paper's "
                        "2^S boxes)")
            ->check(CLI::IsMember({"aperture", "box"}))
            ->default_val("aperture");
        render
            .add_option("--aperture-grids", args->settings.aperture_grids,
                        "multilayer: taps per axis of the aperture levels built from each box "
                        "level (increasing, each below twice the first; one level per grid and "
                        "octave of blur)")
            ->delimiter(',')
            ->default_str("4,5,6");
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
