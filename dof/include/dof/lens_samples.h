// Lens sample patterns and aperture shapes, shared by every method that samples the lens
// (accum, multiview). Consumes a pattern choice, a count, a seed and an aperture shape (an
// aperture image arrives as plain float data, loaded by the app); produces positions on the
// aperture with weights. LensSampleSet owns its arrays; everything is a pure function of its
// inputs, so the same arguments give the same bits on every run and thread.
//
// Two steps, as in pbrt: a point u in the primary domain [0,1)^2 (Halton, Hammersley or a
// Poisson-disk set), then a shape map from [0,1)^2 onto the aperture that preserves area
// (uniform density for circle and polygon; density proportional to transmission for an image).
// Positions are in lens units: the unit disk for the circle, a polygon inscribed in it, the
// square [-1,1]^2 for an image; +x along View::right, +y along View::up (see lens.h for what
// that means on screen). Multiply by the aperture radius E for world units.
#pragma once

#include <raster/status.h>

#include <glm/vec2.hpp>

#include <cstdint>
#include <vector>

namespace dof {

enum class LensPattern : uint8_t {
    Halton,     // bases 2 and 3, Cranley-Patterson shifted by 1/2 so index 0 is the centre
    Hammersley, // ((i + 1/2)/N, radical inverse base 2 of i + 1/(2N)); stratified for known N
    Poisson,    // best-candidate Poisson-disk set on the torus [0,1)^2 (Mitchell 1991), first
                // point the centre
};

enum class ApertureKind : uint8_t { Circle, Polygon, Image };

// Transmission of an aperture image in [0,inf), row 0 at the top (+y). The image is fitted into
// [-1,1]^2 with its longer side spanning the full width and kept centred.
struct ApertureMask {
    uint32_t width = 0;
    uint32_t height = 0;
    std::vector<float> transmission; // width*height values, row-major, top row first
};

struct ApertureShape {
    ApertureKind kind = ApertureKind::Circle;
    uint32_t blades = 6;       // Polygon: number of blades (>= 3); vertices on the unit circle
    float rotation_deg = 0.0f; // Polygon: counter-clockwise; 0 puts a vertex straight up (+y)
    ApertureMask mask;         // Image
};

// The same aperture bit for bit (kind, blades, rotation and mask), so the same pattern, count
// and seed build the same sample set on both.
bool sameAperture(const ApertureShape& a, const ApertureShape& b);

struct LensSample {
    glm::vec2 position{0.0f}; // lens units (see top)
    float weight = 1.0f;      // the set's weights sum to 1
};

// --- primary-domain building blocks (exposed for tests and other methods) ---

// Van der Corput radical inverse of `index` in `base` (2, 3, 5, 7, ...), in [0,1).
float radicalInverse(uint32_t base, uint64_t index);
// Shirley & Chiu 1997 concentric map of [0,1)^2 onto the unit disk; (1/2,1/2) maps to 0.
glm::vec2 concentricDisk(glm::vec2 u);
// Counter-based hash of up to four words (bit-mixing; no state). Same input, same output.
uint32_t hashWords(uint32_t a, uint32_t b, uint32_t c = 0, uint32_t d = 0);
// A uniform float in [0,1) from a hash value (its top 24 bits).
float hashToUnit(uint32_t h);
// Per-pixel Cranley-Patterson rotation in [0,1)^2: a pure function of (x, y, seed).
glm::vec2 pixelRotation(uint32_t x, uint32_t y, uint32_t seed);
// `count` points of the pattern in [0,1)^2, index order; seed != 0 rotates the whole set by a
// Cranley-Patterson shift and (Poisson) changes its candidates. Allocates the returned vector
// (std::bad_alloc when that fails, as from the vector); LensSampleSet::create is the entry point
// that returns a Status.
std::vector<glm::vec2> primaryPoints(LensPattern pattern, uint32_t count, uint32_t seed);

// Maps [0,1)^2 onto an aperture shape. Immutable after create(); cheap to copy.
class ApertureSampler {
public:
    // Fails on blades < 3, non-finite rotation, an empty mask, or a mask without transmission.
    static raster::Result<ApertureSampler> create(const ApertureShape& shape);
    ApertureSampler() = default;

    // Area-preserving (circle, polygon) or transmission-proportional (image) map.
    glm::vec2 map(glm::vec2 u) const;
    const ApertureShape& shape() const { return shape_; }

private:
    ApertureShape shape_;
    std::vector<glm::vec2> vertices_; // Polygon: blades vertices, counter-clockwise
    std::vector<double> row_cdf_;     // Image: height+1 cumulative row sums
    std::vector<double> col_cdf_;     // Image: height*(width+1) cumulative sums per row
};

// N lens samples of one pattern on one aperture: the set every pixel shares (accum renders one
// view per sample), and the per-pixel decorrelated variant for methods that can use a different
// set per pixel (the rotation is keyed on (pixel, seed); a sample is keyed on (pixel, index,
// seed)).
class LensSampleSet {
public:
    static raster::Result<LensSampleSet> create(const ApertureShape& shape, LensPattern pattern,
                                                uint32_t count, uint32_t seed);

    uint32_t size() const { return uint32_t(samples_.size()); }
    const ApertureShape& shape() const { return sampler_.shape(); }
    LensPattern pattern() const { return pattern_; }
    uint32_t seed() const { return seed_; }
    // The shared sample `index` (< size()).
    const LensSample& sample(uint32_t index) const { return samples_[index]; }
    const std::vector<LensSample>& samples() const { return samples_; }
    // Sample `index` for pixel (x, y): the primary point rotated by pixelRotation(x, y, seed),
    // then mapped onto the aperture.
    LensSample sample(uint32_t x, uint32_t y, uint32_t index) const;

private:
    ApertureSampler sampler_;
    LensPattern pattern_ = LensPattern::Halton;
    uint32_t seed_ = 0;
    std::vector<glm::vec2> primary_;
    std::vector<LensSample> samples_;
};

} // namespace dof
