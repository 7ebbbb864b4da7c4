// `focal bench`'s temporal-stability study on one scene: K frames of a focus pull (d_f from
// 0.85x to 1.15x) with the eye moving sideways by 2% of the focus distance in total, each method
// at its study setting against accum references of the same frames. Flicker of a sequence = mean
// over frame pairs of the mean |I_k - I_k-1| (linear RGB); the excess flicker compares each
// method's frame differences with the reference's. Consumes the bench's arguments and scene;
// produces one JSON row per method (caller-owned); renders in memory, with the scene loaded
// once, and writes its references into the cache.
#pragma once

#include "apps/bench_command.h"
#include "apps/bench_rows.h"
#include "apps/bench_scene.h"

#include <raster/status.h>

#include <string>

namespace focal {

raster::Result<Json> temporalStudy(const BenchArgs& args, const BenchScene& scene,
                                   const std::string& cache_dir);

} // namespace focal
