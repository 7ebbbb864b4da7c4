#include "out_of_memory.h"

#include <dof/aperture_grid.h>

#include <algorithm>
#include <cmath>
#include <new>

namespace dof {

raster::Result<LensSampleSet> apertureGridSamples(const ApertureShape& shape) {
    constexpr uint32_t kSamples = 1u << 16; // the weights' error is ~1/256 of a cell's share
    return LensSampleSet::create(shape, LensPattern::Hammersley, kSamples, 0);
}

raster::Result<ApertureGrid> apertureGrid(const ApertureShape& shape, uint32_t size,
                                          FocalSide side) try {
    raster::Result<LensSampleSet> set = apertureGridSamples(shape);
    if (!set.ok())
        return set.status(); // a copy of its message, which may allocate
    return apertureGrid(*set, shape, size, side);
} catch (const std::bad_alloc&) {
    return detail::outOfMemory("building an aperture grid");
}

raster::Result<ApertureGrid> apertureGrid(const LensSampleSet& samples, const ApertureShape& shape,
                                          uint32_t size, FocalSide side) try {
    if (size == 0 || size > 64)
        return raster::Status::error("aperture grid: the cell count per axis must be in [1, 64]");
    ApertureGrid grid;
    grid.size = size;
    // The mass behind the focal plane, where image offset = R·(-v.x, +v.y) (dof/lens.h).
    std::vector<double> mass(size_t(size) * size, 0.0);
    double total = 0.0, m2 = 0.0;
    const auto cell = [size](double o) {
        const double c = std::floor((o + 1.0) * 0.5 * double(size));
        return uint32_t(std::clamp(c, 0.0, double(size - 1)));
    };
    for (const LensSample& s : samples.samples()) {
        const double ox = -double(s.position.x);
        const double oy = double(s.position.y);
        mass[size_t(cell(oy)) * size + cell(ox)] += double(s.weight);
        total += double(s.weight);
        m2 += double(s.weight) * 0.5 * (ox * ox + oy * oy);
    }
    if (!(total > 0.0))
        return raster::Status::error("aperture grid: the aperture lets no light through");
    // A circle and a polygon with an even blade count are symmetric under a half turn: average
    // each cell with its mirror cell so that the near and far grids are the same bits.
    const bool half_turn_symmetric = shape.kind == ApertureKind::Circle ||
                                     (shape.kind == ApertureKind::Polygon && shape.blades % 2 == 0);
    const size_t cells = mass.size();
    grid.weight.resize(cells);
    for (size_t i = 0; i < cells; ++i) {
        // In front of the focal plane the offset is -R·(-v.x, +v.y): the grid turned by 180°.
        const size_t src = side == FocalSide::Far ? i : cells - 1 - i;
        const double m =
            half_turn_symmetric ? 0.5 * (mass[src] + mass[cells - 1 - src]) : mass[src];
        grid.weight[i] = float(m / total);
    }
    grid.second_moment = m2 / total;
    return grid;
} catch (const std::bad_alloc&) {
    return detail::outOfMemory("building an aperture grid");
}

bool sameWeights(const ApertureGrid& a, const ApertureGrid& b) {
    return a.size == b.size && a.weight == b.weight;
}

} // namespace dof
