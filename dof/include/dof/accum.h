// `accum`: the accumulation-buffer reference (Haeberli & Akeley 1990; Lee et al. 2009 Sec. 3,
// Zhou et al. 2007 Sec. 3.2, Selgrad et al. 2015 Sec. 2). Consumes a view, a thin lens, a lens
// sample set and a render callback; produces a Frame whose colour is the weighted mean of one
// pinhole render per lens sample (sheared frusta that keep the focal plane's pixels fixed),
// and whose depth is the pinhole depth. The caller owns the output frame; scratch is internal.
//
// Determinism: views are rendered and added one after another in sample order into a double
// accumulator, so the bytes do not depend on the thread count or tile size (the render callback
// must itself be deterministic, as raster::Renderer is).
#pragma once

#include <dof/lens.h>
#include <dof/lens_samples.h>
#include <dof/settings_table.h>
#include <raster/camera.h>
#include <raster/frame.h>
#include <raster/status.h>
#include <raster/task_pool.h>

#include <glm/vec2.hpp>

#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

namespace dof {

// Renders the scene through `view` into the frame (resizing it). Must be deterministic.
using RenderFn = std::function<raster::Status(const raster::View&, raster::Frame&)>;
// Called after each view with (views done, views total); may be empty.
using ProgressFn = std::function<void(uint32_t, uint32_t)>;

// One lens view's sample of a probed pixel (AccumSettings::probes): what the view rendered
// there and how it enters the mean (Haeberli & Akeley 1990; Lee et al. 2009 §3).
struct AccumViewSample {
    glm::vec2 lens{0};        // the lens sample (lens units): the eye at eye + E (x right + y up)
    glm::vec2 pixel_shift{0}; // the view's sub-pixel shift (pixelJitter; 0 without pixel_jitter)
    float weight = 0.0f;      // the sample's weight in the mean
    float rgba[4] = {};       // the view's linear colour at the pixel
    float depth = 0.0f;       // the view's stored depth D there (camera.h; kFarDepth: empty)
};

// A probed pixel of the frame: its views in sample (accumulation) order and the result.
struct AccumPixelProbe {
    uint32_t x = 0, y = 0;
    // One per lens view, in the order they were added; empty when the frame was skipped
    // (AccumStats::skipped: the pixel is the pinhole's).
    std::vector<AccumViewSample> views;
    // The accumulated result, bit-equal to the frame's: sum_i double(weight_i) double(rgba_i) in
    // view order, times 1 / sum_i double(weight_i), rounded to float.
    float rgba[4] = {};
};

struct AccumSettings {
    // Also jitter the sub-pixel position per view (View::pixel_shift, Halton bases 5 and 7,
    // centred): a box filter over each pixel. Off: pixels are point-sampled at their centres.
    bool pixel_jitter = false;
    // Probing (not in accumParams; the caller's memory): when `probes` is set, renderAccum fills
    // it with one AccumPixelProbe per pixel of `probe_pixels`, in that order, recording each
    // view's sample as the view is added (no effect on the image). A pixel outside the image
    // fails the call before anything is rendered. Null: nothing recorded or allocated.
    std::span<const glm::uvec2> probe_pixels;
    std::vector<AccumPixelProbe>* probes = nullptr;
};

// The parameters of AccumSettings (settings_table.h).
std::span<const Param<AccumSettings>> accumParams();

struct AccumStats {
    uint32_t views = 0;   // lens views averaged (0 when skipped)
    uint32_t renders = 0; // renderer calls, including the pinhole
    bool skipped = false; // the lens cannot change the image: the pinhole render is the result
    std::string skip_reason;
    CocRange coc; // over the pinhole's visible depths
    double ms_pinhole = 0.0;
    double ms_views = 0.0;      // rendering the lens views
    double ms_accumulate = 0.0; // adding them up and normalising
};

// Buffers kept from frame to frame by a caller that renders again (dof::FrameRenderer keeps
// one): the running sums and the frame each lens view renders into. Sized by renderAccum.
struct AccumScratch {
    std::vector<double> sums; // RGBA per pixel
    raster::Frame view;
    // After each view is added (when progress is called): the frame it was read from (`view`,
    // or the output frame holding the pinhole when the view is the lens centre without shift)
    // and the sum of the weights added so far; sums / weight_sum is the running average.
    const raster::Frame* last_view = nullptr;
    double weight_sum = 0.0;
};

// The sheared view for lens sample `sample` (lens units) and sub-pixel shift `pixel_shift`.
raster::View lensView(const raster::View& view, const ThinLens& lens, glm::vec2 sample,
                      glm::vec2 pixel_shift);

// Sub-pixel shift of view `index` in pixels, in [-1/2, 1/2)^2; index 0 is (0, 0).
glm::vec2 pixelJitter(uint32_t index);

// Renders the accumulation reference into `out`. First renders the pinhole (lens centre) view;
// when E = 0 or every visible depth has |C(d)| < 0.5 px and pixel jitter is off, that is the
// result (stats.skipped). Otherwise renders one view per sample and averages them with the
// samples' weights in linear light. `pool` (may be null) parallelises the accumulation over
// rows. `scratch` (may be null: local buffers) keeps the buffers for the next call. Fails if
// the lens is invalid or a render fails.
raster::Result<AccumStats> renderAccum(const raster::View& view, const ThinLens& lens,
                                       const LensSampleSet& samples, const AccumSettings& settings,
                                       const RenderFn& render, raster::Frame& out,
                                       raster::TaskPool* pool = nullptr,
                                       const ProgressFn& progress = {},
                                       AccumScratch* scratch = nullptr);

} // namespace dof
