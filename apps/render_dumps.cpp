#include "apps/render_dumps.h"

#include "apps/target_dumps.h"

#include <dof/layer_spacing.h>

#include <algorithm>

namespace focal {

using raster::Status;

namespace {

Status dumpLayersOf(raster::Renderer& renderer, const raster::Frame& pinhole,
                    const raster::Scene& scene, const raster::View& view,
                    const raster::RenderOptions& options, const RenderArgs& args,
                    const TargetStorage& targets, nlohmann::json& out) {
    const dof::DepthRange range = dof::visibleDepthRange(pinhole, view);
    if (!range.covered)
        return Status::error(args.scene + ": nothing visible to decompose into layers");
    raster::LayeredTargetDesc desc;
    desc.bounds = uniformInverseDepthBounds(
        range.near_d, std::max(range.far_d, range.near_d * 1.001f), args.dump_layer_count);
    desc.color_format = targets.color.value_or(raster::ColorFormat::Float32);
    desc.depth_format = targets.depth.value_or(raster::DepthFormat::Float32);
    raster::LayeredTarget layers;
    raster::FrameStats ts;
    if (Status s = renderer.renderLayers(scene, view, options, desc, layers, &ts); !s.ok())
        return s;
    if (Status s = dumpLayers(layers, view, args.dump_layers); !s.ok())
        return s;
    out["layers"] = {{"count", layers.layer_count},
                     {"bounds", desc.bounds},
                     {"bytes", ts.target_bytes},
                     {"time_ms", {{"raster", ts.ms_raster}, {"copy", ts.ms_resolve}}}};
    return {};
}

Status dumpFragmentsOf(raster::Renderer& renderer, const raster::Scene& scene,
                       const raster::View& view, const raster::RenderOptions& options,
                       const RenderArgs& args, const TargetStorage& targets, nlohmann::json& out) {
    raster::FragmentListDesc desc;
    desc.max_per_pixel = std::max(desc.max_per_pixel, args.dump_fragment_layers);
    desc.early_reject = false; // look inside: every fragment, the full list lengths
    desc.color_format = targets.color.value_or(desc.color_format);
    desc.depth_format = targets.depth.value_or(desc.depth_format);
    raster::FragmentLists lists;
    raster::FrameStats ts;
    if (Status s = renderer.renderFragmentLists(scene, view, options, desc, lists, &ts); !s.ok())
        return s;
    if (Status s = dumpFragments(lists, view, args.dump_fragments, args.dump_fragment_layers);
        !s.ok())
        return s;
    out["fragment_lists"] = {{"collected", lists.fragments_collected},
                             {"kept", lists.fragments_kept},
                             {"max_list_length", lists.max_list_length},
                             {"bytes", ts.target_bytes},
                             {"time_ms", {{"collect", ts.ms_raster}, {"resolve", ts.ms_resolve}}}};
    return {};
}

} // namespace

raster::Result<nlohmann::json> dumpTargets(dof::FrameRenderer& frames, const raster::Scene& scene,
                                           const raster::View& view,
                                           const raster::RenderOptions& options,
                                           const RenderArgs& args, const TargetStorage& targets) {
    nlohmann::json out;
    if (args.dump_layers.empty() && args.dump_fragments.empty())
        return out;
    // The last frame's pinhole when it is this view's, else a new render.
    raster::Frame rendered;
    const raster::Frame* pinhole = frames.lastPinhole(scene, view, options);
    if (!pinhole) {
        if (Status s = frames.renderer().render(scene, view, options, rendered); !s.ok())
            return s;
        pinhole = &rendered;
    }
    if (!args.dump_layers.empty())
        if (Status s =
                dumpLayersOf(frames.renderer(), *pinhole, scene, view, options, args, targets, out);
            !s.ok())
            return s;
    if (!args.dump_fragments.empty())
        if (Status s = dumpFragmentsOf(frames.renderer(), scene, view, options, args, targets, out);
            !s.ok())
            return s;
    return out;
}

} // namespace focal
