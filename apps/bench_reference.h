// The `accum` reference every bench setting is compared with: rendered once through `focal
// render` and cached on disk under a key of every option that changes its bits, then read back
// with the depth-discontinuity band the band metrics use. Consumes a BenchScene and render
// options; produces a Reference owned by the caller; writes KEY.exr, KEY_depth.exr and KEY.json
// into the cache folder.
#pragma once

#include "apps/bench_scene.h"
#include "apps/image_io.h"
#include "apps/render_command.h"

#include <dof/metrics.h>
#include <raster/status.h>

#include <cstdint>
#include <string>
#include <vector>

namespace focal {

// The band around depth discontinuities (as `focal compare` defaults) and the scale of the
// false-colour difference images.
inline constexpr float kBandThreshold = 0.05f;
inline constexpr float kBandRadius = 4.0f;
inline constexpr float kDiffScale = 0.1f;

struct Reference {
    ImageData color;
    ImageData depth;
    std::vector<uint8_t> band; // 1 inside the discontinuity band of `depth`
    uint64_t band_pixels = 0;
    std::string key; // the cache key (hex)
    double ms = 0.0; // the render's time when it was made
    bool cached = false;
};

// Renders (or loads from `cache_dir`) `accum` with `samples` views for `common` render options
// (the scene spec first). `threads` is not part of the key: the bits do not depend on it
// (docs/architecture.md, "Threads"). `loaded`: the scene, loaded for `common`.
raster::Result<Reference> reference(const BenchScene& scene, const std::vector<std::string>& common,
                                    uint32_t samples, uint32_t threads,
                                    const std::string& cache_dir, const LoadedScene* loaded);

// A view of `img`'s pixels for dof/metrics.h; valid while `img` is.
dof::ImageRef imageRefOf(const ImageData& img);

} // namespace focal
