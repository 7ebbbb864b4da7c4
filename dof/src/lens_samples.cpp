#include "out_of_memory.h"

#include <dof/lens_samples.h>
#include <raster/hash.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <new>
#include <string>

namespace dof {

using raster::Status;

namespace {

constexpr float kPi = 3.14159265358979f;

using raster::hash32;

float fract(float x) {
    return x - std::floor(x);
}

glm::vec2 rotateModOne(glm::vec2 u, glm::vec2 shift) {
    glm::vec2 r(fract(u.x + shift.x), fract(u.y + shift.y));
    // fract can round up to exactly 1 for tiny negative inputs; keep the half-open interval.
    if (r.x >= 1.0f)
        r.x = 0.0f;
    if (r.y >= 1.0f)
        r.y = 0.0f;
    return r;
}

// Squared distance on the unit torus.
float torusDist2(glm::vec2 a, glm::vec2 b) {
    float dx = std::fabs(a.x - b.x), dy = std::fabs(a.y - b.y);
    dx = std::min(dx, 1.0f - dx);
    dy = std::min(dy, 1.0f - dy);
    return dx * dx + dy * dy;
}

// Mitchell's best-candidate algorithm on the torus: each new point is the candidate farthest
// from the points so far. A uniform grid answers nearest-neighbour queries.
std::vector<glm::vec2> poissonPoints(uint32_t count, uint32_t seed) {
    constexpr uint32_t kCandidates = 16;
    std::vector<glm::vec2> points;
    points.reserve(count);
    const int grid = std::max(1, int(std::sqrt(double(count))));
    const float cell = 1.0f / float(grid);
    std::vector<std::vector<uint32_t>> cells(size_t(grid) * size_t(grid));
    auto cellOf = [grid](float v) { return std::min(grid - 1, int(v * float(grid))); };
    auto insert = [&](glm::vec2 p) {
        cells[size_t(cellOf(p.y)) * size_t(grid) + size_t(cellOf(p.x))].push_back(
            uint32_t(points.size()));
        points.push_back(p);
    };
    auto nearest2 = [&](glm::vec2 p) {
        float best = INFINITY;
        const int cx = cellOf(p.x), cy = cellOf(p.y);
        for (int ring = 0; ring <= grid / 2 + 1; ++ring) {
            // Every point in ring r is at least (r - 1) cells away.
            const float reach = float(ring - 1) * cell;
            if (ring > 1 && reach * reach >= best)
                break;
            for (int dy = -ring; dy <= ring; ++dy)
                for (int dx = -ring; dx <= ring; ++dx) {
                    if (std::max(std::abs(dx), std::abs(dy)) != ring)
                        continue;
                    const int gx = ((cx + dx) % grid + grid) % grid;
                    const int gy = ((cy + dy) % grid + grid) % grid;
                    for (uint32_t i : cells[size_t(gy) * size_t(grid) + size_t(gx)])
                        best = std::min(best, torusDist2(p, points[i]));
                }
        }
        return best;
    };
    if (count == 0)
        return points;
    insert({0.5f, 0.5f});
    for (uint32_t i = 1; i < count; ++i) {
        glm::vec2 best_p(0.0f);
        float best_d = -1.0f;
        for (uint32_t c = 0; c < kCandidates; ++c) {
            const glm::vec2 p(hashToUnit(hashWords(i, c, seed, 0x9e3779b9u)),
                              hashToUnit(hashWords(i, c, seed, 0x7f4a7c15u)));
            const float d = nearest2(p);
            if (d > best_d) {
                best_d = d;
                best_p = p;
            }
        }
        insert(best_p);
    }
    return points;
}

// Index of the interval [cdf[k], cdf[k+1]) holding x, for cdf[0] = 0 <= x < cdf[n]; skips
// empty intervals.
size_t findInterval(const double* cdf, size_t n, double x) {
    const double* it = std::upper_bound(cdf, cdf + n + 1, x);
    size_t k = size_t(it - cdf);
    k = k == 0 ? 0 : k - 1;
    k = std::min(k, n - 1);
    while (k > 0 && cdf[k + 1] <= cdf[k])
        --k; // only when x == cdf[n]: step back to the last non-empty interval
    return k;
}

} // namespace

float radicalInverse(uint32_t base, uint64_t index) {
    // Digits accumulated in double, then rounded once: exact for base 2 up to 2^53.
    const double inv_base = 1.0 / double(base);
    double inv = inv_base, result = 0.0;
    while (index > 0) {
        result += double(index % base) * inv;
        index /= base;
        inv *= inv_base;
    }
    const float r = float(result);
    return r < 1.0f ? r : 0x1.fffffep-1f;
}

namespace {

// Shirley & Chiu 1997, "A low distortion map between disk and square", in the polar form of
// Shirley's 2011 note (one branch per pair of wedges): a signed radius r (0 only at the centre)
// and an angle phi.
struct ConcentricPolar {
    float r = 0.0f;
    float phi = 0.0f;
};

ConcentricPolar concentricPolar(glm::vec2 u) {
    const float a = 2.0f * u.x - 1.0f, b = 2.0f * u.y - 1.0f;
    if (a == 0.0f && b == 0.0f)
        return {};
    if (std::fabs(a) > std::fabs(b))
        return {a, (kPi / 4.0f) * (b / a)};
    return {b, kPi / 2.0f - (kPi / 4.0f) * (a / b)};
}

} // namespace

glm::vec2 concentricDisk(glm::vec2 u) {
    const ConcentricPolar p = concentricPolar(u);
    if (p.r == 0.0f)
        return {0.0f, 0.0f};
    return {p.r * std::cos(p.phi), p.r * std::sin(p.phi)};
}

uint32_t hashWords(uint32_t a, uint32_t b, uint32_t c, uint32_t d) {
    uint32_t h = hash32(a + 0x9e3779b9u);
    h = hash32(h ^ (b + 0x85ebca6bu));
    h = hash32(h ^ (c + 0xc2b2ae35u));
    return hash32(h ^ (d + 0x27d4eb2fu));
}

float hashToUnit(uint32_t h) {
    return float(h >> 8) * 0x1.0p-24f;
}

glm::vec2 pixelRotation(uint32_t x, uint32_t y, uint32_t seed) {
    return {hashToUnit(hashWords(x, y, seed, 1u)), hashToUnit(hashWords(x, y, seed, 2u))};
}

std::vector<glm::vec2> primaryPoints(LensPattern pattern, uint32_t count, uint32_t seed) {
    std::vector<glm::vec2> points;
    if (pattern == LensPattern::Poisson) {
        points = poissonPoints(count, seed);
    } else {
        points.resize(count);
        for (uint32_t i = 0; i < count; ++i) {
            if (pattern == LensPattern::Halton)
                points[i] = {fract(radicalInverse(2, i) + 0.5f),
                             fract(radicalInverse(3, i) + 0.5f)};
            else
                points[i] = {(float(i) + 0.5f) / float(count),
                             fract(radicalInverse(2, i) + 0.5f / float(count))};
        }
    }
    if (seed != 0) {
        const glm::vec2 shift(hashToUnit(hashWords(seed, 3u)), hashToUnit(hashWords(seed, 4u)));
        for (glm::vec2& p : points)
            p = rotateModOne(p, shift);
    }
    return points;
}

bool sameAperture(const ApertureShape& a, const ApertureShape& b) {
    const auto sameBytes = [](const void* x, const void* y, size_t bytes) {
        return bytes == 0 || std::memcmp(x, y, bytes) == 0;
    };
    return a.kind == b.kind && a.blades == b.blades &&
           sameBytes(&a.rotation_deg, &b.rotation_deg, sizeof(float)) &&
           a.mask.width == b.mask.width && a.mask.height == b.mask.height &&
           a.mask.transmission.size() == b.mask.transmission.size() &&
           sameBytes(a.mask.transmission.data(), b.mask.transmission.data(),
                     a.mask.transmission.size() * sizeof(float));
}

raster::Result<ApertureSampler> ApertureSampler::create(const ApertureShape& shape) try {
    ApertureSampler s;
    s.shape_ = shape;
    if (shape.kind == ApertureKind::Polygon) {
        if (shape.blades < 3 || shape.blades > 64)
            return Status::error("aperture shape: blades must be in [3, 64], got " +
                                 std::to_string(shape.blades));
        if (!std::isfinite(shape.rotation_deg))
            return Status::error("aperture shape: rotation_deg must be a finite angle in degrees");
        const double rot = double(shape.rotation_deg) * 3.14159265358979323846 / 180.0;
        for (uint32_t k = 0; k < shape.blades; ++k) {
            const double a = rot + 3.14159265358979323846 / 2.0 +
                             2.0 * 3.14159265358979323846 * double(k) / double(shape.blades);
            s.vertices_.push_back({float(std::cos(a)), float(std::sin(a))});
        }
    } else if (shape.kind == ApertureKind::Image) {
        const ApertureMask& m = shape.mask;
        if (m.width == 0 || m.height == 0 || m.transmission.size() != size_t(m.width) * m.height)
            return Status::error("aperture image is empty or does not match its size");
        s.row_cdf_.assign(size_t(m.height) + 1, 0.0);
        s.col_cdf_.assign(size_t(m.height) * (m.width + 1), 0.0);
        for (uint32_t y = 0; y < m.height; ++y) {
            double* row = &s.col_cdf_[size_t(y) * (m.width + 1)];
            for (uint32_t x = 0; x < m.width; ++x) {
                const float t = m.transmission[size_t(y) * m.width + x];
                if (!std::isfinite(t) || t < 0.0f)
                    return Status::error("aperture image has a negative or non-finite value at "
                                         "pixel " +
                                         std::to_string(x) + "," + std::to_string(y));
                row[x + 1] = row[x] + double(t);
            }
            s.row_cdf_[y + 1] = s.row_cdf_[y] + row[m.width];
        }
        if (!(s.row_cdf_[m.height] > 0.0))
            return Status::error("aperture image transmits no light (every pixel is 0)");
    }
    return s;
} catch (const std::bad_alloc&) {
    return detail::outOfMemory("building the aperture sampler");
}

glm::vec2 ApertureSampler::map(glm::vec2 u) const {
    switch (shape_.kind) {
    case ApertureKind::Circle:
        return concentricDisk(u);
    case ApertureKind::Polygon: {
        // Concentric radius r (P(r < R) = R^2) and the ring position s in [0,1) (uniform for a
        // given r). The fan of `blades` triangles from the centre has equal areas, so s picks a
        // triangle and a point along its outer edge linearly; scaling by r keeps area uniform.
        const ConcentricPolar polar = concentricPolar(u);
        if (polar.r == 0.0f)
            return {0.0f, 0.0f};
        float r = polar.r, phi = polar.phi;
        if (r < 0.0f) {
            r = -r;
            phi += kPi;
        }
        // phi in [-pi/4, 7pi/4): s is the fraction of the way round, starting at vertex 0.
        const float vertex0 = std::atan2(vertices_[0].y, vertices_[0].x);
        float s = (phi - vertex0) / (2.0f * kPi);
        s = fract(s);
        const uint32_t n = uint32_t(vertices_.size());
        const float sn = s * float(n);
        const uint32_t k = std::min(n - 1, uint32_t(sn));
        const float t = sn - float(k);
        const glm::vec2 va = vertices_[k], vb = vertices_[(k + 1) % n];
        return r * ((1.0f - t) * va + t * vb);
    }
    case ApertureKind::Image: {
        const ApertureMask& m = shape_.mask;
        // Marginal over rows, then the row's conditional over columns; the remainder of each
        // search places the point inside the texel, so the density is piecewise constant.
        const double total = row_cdf_[m.height];
        const double yv = double(u.y) * total;
        const size_t row = findInterval(row_cdf_.data(), m.height, yv);
        const double row_w = row_cdf_[row + 1] - row_cdf_[row];
        const double fy = std::clamp((yv - row_cdf_[row]) / row_w, 0.0, 1.0);
        const double* cols = &col_cdf_[row * (m.width + 1)];
        const double xv = double(u.x) * cols[m.width];
        const size_t col = findInterval(cols, m.width, xv);
        const double col_w = cols[col + 1] - cols[col];
        const double fx = std::clamp((xv - cols[col]) / col_w, 0.0, 1.0);
        const double side = double(std::max(m.width, m.height));
        const double x = (-double(m.width) + 2.0 * (double(col) + fx)) / side;
        const double y = (double(m.height) - 2.0 * (double(row) + fy)) / side;
        return {float(x), float(y)};
    }
    }
    return {0.0f, 0.0f};
}

raster::Result<LensSampleSet> LensSampleSet::create(const ApertureShape& shape, LensPattern pattern,
                                                    uint32_t count, uint32_t seed) try {
    if (count == 0)
        return Status::error("lens samples: count must be at least 1");
    raster::Result<ApertureSampler> sampler = ApertureSampler::create(shape);
    if (!sampler.ok())
        return sampler.status();
    LensSampleSet set;
    set.sampler_ = std::move(*sampler);
    set.pattern_ = pattern;
    set.seed_ = seed;
    set.primary_ = primaryPoints(pattern, count, seed);
    set.samples_.resize(count);
    // Importance-sampled shapes: every sample carries the same weight.
    const float w = 1.0f / float(count);
    for (uint32_t i = 0; i < count; ++i)
        set.samples_[i] = {set.sampler_.map(set.primary_[i]), w};
    return set;
} catch (const std::bad_alloc&) {
    return detail::outOfMemory("building the lens samples");
}

LensSample LensSampleSet::sample(uint32_t x, uint32_t y, uint32_t index) const {
    const glm::vec2 u = rotateModOne(primary_[index], pixelRotation(x, y, seed_));
    return {sampler_.map(u), samples_[index].weight};
}

} // namespace dof
