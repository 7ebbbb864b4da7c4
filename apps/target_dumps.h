// `--dump-layers DIR` and `--dump-fragments DIR`: write what the GPU-emulating targets hold as
// images, for looking inside (docs/targets.md). Consumes a LayeredTarget or FragmentLists plus
// the View they were rendered with; writes files into a folder (created when missing).
#pragma once

#include <raster/camera.h>
#include <raster/fragment_lists.h>
#include <raster/layered_target.h>
#include <raster/status.h>

#include <cstdint>
#include <string>
#include <vector>

namespace focal {

// M layer bounds between the visible depth range [d_near, d_far], uniform in 1/d (uniform in
// circle of confusion, as Lee et al. 2009 Eq. 4 spaces them).
std::vector<float> uniformInverseDepthBounds(float d_near, float d_far, uint32_t layers);

// Per layer l: layer_LL_color.png (sRGB, alpha = coverage), layer_LL_depth.exr (linear distance
// along the view axis; 0 where empty); plus layers.json with the bounds and overlapped intervals.
raster::Status dumpLayers(const raster::LayeredTarget& layers, const raster::View& view,
                          const std::string& dir);

// fragment_count.png (false-colour heat map of the per-pixel list length before the cap),
// fragment_count.exr (the counts), and for k < first_k: fragment_KK_color.png (sRGB, alpha =
// opacity) and fragment_KK_depth.exr (linear distance; 0 where the list is shorter).
raster::Status dumpFragments(const raster::FragmentLists& lists, const raster::View& view,
                             const std::string& dir, uint32_t first_k);

} // namespace focal
