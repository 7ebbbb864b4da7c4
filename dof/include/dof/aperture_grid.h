// The aperture drawn on a G x G grid of image cells: how much of the lens's light a gather
// filter of the circle of confusion takes from each cell. Consumes an aperture shape (shared
// with accum and multiview, dof/lens_samples.h) and the side of the focal plane; produces plain
// weights owned by the caller. multilayer builds its aperture-shaped levels from it
// (dof/fragment_levels.h), so its bokeh has the aperture's shape instead of the box's.
//
// Geometry (dof/lens.h): the lens ray through pixel p from lens point v meets depth d where the
// pinhole image shows p + C(d)·(-v.x, +v.y). A gather of radius R = |C| therefore reads image
// offset R·(-v.x, +v.y) behind the focal plane (C > 0) and R·(+v.x, -v.y) in front of it. Cell
// (a, b) covers the offsets [-R + a·2R/G, -R + (a+1)·2R/G] in x (right) and the same in y
// (down), i.e. the lens square [-1,1]^2 cut into G x G cells in that orientation.
#pragma once

#include <dof/lens_samples.h>
#include <raster/status.h>

#include <cstdint>
#include <vector>

namespace dof {

// The side of the focal plane. The bokeh there (what a point light looks like) is the aperture
// turned by 180 degrees in front of it and upright behind it (dof/lens.h); a gather grid is the
// bokeh turned by 180 degrees.
enum class FocalSide : uint8_t {
    Near, // in front of the focal plane, C < 0
    Far,  // behind it, C > 0
};

struct ApertureGrid {
    uint32_t size = 0;          // G cells per axis
    std::vector<float> weight;  // G*G, row b (image y, down) major; sums to 1
    double second_moment = 0.0; // per-axis second moment of the aperture, lens units² (1/4:
                                // the uniform disk), from the same samples

    float at(uint32_t a, uint32_t b) const { return weight[size_t(b) * size + a]; }
};

// The share of the aperture's transmission in each cell, estimated from 2^16 Hammersley lens
// samples of `shape` (a pure function of its arguments). Fails on an invalid shape or size 0.
raster::Result<ApertureGrid> apertureGrid(const ApertureShape& shape, uint32_t size,
                                          FocalSide side);

// The same from samples made once by apertureGridSamples(shape), for several grids of one shape.
raster::Result<LensSampleSet> apertureGridSamples(const ApertureShape& shape);
raster::Result<ApertureGrid> apertureGrid(const LensSampleSet& samples, const ApertureShape& shape,
                                          uint32_t size, FocalSide side);

// True when the two grids hold the same weights (an aperture symmetric under a half turn).
bool sameWeights(const ApertureGrid& a, const ApertureGrid& b);

} // namespace dof
