// Multiview's tile tracer (§4.3-§4.5): per pixel, its lens rays (jittered, §4.5) traced layer
// by layer through the height fields, coned and shaded, and their weighted mean. Consumes the
// Tracer built by multiview.cpp and multiview_setup.cpp; produces the tile's RGBA pixels and its
// TileCounters; ray and pixel states live in the caller's per-worker buffers. Everything a ray
// calls is in the .inl files included here, so each traceTile copy inlines all of it.
#include "multiview_tracer.h"

#include "multiview_cones.inl"
#include "multiview_shading.inl"
#include "multiview_traversal.inl"

#include <raster/simd.h>

#include <bit>
#include <limits>

namespace dof::multiview_detail {
namespace {

// Cone coverage at or above this ends the traversal (the cone is fully blocked, §4.4).
constexpr float kFullCoverage = 0.999f;

// A pixel's weighted sums of its rays' colours and of their weights, in double and in sample
// order: four independent sums (the weight's as wt * 1, which is wt), so the compiler can keep
// them in one vector register with the same bits as four scalars.
struct RaySum {
    double v[4] = {0.0, 0.0, 0.0, 0.0};
    void add(float weight, glm::vec3 c) {
        const double wt = double(weight);
        const double in[4] = {double(c.r), double(c.g), double(c.b), 1.0};
        for (int i = 0; i < 4; ++i)
            v[i] += wt * in[i];
    }
    // The weighted mean into out[0..2] (sums with a positive weight).
    void mean(float* out) const {
        for (int i = 0; i < 3; ++i)
            out[i] = float(v[i] / v[3]);
    }
};

// std::nextafter(x, INFINITY) inline (the library call is a tenth of a partial cone's cost): the
// next float up, by one step of the bit pattern away from zero (x > 0) or towards it (x < 0).
float nextUp(float x) {
    if (!(x < INFINITY))
        return x; // +infinity and NaN
    if (x == 0.0f)
        return std::numeric_limits<float>::denorm_min(); // from +0 and -0
    const uint32_t bits = std::bit_cast<uint32_t>(x);
    return std::bit_cast<float>(x > 0.0f ? bits + 1 : bits - 1);
}

// The lens position of sample k at output pixel (x, y) under the jitter mode (§4.5), and its
// weight.
LensSample jitteredSample(const Tracer& tr, uint32_t x, uint32_t y, uint32_t k,
                          const std::array<float, 4>& noise, uint32_t halton_offset) {
    const MultiviewSettings& s = *tr.settings;
    switch (s.jitter) {
    case JitterMode::None:
        return tr.samples->sample(k);
    case JitterMode::Rotate:
        return tr.samples->sample(x, y, k);
    case JitterMode::Halton: {
        const LensSampleSet& seq = *s.sequence_2n;
        return seq.sample((halton_offset + k) % seq.size());
    }
    case JitterMode::Noise: {
        // 16 pairwise combinations (n_i, n_j) of the texel's four components, each applied to
        // 1/16th of the samples, scaled to half the mean sample spacing (§4.5).
        LensSample ls = tr.samples->sample(k);
        const uint32_t combo = k % 16;
        const glm::vec2 off(noise[combo / 4], noise[combo % 4]);
        glm::vec2 p = ls.position + tr.lambda * off;
        const float len = glm::length(p);
        if (len > tr.r_max)
            p *= tr.r_max / len; // stay within the aperture's radius
        ls.position = p;
        return ls;
    }
    }
    return tr.samples->sample(k);
}

// traceTile's recorders. The render's, NoRecorder, records nothing: every use of a recorder's
// members sits under `if constexpr (Rec::kOn)`, so the render's code is that of a tracer without
// them.
struct NoRecorder {
    static constexpr bool kOn = false;
    // Where pixel (x, y)'s result goes: the frame's image.
    static float* pixelOut(float* rgba, const Tracer& tr, uint32_t x, uint32_t y, bool) {
        return rgba + tr.imagePixel(x, y) * 4;
    }
};

// probePixel's: fills a MultiviewPixelProbe (sized before tracing) as the tracer runs.
struct ProbeRecorder {
    static constexpr bool kOn = true;
    MultiviewPixelProbe& probe;
    PixelLayers pixel_layers;           // the pixel's culling, before rays end layers
    MultiviewLayerStep* step = nullptr; // the (ray, layer) step being traced
    uint64_t step_fetches = 0;          // TileCounters::fetches when it began
    std::array<float, 4> traced_rgba{}; // the traced result of a pixel resolved in focus

    // The pixel's result: probe.rgba is what the frame wrote, from inFocusPixel (traced =
    // false) or from endPixel; an in-focus pixel's traced rays end in traced_rgba.
    float* pixelOut(float*, const Tracer&, uint32_t, uint32_t, bool traced) {
        return traced && probe.in_focus ? traced_rgba.data() : probe.rgba;
    }
    void beginStep(uint32_t k, uint32_t l, float t_enter, const TileCounters& cnt) {
        step = &probe.rays[k].steps.emplace_back();
        step->layer = l;
        step->t_enter = t_enter;
        step_fetches = cnt.fetches;
    }
    // Ray k took colour c1 with coverage v1 in the step's layer (result: Hit, Cone, MissedCone).
    void colour(uint32_t k, MultiviewStepResult result, float t, uint32_t texel, float v1,
                glm::vec3 c1) {
        probe.rays[k].layer = int32_t(step->layer);
        step->result = result;
        step->t = t;
        step->texel = texel;
        step->coverage = v1;
        step->c1 = c1;
    }
    // Ray k of pixel (x, y) as beginRays set it up (ended at once when discarded there).
    void beginRay(const Tracer& tr, uint32_t x, uint32_t y, uint32_t k, const RayState& ray) {
        MultiviewRayRecord& r = probe.rays[k];
        r.lens = ray.lens.position;
        r.weight = ray.lens.weight;
        r.t_start = tr.segs.front().t0;
        r.start_px = pointAt(tr, x, y, ray, r.t_start);
        if (ray.discarded)
            r.discarded = true, r.t_end = r.t_start, r.end_px = r.start_px;
    }
    // Ray k's end in endPixel: its colour (with the background it sees), where it ended and
    // whether its path left the image there (`dropped`).
    void endRay(const Tracer& tr, uint32_t x, uint32_t y, uint32_t k, const RayState& ray,
                glm::vec3 color, float t_end, bool background, bool dropped) {
        MultiviewRayRecord& r = probe.rays[k];
        if (background)
            r.layer = -1;
        r.t_end = t_end;
        r.end_px = pointAt(tr, x, y, ray, t_end);
        r.discarded = dropped;
        if (!dropped)
            r.rgba[0] = color.r, r.rgba[1] = color.g, r.rgba[2] = color.b, r.rgba[3] = 1.0f;
    }
    // The output image position of the ray of the layers' pixel (x, y) at stored depth t
    // (Eq. 2-3).
    static glm::vec2 pointAt(const Tracer& tr, uint32_t x, uint32_t y, const RayState& ray,
                             float t) {
        const float g = float(tr.guard);
        return glm::vec2(float(x) - g + 0.5f, float(y) - g + 0.5f) + tr.cocOf(t) * ray.w;
    }
    void endStep(const RayState& ray, const TileCounters& cnt) {
        step->fetches = uint32_t(cnt.fetches - step_fetches);
        step->color = ray.color;
        step->transmit = ray.transmit;
    }
};

// Whether pixel (x, y)'s ray with offset w lies in the image at stored depth t.
bool rayInside(const Tracer& tr, uint32_t x, uint32_t y, glm::vec2 w, float t) {
    const glm::vec2 o = tr.offsetOf(w, t);
    return o.x >= -float(x) && o.y >= -float(y) && o.x < float(tr.width - x) &&
           o.y < float(tr.height - y);
}

// A pixel in focus, resolved without tracing. Let l be its nearest active layer (nothing nearer
// can be hit or seen by a cone: per-pixel culling with the cone margin) and h the depth of its
// own texel there. When h lies where every ray crosses the own texel's column (LayerSeg::
// focus_t0/t1), and no texel the rays cross before it can stop them (each such cell is left
// at D <= focus_t0, so a texel deeper than focus_t0, or nearer than the segment, is no hit for
// cellHit), the scan (scanPath) hits the own texel at h with every ray. There is no cone (lambda
// |C(h)| <= 1), so each ray's colour is the texel's, and the mean is summed as endPixel sums
// it: the same bits as tracing the rays. Writes the pixel and returns true, or returns false
// when the rays have to be traced.
bool inFocusPixel(const Tracer& tr, uint32_t x, uint32_t y, const PixelLayers& pl, float* out,
                  TileCounters& cnt) {
    if (pl.active == 0)
        return false;
    const uint32_t l = uint32_t(std::countr_zero(pl.active));
    const LayerSeg& seg = tr.segs[l];
    const float* depth = tr.scratch->depth[l].data();
    const uint32_t texel = y * tr.width + x;
    const float h = depth[texel];
    if (!((pl.hittable >> l) & 1) || seg.transparent ||
        !(h >= seg.t0 && h >= seg.focus_t0 && h <= seg.focus_t1) ||
        (tr.settings->cone && tr.lambda * std::fabs(tr.cocOf(h)) > 1.0f))
        return false;
    const auto& box = seg.focus_box;
    if (box.x0 <= box.x1) {
        if (int64_t(x) + box.x0 < 0 || int64_t(y) + box.y0 < 0 ||
            int64_t(x) + box.x1 >= int64_t(tr.width) || int64_t(y) + box.y1 >= int64_t(tr.height))
            return false; // clamped reads near the border: traced
        for (int32_t dy = box.y0; dy <= box.y1; ++dy)
            for (int32_t dx = box.x0; dx <= box.x1; ++dx) {
                const float hb = depth[int64_t(texel) + int64_t(dy) * tr.width + dx];
                if ((dx != 0 || dy != 0) && hb >= seg.t0 && hb <= seg.focus_t0)
                    return false;
            }
    }
    const raster::LayeredTarget& lt = *tr.layers;
    const glm::vec3 c(lt.color.load(lt.index(l, texel)));
    RaySum sum;
    for (uint32_t k = 0; k < tr.samples->size(); ++k)
        sum.add(tr.samples->sample(k).weight, c);
    sum.mean(out);
    out[3] = 1.0f;
    cnt.rays += tr.samples->size();
    ++cnt.pixels_in_focus;
    return true;
}

// The start of each of pixel (x, y)'s rays.
template <class Rec>
void beginRays(const Tracer& tr, uint32_t x, uint32_t y, RayState* rays, TileCounters& cnt,
               Rec& rec) {
    const MultiviewSettings& s = *tr.settings;
    // Per-pixel jitter keys (§4.5): a pure function of the output pixel (ix, iy) and the seed,
    // whatever the guard band.
    const uint32_t ix = x - tr.guard, iy = y - tr.guard;
    std::array<float, 4> noise{};
    uint32_t halton_offset = 0;
    if (s.jitter == JitterMode::Noise)
        for (uint32_t c = 0; c < 4; ++c)
            noise[c] = hashToUnit(hashWords(ix, iy, s.seed, 0x6e6f6973u + c)) - 0.5f;
    if (s.jitter == JitterMode::Halton)
        halton_offset = hashWords(ix, iy, s.seed, 0x68616c74u) % s.sequence_2n->size();
    const uint32_t n = tr.samples->size();
    const float t_first = tr.segs.front().t0, t_last = tr.segs.back().t1;
    cnt.rays += n;
    const bool shared = !tr.first_rays.empty(); // the set's samples, the same for every pixel
    if (shared) {
        std::copy_n(tr.first_rays.data(), n, rays);
        if (!Rec::kOn && s.offscreen != OffscreenPolicy::Discard)
            return;
    }
    const glm::vec2* cone_offsets = tr.cone_offsets.empty() ? nullptr : tr.cone_offsets.data();
    for (uint32_t k = 0; k < n; ++k) {
        RayState& ray = rays[k];
        if (!shared) {
            const LensSample ls = jitteredSample(tr, ix, iy, k, noise, halton_offset);
            const glm::vec2 w(-ls.position.x, ls.position.y);
            ray = RayState{ls, w, cone_offsets ? w + cone_offsets[k] : w};
            ray.t_end = t_last;
        }
        if (s.offscreen == OffscreenPolicy::Discard && !rayInside(tr, x, y, ray.w, t_first)) {
            ++cnt.discarded; // the path starts outside the image
            ray.discarded = true;
            ray.transmit = 0.0f;
        }
        if constexpr (Rec::kOn)
            rec.beginRay(tr, x, y, k, ray);
    }
}

// What every ray of pixel (x, y) shares in layer l (traceLayer): the layer's part is set once
// per tile layer (setLayer), the pixel's once per pixel and layer (setPixel).
struct PixelLayer {
    uint32_t l = 0;
    // A copy of the layer's segment: a local the ray's stores cannot change, so its values stay
    // in registers over the layer's rays.
    LayerSeg seg;
    const float* depth = nullptr; // the layer's stored depths
    bool shade = false;           // hits are shaded per ray (§5)
    // Sample k's path walked in advance through the whole segment: paths[k * path_stride];
    // null when the paths are walked per ray.
    const RayPath* paths = nullptr;
    size_t path_stride = 0;
    uint32_t x = 0, y = 0;
    float cx = 0.0f, cy = 0.0f; // the pixel's centre
    bool hittable = false;      // PixelLayers::hittable
    bool cones = false;         // PixelLayers::cones
    // The pixel centre lies first_cone_px inside the image: the missed cones' first lookups are
    // inside the image and their taps inside their mip levels (missCone).
    bool first_cones_inside = false;
    bool paths_inside = false; // every path of the layer lies in the image around the pixel

    void setLayer(const Tracer& tr, uint32_t layer) {
        l = layer;
        seg = tr.segs[l];
        depth = tr.scratch->depth[l].data();
        shade = tr.settings->view_dependent || tr.settings->env_map;
        paths = tr.paths.empty() ? nullptr : tr.paths.data() + l;
        path_stride = tr.segs.size();
    }
    void setPixel(const Tracer& tr, uint32_t px, uint32_t py, const PixelLayers& pls) {
        x = px, y = py;
        cx = float(x) + 0.5f, cy = float(y) + 0.5f;
        hittable = (pls.hittable >> l) & 1;
        cones = (pls.cones >> l) & 1;
        // A first lookup is within r_max |C(t_cone)| (+ rounding) of the centre, and its taps
        // inside level L when 2^(L-1) <= px < width - 2^(L-1): first_cone_px holds both.
        const float r = seg.first_cone_px;
        first_cones_inside = cx - r >= 0.0f && cy - r >= 0.0f && cx + r <= float(tr.width) &&
                             cy + r <= float(tr.height);
        const auto& box = seg.paths_box;
        paths_inside = paths && box.x0 <= box.x1 && int64_t(x) + box.x0 >= 0 &&
                       int64_t(y) + box.y0 >= 0 && int64_t(x) + box.x1 < int64_t(tr.width) &&
                       int64_t(y) + box.y1 < int64_t(tr.height);
    }
};

// Ray k of pixel (pl.x, pl.y) through layer pl.l (§4.3-§4.4): its opaque hit or miss, the
// layer's transparent plane in front of it, and the cone of either. kPlain: compiled for the
// usual case, no per-ray shading and no transparent plane in the layer (the same arithmetic,
// without the tests for them). `rec` records the step (traceTile's recorders).
template <bool kPlain, class Rec>
void traceLayer(const Tracer& tr, const PixelLayer& pl, uint32_t k, RayState& ray,
                TileCounters& cnt, Rec& rec) {
    const MultiviewSettings& s = *tr.settings;
    const raster::View& view = *tr.view;
    const raster::LayeredTarget& lt = *tr.layers;
    const uint32_t x = pl.x, y = pl.y, l = pl.l;
    const bool shade = !kPlain && pl.shade;
    const float cx = pl.cx, cy = pl.cy;
    const glm::vec2 w = ray.w, wc = ray.wc;
    // Where this ray's hits are shaded from (§5): its lens point, or the lens centre.
    const glm::vec3 shade_from =
        !kPlain && s.view_dependent
            ? view.eye + tr.lens->aperture_radius *
                             (ray.lens.position.x * view.right + ray.lens.position.y * view.up)
            : view.eye;
    // §4.4: a cone of coverage v1 and colour c1 gives v1 c1 + (1 - v1) c2, c2 what the rest
    // of the ray sees; from kFullCoverage on it blocks the ray (returns true).
    auto blend = [&](float v1, glm::vec3 c1) {
        if (v1 >= kFullCoverage) {
            ray.color += ray.transmit * c1;
            ray.transmit = 0.0f;
            return true;
        }
        ray.color += ray.transmit * v1 * c1;
        ray.transmit *= 1.0f - v1;
        return false;
    };
    ++cnt.layer_steps;
    const LayerSeg& seg = pl.seg;
    const float s0 = std::max(seg.t0, ray.t_resume);
    if constexpr (Rec::kOn)
        rec.beginStep(k, l, s0, cnt);
    if (!(s0 < seg.t1)) {
        if constexpr (Rec::kOn)
            rec.step->result = MultiviewStepResult::Skipped;
        return;
    }
    // The whole segment's path walked in advance, unless the ray resumes inside it.
    const RayPath* path =
        pl.paths && s0 == seg.t0 ? pl.paths + size_t(k) * pl.path_stride : nullptr;
    bool can_hit = pl.hittable;
    if (can_hit && s.culling && (!path || (seg.long_paths && path->count > kRayCullMinCells))) {
        // Per-ray culling: the texels this ray's segment can read lie in the box of its end
        // points; one N-buffer query skips the height-field test when none of them is within
        // the layer (the same test as §4.3's per-pixel culling, on a smaller window, so it is
        // just as lossless). Short paths walked in advance are scanned without it.
        const CellBox box = path ? CellBox{path->box_x0, path->box_x1, path->box_y0, path->box_y1}
                                 : cellBox(tr.offsetOf(w, s0), tr.offsetOf(w, seg.t1));
        if (boxCulled(tr, l, int64_t(x) + box.x0, int64_t(x) + box.x1, int64_t(y) + box.y0,
                      int64_t(y) + box.y1)) {
            ++cnt.culled_ray;
            can_hit = false;
            if constexpr (Rec::kOn)
                rec.step->culled = true;
        }
    }
    auto trace = [&](const std::vector<float>& depth, float near, float t_a, float t_b) {
        return s.traversal == Traversal::Scan
                   ? scanHeightField(tr, depth.data(), near, t_a, t_b, x, y, w, cnt)
                   : traceHeightField(tr, depth.data(), near, t_a, t_b, x, y, w, cnt, rec);
    };
    Hit h;
    if (can_hit) {
        ++cnt.layer_tests;
        if constexpr (Rec::kOn)
            rec.step->tested = true;
        h = !path ? trace(tr.scratch->depth[l], seg.t0, s0, seg.t1)
            : pl.paths_inside
                ? scanPathInside(tr, pl.depth, seg.t0, seg.t1, y * tr.width + x, *path, cnt)
                : scanPath(tr, pl.depth, seg.t0, seg.t1, x, y, *path, cnt);
    }
    // A ray that crossed the whole segment without a hit still has a cone (missCone),
    // composited in depth order with the transparent plane.
    std::optional<MissCone> miss;
    if (!h.hit && pl.cones && s0 == seg.t0)
        miss = missCone(tr, l, seg, cx, cy, wc, pl.first_cones_inside, shade, shade_from, cnt);
    auto addMiss = [&] {
        if (blend(miss->v1, miss->c1))
            ray.t_end = miss->t;
        if constexpr (Rec::kOn) {
            rec.colour(k, MultiviewStepResult::MissedCone, miss->t, 0, miss->v1, miss->c1);
            ++rec.probe.rays[k].missed_cones;
        }
        miss.reset();
    };
    // The layer's transparent plane in front of its opaque hit. The plane holds only depths of
    // the layer's own interval (LayerSink routes each BLEND fragment to the one layer owning
    // its depth), so only that part of the segment is searched. Its premultiplied colour is
    // added and the rest of the ray is seen through (1 - opacity); with cone tracing both come
    // from its mipmap (§4.4).
    const float ta = std::max(s0, seg.own0);
    const float tb = std::min(h.hit ? h.t : seg.t1, seg.own1);
    if (!kPlain && can_hit && seg.transparent && ta < tb) {
        const Hit ht = trace(tr.scratch->transparent_depth[l], seg.own0, ta, tb);
        if (ht.hit && miss && miss->t < ht.t)
            addMiss(); // the missed cone's content lies in front of the pane
        if (ht.hit && ray.transmit > 0.0f) {
            ++cnt.transparent_hits;
            const float ct = tr.cocOf(ht.t);
            const glm::vec4 m = s.cone && tr.lambda * std::fabs(ct) > 1.0f
                                    ? sampleCone(tr, tr.transparent_mips[l], cx + ct * wc.x,
                                                 cy + ct * wc.y, tr.lambda * std::fabs(ct))
                                    : lt.transparent_color.load(lt.index(l, ht.texel));
            glm::vec3 rgb(m);
            const size_t ti = lt.index(l, ht.texel);
            if (shade && lt.transparent_top_alpha[ti] > 0.0f) {
                // §5 for the plane: the composite is linear in its top pane's colour, which the
                // rasterizer shaded from the lens centre; swap in the top pane shaded from this
                // ray's origin (scaled by the cone's share of the texel's opacity).
                const raster::GSample& g = lt.transparent_gbuffer[ti];
                const glm::vec3 world = texelWorld(tr, ht.texel, ht.t);
                const glm::vec3 centre = tr.shader->shade(g, world, view.eye);
                const glm::vec3 from_ray = shadeSample(tr, g, world, shade_from);
                const float texel_a = lt.transparent_color.load(ti).a;
                const float share = texel_a > 0.0f ? std::min(m.a / texel_a, 1.0f) : 0.0f;
                rgb += share * lt.transparent_top_alpha[ti] * (from_ray - centre);
            }
            ray.color += ray.transmit * rgb;
            ray.transmit *= 1.0f - std::clamp(m.a, 0.0f, 1.0f);
            ray.t_end = ht.t;
            if constexpr (Rec::kOn) {
                rec.probe.rays[k].layer = int32_t(l);
                rec.step->transparent = true;
            }
        }
    }
    if (!h.hit) {
        if (miss)
            addMiss();
        return;
    }
    const float c_hit = tr.cocOf(h.t);
    glm::vec3 c1;
    float v1 = 1.0f;
    const bool cone_hit = s.cone && tr.lambda * std::fabs(c_hit) > 1.0f;
    if (cone_hit) {
        // §4.4: a cone of diameter lambda |C(d_i)| around the ray; the mipmapped alpha is its
        // coverage v1, the mipmapped RGB / v1 its mean colour c1.
        const glm::vec4 m = sampleCone(tr, tr.mips[l], cx + c_hit * wc.x, cy + c_hit * wc.y,
                                       tr.lambda * std::fabs(c_hit));
        v1 = std::clamp(m.a, 0.0f, 1.0f);
        c1 = v1 > 0.0f ? glm::vec3(m) / m.a : glm::vec3(0.0f);
    } else {
        c1 = glm::vec3(lt.color.load(lt.index(l, h.texel)));
    }
    if (shade)
        c1 = cone_hit ? shadeFootprint(tr, l, h.texel, h.t, cx + c_hit * wc.x, cy + c_hit * wc.y,
                                       0.5f * tr.lambda * std::fabs(c_hit), shade_from)
                      : shadeHit(tr, l, h.texel, h.t, shade_from);
    if constexpr (Rec::kOn)
        rec.colour(k, cone_hit ? MultiviewStepResult::Cone : MultiviewStepResult::Hit, h.t, h.texel,
                   v1, c1);
    ray.t_end = h.t;
    if (blend(v1, c1))
        return; // the ray ends here (transmit 0)
    // Continue along the centre ray for c2.
    ++cnt.cone_partial;
    if constexpr (Rec::kOn)
        ++rec.probe.rays[k].partial_hits;
    // Resume a thousandth of the segment behind the slab, and at least one float step: stored
    // depth D = -n/d has the scale of n/d (camera.h), so an absolute nudge would skip whole
    // scenes under a tiny near plane.
    ray.t_resume = nextUp(h.t_behind + 1e-3f * (seg.t1 - seg.t0));
}

// The end of pixel (x, y)'s rays: the background behind them, the paths that left the image
// (Discard), and the weighted mean in sample order.
template <class Rec>
void endPixel(const Tracer& tr, uint32_t x, uint32_t y, const RayState* rays, float* out,
              TileCounters& cnt, Rec& rec) {
    const MultiviewSettings& s = *tr.settings;
    const float t_last = tr.segs.back().t1;
    RaySum sum;
    const uint32_t n = tr.samples->size();
    // No ray is recorded or discarded (the usual case): the weighted mean alone, as below.
    const bool plain = !Rec::kOn && s.offscreen != OffscreenPolicy::Discard;
    for (uint32_t k = 0; plain && k < n; ++k) {
        const RayState& ray = rays[k];
        glm::vec3 color = ray.color;
        if (ray.transmit > 0.0f) {
            ++cnt.background;
            color += ray.transmit * tr.background;
        }
        sum.add(ray.lens.weight, color);
    }
    for (uint32_t k = 0; !plain && k < n; ++k) {
        const RayState& ray = rays[k];
        if (ray.discarded)
            continue;
        glm::vec3 color = ray.color;
        float t_end = ray.t_end;
        const bool background = ray.transmit > 0.0f;
        if (background) {
            ++cnt.background;
            color += ray.transmit * tr.background;
            t_end = t_last;
        }
        const bool dropped =
            s.offscreen == OffscreenPolicy::Discard && !rayInside(tr, x, y, ray.w, t_end);
        if constexpr (Rec::kOn)
            rec.endRay(tr, x, y, k, ray, color, t_end, background, dropped);
        if (dropped) {
            ++cnt.discarded; // the path to the hit leaves the image
            continue;
        }
        sum.add(ray.lens.weight, color);
    }
    if (sum.v[3] > 0.0) {
        sum.mean(out);
    } else { // every ray left the image: the pinhole colour
        const size_t i = tr.imagePixel(x, y) * 4;
        out[0] = tr.pinhole->color[i];
        out[1] = tr.pinhole->color[i + 1];
        out[2] = tr.pinhole->color[i + 2];
    }
    out[3] = 1.0f;
}

// The rays of the pixels [x0, x1) x [y0, y1), layer by layer: every ray of the tile meets layer
// l before any meets layer l + 1, so one layer's texels, mipmaps and N-buffer around the tile
// stay in the cache while they are read (pixel by pixel, all layers of a tile do not fit in it).
// Each ray still visits its layers front to back with the same arithmetic, so the bytes are
// those of tracing each pixel's rays to their ends in turn. `rays` holds (x1-x0)(y1-y0)N states.
// `rec` records what happens (NoRecorder: nothing); a recorder traces the rays of a pixel in
// focus too, after inFocusPixel has given its result.
template <class Rec>
void traceTile(const Tracer& tr, uint32_t x0, uint32_t x1, uint32_t y0, uint32_t y1,
               const uint32_t* tile_layers, uint32_t tile_layer_count, RayState* rays,
               PixelLayers* pixel_layers, float* rgba, TileCounters& counters, Rec& rec) {
    // Counted in a local: the compiler then knows that the counts' stores change none of the
    // Tracer's, segments' or buffers' values, and need not load those again after each count
    // (traceTileAvx2 on demo 400x300, N = 32: 2 % fewer instructions).
    TileCounters cnt = counters;
    const uint32_t n = tr.samples->size();
    const uint32_t tw = x1 - x0;
    std::array<LayerCulls, raster::kMaxLayers> culls;
    if (tr.settings->culling)
        for (uint32_t i = 0; i < tile_layer_count; ++i)
            culls[i] = layerCulls(tr, tile_layers[i]);
    for (uint32_t y = y0; y < y1; ++y)
        for (uint32_t x = x0; x < x1; ++x) {
            const size_t p = size_t(y - y0) * tw + (x - x0);
            PixelLayers& pl = pixel_layers[p];
            pl = pixelLayers(tr, x, y, tile_layers, tile_layer_count, culls.data(), cnt);
            if constexpr (Rec::kOn)
                rec.pixel_layers = pl;
            if (tr.in_focus &&
                inFocusPixel(tr, x, y, pl, rec.pixelOut(rgba, tr, x, y, false), cnt)) {
                if constexpr (Rec::kOn) {
                    rec.probe.in_focus = true;
                } else {
                    pl.active = 0;
                    pl.resolved = true;
                    continue;
                }
            }
            beginRays(tr, x, y, rays + p * n, cnt, rec);
        }
    PixelLayer pxl;
    for (uint32_t i = 0; i < tile_layer_count; ++i) {
        const uint32_t l = tile_layers[i];
        pxl.setLayer(tr, l);
        for (uint32_t y = y0; y < y1; ++y)
            for (uint32_t x = x0; x < x1; ++x) {
                const size_t p = size_t(y - y0) * tw + (x - x0);
                if (!((pixel_layers[p].active >> l) & 1))
                    continue;
                pxl.setPixel(tr, x, y, pixel_layers[p]);
                RayState* pr = rays + p * n;
                // The live rays through the layer, one loop per traceLayer variant.
                const auto traceRays = [&]<bool kPlain>() {
                    uint32_t live = 0;
                    for (uint32_t k = 0; k < n; ++k)
                        if (pr[k].transmit > 0.0f) {
                            traceLayer<kPlain>(tr, pxl, k, pr[k], cnt, rec);
                            if constexpr (Rec::kOn)
                                rec.endStep(pr[k], cnt);
                            live += pr[k].transmit > 0.0f ? 1 : 0;
                        }
                    return live;
                };
                const uint32_t live = !pxl.shade && !pxl.seg.transparent
                                          ? traceRays.template operator()<true>()
                                          : traceRays.template operator()<false>();
                if (live == 0)
                    pixel_layers[p].active = 0; // every ray has ended: no layer behind is met
            }
    }
    for (uint32_t y = y0; y < y1; ++y)
        for (uint32_t x = x0; x < x1; ++x) {
            const size_t p = size_t(y - y0) * tw + (x - x0);
            if (!pixel_layers[p].resolved)
                endPixel(tr, x, y, rays + p * n, rec.pixelOut(rgba, tr, x, y, true), cnt, rec);
        }
    counters = cnt;
}

// traceTile compiled twice, for the baseline x86-64 and for AVX2 (the raster kernels' written-
// once, compiled-twice form, here by function attributes): `flatten` inlines everything it calls
// (the tracer's functions and the standard library's inline code) into each copy, so each is
// compiled whole for its target, and no code built for AVX2 is shared with the baseline copy.
// Without FMA the AVX2 copy computes the same IEEE operations in the same order (the build
// forbids contraction and reassociation), so the bytes are the same; what differs is the
// instructions chosen (a floor is one `vroundss` instead of a dozen SSE2 instructions, selects
// are blends). The baseline copy is the reference: ShadingInputs::simd = false (`--no-simd`).
#if defined(__x86_64__) && !defined(FOCAL_NO_SIMD)
#define FOCAL_MULTIVIEW_AVX2 1
#endif

__attribute__((flatten)) void
traceTileBaseline(const Tracer& tr, uint32_t x0, uint32_t x1, uint32_t y0, uint32_t y1,
                  const uint32_t* tile_layers, uint32_t tile_layer_count, RayState* rays,
                  PixelLayers* pixel_layers, float* rgba, TileCounters& cnt) {
    NoRecorder rec;
    traceTile(tr, x0, x1, y0, y1, tile_layers, tile_layer_count, rays, pixel_layers, rgba, cnt,
              rec);
}

#ifdef FOCAL_MULTIVIEW_AVX2
__attribute__((flatten, target("avx2,no-fma"))) void
traceTileAvx2(const Tracer& tr, uint32_t x0, uint32_t x1, uint32_t y0, uint32_t y1,
              const uint32_t* tile_layers, uint32_t tile_layer_count, RayState* rays,
              PixelLayers* pixel_layers, float* rgba, TileCounters& cnt) {
    NoRecorder rec;
    traceTile(tr, x0, x1, y0, y1, tile_layers, tile_layer_count, rays, pixel_layers, rgba, cnt,
              rec);
}
#endif

} // namespace

bool culled(const Tracer& tr, uint32_t l, uint32_t x0, uint32_t x1, uint32_t y0, uint32_t y1,
            float margin) {
    const float r = tr.segs[l].reach_px + margin;
    const int64_t lo = int64_t(std::floor(0.5f - r)), hi = int64_t(std::floor(0.5f + r));
    return boxCulled(tr, l, int64_t(x0) + lo, int64_t(x1) + hi, int64_t(y0) + lo, int64_t(y1) + hi);
}

uint32_t tileLayers(const Tracer& tr, uint32_t x0, uint32_t x1, uint32_t y0, uint32_t y1,
                    uint32_t* out, TileCounters& cnt) {
    uint32_t count = 0;
    for (uint32_t l = 0; l < tr.segs.size(); ++l) {
        if (tr.segs[l].empty)
            continue;
        if (tr.settings->culling && culled(tr, l, x0, x1 - 1, y0, y1 - 1, tr.segs[l].cone_px)) {
            ++cnt.culled_tile;
            continue;
        }
        out[count++] = l;
    }
    return count;
}

void probePixel(const Tracer& tr, uint32_t x, uint32_t y, MultiviewPixelProbe& out) {
    const uint32_t n = tr.samples->size(), m = uint32_t(tr.segs.size());
    out = MultiviewPixelProbe{};
    out.x = x, out.y = y;
    out.rays.resize(n);
    // The frame's tile around the pixel and its layers (the same per-tile culling), in the
    // layers' coordinates.
    const uint32_t ts = tr.settings->tile_size, g = tr.guard;
    const uint32_t x0 = g + x / ts * ts, y0 = g + y / ts * ts;
    TileCounters cnt;
    std::array<uint32_t, raster::kMaxLayers> tile_layers{};
    const uint32_t count =
        tileLayers(tr, x0, std::min(x0 + ts, g + tr.image_width), y0,
                   std::min(y0 + ts, g + tr.image_height), tile_layers.data(), cnt);
    // The pixel alone, as its tile traces it (each pixel's rays are independent of the others').
    std::vector<RayState> rays(n);
    PixelLayers pixel_layers;
    ProbeRecorder rec{out, {}, nullptr, 0, {}};
    traceTile(tr, g + x, g + x + 1, g + y, g + y + 1, tile_layers.data(), count, rays.data(),
              &pixel_layers, nullptr, cnt, rec);
    out.layers.resize(m);
    for (uint32_t l = 0; l < m; ++l) {
        const PixelLayers& pl = rec.pixel_layers;
        const uint64_t bit = uint64_t(1) << l;
        out.layers[l] = tr.segs[l].empty ? MultiviewLayerCull::Empty
                        : std::find(tile_layers.data(), tile_layers.data() + count, l) ==
                                tile_layers.data() + count
                            ? MultiviewLayerCull::Tile
                        : !(pl.active & bit)   ? MultiviewLayerCull::Pixel
                        : !(pl.hittable & bit) ? MultiviewLayerCull::ConesOnly
                                               : MultiviewLayerCull::None;
    }
}

TraceTileFn traceTileFor(bool simd) {
#ifdef FOCAL_MULTIVIEW_AVX2
    if (raster::useAvx2(simd))
        return traceTileAvx2;
#endif
    (void)simd;
    return traceTileBaseline;
}

} // namespace dof::multiview_detail
