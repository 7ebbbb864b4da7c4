// Helpers for the dof tests: accum renders through a real raster::Renderer, and image moments.
#pragma once

#include "support/test_util.h"

#include <dof/accum.h>
#include <dof/lens.h>
#include <dof/lens_samples.h>
#include <dof/multiview.h>
#include <raster/check.h>
#include <raster/renderer.h>
#include <raster/task_pool.h>

#include <glm/vec2.hpp>

#include <algorithm>
#include <cmath>

namespace focal::test {

// Multiview's render callbacks through a real renderer; the renderer, scene and options must
// outlive them.
inline dof::PinholeFn pinholeFnOf(raster::Renderer& renderer, const raster::Scene& scene,
                                  const raster::RenderOptions& options) {
    return [&renderer, &scene, &options](const raster::View& v, raster::Frame& f, bool depth_only) {
        raster::RenderOptions o = options;
        o.depth_only = depth_only;
        return renderer.render(scene, v, o, f);
    };
}

inline dof::LayersFn layersFnOf(raster::Renderer& renderer, const raster::Scene& scene,
                                const raster::RenderOptions& options) {
    return [&renderer, &scene, &options](const raster::View& v, const raster::LayeredTargetDesc& d,
                                         raster::LayeredTarget& t) {
        return renderer.renderLayers(scene, v, options, d, t);
    };
}

inline raster::Frame renderAccum(const raster::Scene& scene, const raster::View& view,
                                 const dof::ThinLens& lens, const dof::LensSampleSet& samples,
                                 dof::AccumSettings settings = {}, uint32_t threads = 0,
                                 const raster::RenderOptions& options = {},
                                 dof::AccumStats* stats_out = nullptr) {
    raster::TaskPool pool(threads);
    raster::Renderer renderer(pool);
    raster::Frame frame;
    const dof::RenderFn fn = [&](const raster::View& v, raster::Frame& f) {
        return renderer.render(scene, v, options, f);
    };
    raster::Result<dof::AccumStats> r =
        dof::renderAccum(view, lens, samples, settings, fn, frame, &pool);
    FOCAL_CHECK(r.ok());
    if (stats_out)
        *stats_out = *r;
    return frame;
}

inline dof::LensSampleSet makeSamples(uint32_t n, dof::ApertureShape shape = {},
                                      dof::LensPattern pattern = dof::LensPattern::Hammersley,
                                      uint32_t seed = 0) {
    raster::Result<dof::LensSampleSet> set = dof::LensSampleSet::create(shape, pattern, n, seed);
    FOCAL_CHECK(set.ok());
    return std::move(*set);
}

// An axis-aligned quad facing the camera at depth d (world rectangle [x0,x1]x[y0,y1], z = -d).
inline void addQuad(raster::Scene& scene, float x0, float y0, float x1, float y1, float d,
                    int32_t material) {
    addMesh(scene, {{x0, y0, -d}, {x1, y0, -d}, {x1, y1, -d}, {x0, y1, -d}}, {0, 1, 2, 0, 2, 3},
            material);
}

// Intensity-weighted centroid (pixel centres) and second moment about `centre` of channel 0.
struct Moments {
    double weight = 0.0;
    glm::dvec2 centroid{0.0};
    double mean_r2 = 0.0; // about `centre`
    double max_r = 0.0;   // farthest pixel centre with value > threshold
};

inline Moments momentsOf(const raster::Frame& f, glm::dvec2 centre, float threshold = 1e-6f) {
    Moments m;
    glm::dvec2 sum(0.0);
    double r2 = 0.0;
    for (uint32_t y = 0; y < f.height; ++y)
        for (uint32_t x = 0; x < f.width; ++x) {
            const double v = double(f.color[(size_t(y) * f.width + x) * 4]);
            if (v <= double(threshold))
                continue;
            const glm::dvec2 p(double(x) + 0.5, double(y) + 0.5);
            m.weight += v;
            sum += v * p;
            const glm::dvec2 d = p - centre;
            r2 += v * (d.x * d.x + d.y * d.y);
            m.max_r = std::max(m.max_r, std::sqrt(d.x * d.x + d.y * d.y));
        }
    if (m.weight > 0.0) {
        m.centroid = sum / m.weight;
        m.mean_r2 = r2 / m.weight;
    }
    return m;
}

} // namespace focal::test
