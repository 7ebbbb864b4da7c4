#include "out_of_memory.h"

#include <dof/accum.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <new>
#include <string>
#include <vector>

namespace dof {

using raster::Status;

namespace {

double msSince(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// The index of the pixel's RGBA in a frame's colour.
size_t colorIndex(const raster::Frame& f, glm::uvec2 p) {
    return (size_t(p.y) * f.width + p.x) * 4;
}

// Copies frame f's colour at each probed pixel into the probes' results.
void probeResults(const raster::Frame& f, std::vector<AccumPixelProbe>& probes) {
    for (AccumPixelProbe& probe : probes)
        std::copy_n(f.color.data() + colorIndex(f, {probe.x, probe.y}), 4, probe.rgba);
}

} // namespace

raster::View lensView(const raster::View& view, const ThinLens& lens, glm::vec2 sample,
                      glm::vec2 pixel_shift) {
    // Haeberli & Akeley 1990: move the eye to the lens point eye + E (v.x right + v.y up) and
    // shear the frustum so the plane d = d_f keeps its pixels (raster::projectionMatrix).
    raster::View v = view;
    v.lens_offset = lens.aperture_radius * sample;
    v.focus_distance = lens.focus_distance;
    v.pixel_shift = pixel_shift;
    return v;
}

glm::vec2 pixelJitter(uint32_t index) {
    auto centred = [](float r) {
        const float s = r + 0.5f;
        return (s >= 1.0f ? s - 1.0f : s) - 0.5f;
    };
    return {centred(radicalInverse(5, index)), centred(radicalInverse(7, index))};
}

raster::Result<AccumStats> renderAccum(const raster::View& view, const ThinLens& lens,
                                       const LensSampleSet& samples, const AccumSettings& settings,
                                       const RenderFn& render, raster::Frame& out,
                                       raster::TaskPool* pool, const ProgressFn& progress,
                                       AccumScratch* kept) try {
    if (Status s = validate(lens, view); !s.ok())
        return s;
    if (samples.size() == 0)
        return Status::error("accum: the lens sample set is empty");
    if (kept)
        kept->last_view = nullptr; // no view added yet in this frame
    std::vector<AccumPixelProbe>* probes = settings.probes;
    if (probes) {
        probes->assign(settings.probe_pixels.size(), AccumPixelProbe{});
        for (size_t i = 0; i < probes->size(); ++i) {
            const glm::uvec2 p = settings.probe_pixels[i];
            if (p.x >= view.width || p.y >= view.height)
                return Status::error("accum: probe pixel (" + std::to_string(p.x) + ", " +
                                     std::to_string(p.y) + ") lies outside the " +
                                     std::to_string(view.width) + "x" +
                                     std::to_string(view.height) + " image");
            (*probes)[i].x = p.x, (*probes)[i].y = p.y;
            (*probes)[i].views.reserve(samples.size());
        }
    }
    AccumStats stats;
    using Clock = std::chrono::steady_clock;

    // Pinhole view (lens centre): the output depth, the visible CoC range, and the result
    // whenever the lens cannot change the image.
    auto t0 = Clock::now();
    const raster::View pinhole = lensView(view, lens, {0.0f, 0.0f}, {0.0f, 0.0f});
    if (Status s = render(pinhole, out); !s.ok())
        return s;
    stats.renders = 1;
    stats.ms_pinhole = msSince(t0);
    stats.coc = visibleCocRange(lens, out, view);
    if (!settings.pixel_jitter) {
        char buf[160];
        if (lens.aperture_radius == 0.0f) {
            stats.skipped = true;
            stats.skip_reason = "aperture radius is 0 (pinhole)";
        } else if (stats.coc.max_abs_px < 0.5f) {
            stats.skipped = true;
            std::snprintf(buf, sizeof buf, "every visible depth has |C(d)| < 0.5 px (max %.3f px)",
                          double(stats.coc.max_abs_px));
            stats.skip_reason = buf;
        }
        if (stats.skipped) {
            if (probes)
                probeResults(out, *probes);
            if (progress)
                progress(1, 1);
            return stats;
        }
    }

    // One view per lens sample, added in sample order (the determinism contract).
    const uint32_t width = out.width, height = out.height;
    const size_t floats = size_t(width) * height * 4;
    AccumScratch local;
    AccumScratch& buffers = kept ? *kept : local;
    // Not cleared: the first view's rows store 0 + w·c (what adding to a cleared sum gives),
    // so no frame-sized serial pass runs on the caller's thread (raster.md §6).
    buffers.sums.resize(floats);
    double* acc = buffers.sums.data();
    raster::Frame& scratch = buffers.view;
    double& weight_sum = buffers.weight_sum;
    weight_sum = 0.0;
    const uint32_t n = samples.size(); // >= 1 (checked above): view 0 writes every sum
    // fn(begin, end) over the sums' floats of each image row, on the pool when there is one.
    auto forRows = [&](auto&& fn) {
        auto row = [&](uint32_t y, uint32_t) {
            const size_t begin = size_t(y) * width * 4;
            fn(begin, begin + size_t(width) * 4);
        };
        if (pool)
            pool->parallelFor(height, row);
        else
            for (uint32_t y = 0; y < height; ++y)
                row(y, 0);
    };
    for (uint32_t i = 0; i < n; ++i) {
        const LensSample& ls = samples.sample(i);
        const glm::vec2 shift = settings.pixel_jitter ? pixelJitter(i) : glm::vec2(0.0f);
        const raster::View v = lensView(view, lens, ls.position, shift);
        const raster::Frame* src = &out; // the lens centre without shift is the pinhole
        if (v.lens_offset != glm::vec2(0.0f) || shift != glm::vec2(0.0f)) {
            t0 = Clock::now();
            if (Status s = render(v, scratch); !s.ok())
                return s;
            ++stats.renders;
            stats.ms_views += msSince(t0);
            if (scratch.width != width || scratch.height != height)
                return Status::error("accum: the render callback changed the image size");
            src = &scratch;
        }
        if (probes)
            for (AccumPixelProbe& probe : *probes) {
                const size_t c = colorIndex(*src, {probe.x, probe.y});
                AccumViewSample& vs = probe.views.emplace_back();
                vs.lens = ls.position;
                vs.pixel_shift = shift;
                vs.weight = ls.weight;
                std::copy_n(src->color.data() + c, 4, vs.rgba);
                vs.depth = src->depth.load(c / 4);
            }
        t0 = Clock::now();
        const double w = double(ls.weight);
        const float* color = src->color.data();
        const bool first = i == 0;
        forRows([&](size_t begin, size_t end) {
            if (first)
                for (size_t k = begin; k < end; ++k)
                    acc[k] = 0.0 + w * double(color[k]);
            else
                for (size_t k = begin; k < end; ++k)
                    acc[k] += w * double(color[k]);
        });
        weight_sum += w;
        buffers.last_view = src;
        stats.ms_accumulate += msSince(t0);
        ++stats.views;
        if (progress)
            progress(i + 1, n);
    }

    // Normalise by the weight sum (1 up to rounding) and store as float.
    t0 = Clock::now();
    const double inv = 1.0 / weight_sum;
    forRows([&](size_t begin, size_t end) {
        for (size_t k = begin; k < end; ++k)
            out.color[k] = float(acc[k] * inv);
    });
    stats.ms_accumulate += msSince(t0);
    if (probes)
        probeResults(out, *probes);
    return stats;
} catch (const std::bad_alloc&) {
    return detail::outOfMemory("rendering accum");
}

} // namespace dof
