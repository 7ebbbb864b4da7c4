// Runs the layered DOF methods on a BuiltinCase the way `focal render` does (a Renderer on a
// 2-thread pool, default render options), for the full-tier tests that compare them with accum.
// Returns linear RGBA owned by the caller.
#pragma once

#include "support/builtin_case.h"

#include <dof/lens_samples.h>
#include <dof/multilayer.h>
#include <dof/multiview.h>
#include <raster/check.h>
#include <raster/renderer.h>

#include <vector>

namespace focal::test {

inline std::vector<float> runMultiview(const BuiltinCase& c, const dof::LensSampleSet& samples,
                                       const dof::MultiviewSettings& s,
                                       raster::Frame* pinhole = nullptr) {
    raster::TaskPool pool(2);
    raster::Renderer renderer(pool);
    raster::RenderOptions options;
    const dof::PinholeFn pin = [&](const raster::View& v, raster::Frame& f, bool depth_only) {
        raster::RenderOptions o = options;
        o.depth_only = depth_only;
        return renderer.render(c.scene, v, o, f);
    };
    const dof::LayersFn lay = [&](const raster::View& v, const raster::LayeredTargetDesc& d,
                                  raster::LayeredTarget& t) {
        return renderer.renderLayers(c.scene, v, options, d, t);
    };
    dof::ShadingInputs shading;
    shading.scene = &c.scene;
    std::vector<float> rgba;
    raster::Result<dof::MultiviewStats> r = dof::renderMultiview(
        c.view, c.lens, samples, s, shading, c.scene.background, pin, lay, pool, rgba, pinhole);
    FOCAL_CHECK(r.ok());
    return rgba;
}

inline std::vector<float> runMultilayer(const BuiltinCase& c, const dof::MultilayerSettings& s) {
    raster::TaskPool pool(2);
    raster::Renderer renderer(pool);
    const dof::CollectFn collect = [&](const raster::FragmentListDesc& desc,
                                       raster::FragmentLists& lists) {
        return renderer.renderFragmentLists(c.scene, c.view, {}, desc, lists);
    };
    dof::Multilayer ml;
    dof::MultilayerImage image;
    const raster::Status status =
        ml.render(c.view, c.lens, c.scene.background, s, collect, pool, image);
    FOCAL_CHECK(status.ok());
    return image.rgba;
}

} // namespace focal::test
