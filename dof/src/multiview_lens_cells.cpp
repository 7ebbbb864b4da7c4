// Multiview's lens cells: the mean nearest-neighbour distance of a lens sample set (the cone
// width lambda, §4.4) and each sample's Voronoi-cell centroid (ConeCentre::Cell). Consumes a
// LensSampleSet; produces plain values and vectors the caller owns, or keeps them in a
// LensCells (multiview_setup.h) from frame to frame.
#include "multiview_setup.h"
#include "out_of_memory.h"

#include <dof/multiview.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <new>
#include <vector>

namespace dof {

namespace {

// The lens samples bucketed on a uniform grid over their bounding box (about one sample per
// cell), for exact nearest-sample queries in O(1) expected time instead of a scan of all N
// (N may be in the millions).
class SampleGrid {
public:
    explicit SampleGrid(const LensSampleSet& samples) : samples_(samples) {
        const uint32_t n = samples.size();
        lo_ = glm::vec2(INFINITY), hi_ = glm::vec2(-INFINITY);
        for (const LensSample& s : samples.samples())
            lo_ = glm::min(lo_, s.position), hi_ = glm::max(hi_, s.position);
        side_ = std::max(1u, uint32_t(std::sqrt(double(n))));
        const glm::vec2 extent = glm::max(hi_ - lo_, glm::vec2(1e-6f));
        cell_ = std::max(extent.x, extent.y) / float(side_);
        start_.assign(size_t(side_) * side_ + 1, 0);
        for (uint32_t i = 0; i < n; ++i)
            ++start_[cellOf(samples.sample(i).position) + 1];
        for (size_t c = 1; c < start_.size(); ++c)
            start_[c] += start_[c - 1];
        index_.resize(n);
        std::vector<uint32_t> fill(start_.begin(), start_.end() - 1);
        for (uint32_t i = 0; i < n; ++i) // in index order: each cell's list is sorted
            index_[fill[cellOf(samples.sample(i).position)]++] = i;
    }

    // The sample nearest to q other than `skip` (by squared distance; ties: the lower index),
    // and its distance as glm::length computes it; n (none) when there is no other sample.
    uint32_t nearest(glm::vec2 q, uint32_t skip, float& distance) const {
        const uint32_t n = samples_.size();
        uint32_t best = n;
        float best_d2 = INFINITY;
        const int64_t cx = axisCell(q.x - lo_.x), cy = axisCell(q.y - lo_.y);
        for (int64_t r = 0; r <= int64_t(side_); ++r) {
            // The ring at Chebyshev distance r: full top and bottom rows, the two side columns.
            for (int64_t y = cy - r; y <= cy + r; ++y) {
                const int64_t step = (y == cy - r || y == cy + r) ? 1 : std::max<int64_t>(2 * r, 1);
                for (int64_t x = cx - r; x <= cx + r; x += step) {
                    if (x < 0 || y < 0 || x >= int64_t(side_) || y >= int64_t(side_))
                        continue;
                    const size_t c = size_t(y) * side_ + size_t(x);
                    for (uint32_t k = start_[c]; k < start_[c + 1]; ++k) {
                        const uint32_t i = index_[k];
                        if (i == skip)
                            continue;
                        const glm::vec2 d = q - samples_.sample(i).position;
                        const float d2 = glm::dot(d, d);
                        if (d2 < best_d2 || (d2 == best_d2 && i < best))
                            best_d2 = d2, best = i;
                    }
                }
            }
            // Every sample not yet seen lies at least r cells from q's cell, so at least
            // r * cell from q (q's own cell is clamped into the grid, which only shortens it).
            if (best < n && std::sqrt(best_d2) < float(r) * cell_ * 0.999f)
                break;
        }
        distance = best < n ? glm::length(q - samples_.sample(best).position) : INFINITY;
        return best;
    }

private:
    int64_t axisCell(float offset) const {
        return std::clamp<int64_t>(int64_t(std::floor(offset / cell_)), 0, int64_t(side_) - 1);
    }
    size_t cellOf(glm::vec2 p) const {
        return size_t(axisCell(p.y - lo_.y)) * side_ + size_t(axisCell(p.x - lo_.x));
    }

    const LensSampleSet& samples_;
    glm::vec2 lo_{0.0f}, hi_{0.0f};
    uint32_t side_ = 1;
    float cell_ = 1.0f;
    std::vector<uint32_t> start_; // side² + 1 prefix sums
    std::vector<uint32_t> index_; // sample indices by cell
};

} // namespace

float meanNeighbourDistance(const LensSampleSet& samples) {
    const uint32_t n = samples.size();
    if (n < 2)
        return 0.0f;
    const SampleGrid grid(samples);
    double sum = 0.0;
    for (uint32_t i = 0; i < n; ++i) {
        float best = INFINITY;
        grid.nearest(samples.sample(i).position, i, best);
        sum += double(best);
    }
    return float(sum / double(n));
}

std::vector<glm::vec2> lensCellOffsets(const LensSampleSet& samples, uint32_t fine_per_sample) {
    const uint32_t n = samples.size();
    const uint64_t wanted = uint64_t(n) * std::max(fine_per_sample, 1u);
    const uint32_t fine_count = uint32_t(std::min<uint64_t>(wanted, 65536));
    // Under 16 points a cell, the centroids are noise (at 64k samples Hammersley's denser set is
    // the set itself); such sets have cones under a pixel wide anyway: keep them on the rays.
    if (n == 0 || uint64_t(fine_count) < 16 * uint64_t(n))
        return {};
    raster::Result<LensSampleSet> fine =
        LensSampleSet::create(samples.shape(), LensPattern::Hammersley, fine_count, 0);
    if (detail::isOutOfMemory(fine.status()))
        throw std::bad_alloc(); // as the vectors below would: not a reason to drop the cells
    if (!fine.ok())
        return {}; // the shape built the main set, so it builds this one too
    std::vector<glm::vec2> offsets(n, glm::vec2(0.0f));
    const SampleGrid grid(samples);
    std::vector<glm::dvec2> sum(n, glm::dvec2(0.0));
    std::vector<double> weight(n, 0.0);
    for (const LensSample& q : fine->samples()) {
        float distance = 0.0f;
        const uint32_t best = grid.nearest(q.position, n, distance);
        sum[best] += double(q.weight) * glm::dvec2(q.position);
        weight[best] += double(q.weight);
    }
    for (uint32_t i = 0; i < n; ++i)
        if (weight[i] > 0.0)
            offsets[i] = glm::vec2(sum[i] / weight[i]) - samples.sample(i).position;
    return offsets;
}

namespace multiview_detail {

void updateLensCells(const LensSampleSet& samples, bool offsets, LensCells& cells) {
    static_assert(sizeof(LensSample) == 3 * sizeof(float), "compared as bytes: no padding");
    const std::vector<LensSample>& s = samples.samples();
    const bool same = cells.valid && cells.key.size() == s.size() &&
                      (s.empty() || std::memcmp(cells.key.data(), s.data(),
                                                s.size() * sizeof(LensSample)) == 0) &&
                      sameAperture(cells.key_shape, samples.shape());
    if (!same) {
        // Invalid until every value is the new set's (an allocation may fail on the way).
        cells.valid = false;
        cells.has_offsets = false;
        cells.lambda = meanNeighbourDistance(samples);
        cells.key = s;
        cells.key_shape = samples.shape();
        cells.valid = true;
    }
    if (offsets && !cells.has_offsets) {
        cells.offsets = lensCellOffsets(samples);
        cells.has_offsets = true;
    }
}

} // namespace multiview_detail

} // namespace dof
