// `focal render --dump-layers DIR` and `--dump-fragments DIR`: renders the view's layered
// decomposition (layers uniform in 1/d over the visible depth range, with Lee et al. 2009's
// routing) and its fragment lists (the closest K kept), and writes them as images
// (apps/target_dumps.h). Consumes the frame renderer (its last pinhole frame when it is this
// view's), scene, view and options; produces the stats' "targets" entry, owned by the caller.
#pragma once

#include "apps/render_command.h"
#include "apps/render_request.h"

#include <dof/frame_renderer.h>
#include <raster/status.h>

#include <nlohmann/json.hpp>

namespace focal {

raster::Result<nlohmann::json> dumpTargets(dof::FrameRenderer& frames, const raster::Scene& scene,
                                           const raster::View& view,
                                           const raster::RenderOptions& options,
                                           const RenderArgs& args, const TargetStorage& targets);

} // namespace focal
