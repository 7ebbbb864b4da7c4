// FrameRenderer's observation (frame_observer.h): the stages of the frame just rendered, built
// from what the renderer and the method kept, and the probes of the observer's pixels. Each
// stage's paragraph is the short version of its page in docs/ (docs/raster.md, docs/targets.md,
// docs/dof/*.md), with the paper section it implements.
#include "pinhole_view.h"

#include <dof/frame_observer.h>
#include <dof/frame_renderer.h>
#include <raster/fragment_lists.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace dof {

using detail::pinholeView;
using raster::Status;

// What observing keeps between frames: the frames and lists rendered only to be looked at,
// accum's captured views and running averages.
struct detail::FrameObservation {
    raster::Frame frame;         // the pinhole view again, for the raster stages
    raster::FrameStats stats;    // its counts and times
    raster::FragmentLists lists; // every fragment of the pinhole view, nearest first
    std::vector<uint32_t> tile_triangles;
    uint32_t tiles_x = 0, tiles_y = 0;
    std::vector<float> coc; // gather's signed CoC map when the caller asked for none
    std::vector<AccumPixelProbe> accum_probes;
    // accum: a few single views and the running average after 1, 2, 4, ... views.
    std::vector<std::pair<uint32_t, std::vector<float>>> views, averages;
};

namespace {

// Views accum's stage shows one by one: the first few.
constexpr uint32_t kAccumViewsShown = 4;
// Fragment-list entries the targets stage shows per pixel.
constexpr uint32_t kListEntriesShown = 4;

// Builds one Stage and owns its images until the observer has seen it.
class StageBuilder {
public:
    StageBuilder(std::string id, std::string group, std::string title, std::string paper,
                 std::string text) {
        stage_.id = std::move(id);
        stage_.group = std::move(group);
        stage_.title = std::move(title);
        stage_.paper = std::move(paper);
        stage_.text = std::move(text);
    }
    void ms(double v) { stage_.ms = v; }
    void count(std::string name, double v) { stage_.counts.emplace_back(std::move(name), v); }
    // A new image of w x h pixels with `channels` floats each, zeroed; returns its pixels.
    float* image(std::string name, std::string caption, StageImageKind kind, uint32_t w, uint32_t h,
                 uint32_t channels, uint32_t scale = 1) {
        // Inner buffers keep their address when the outer vector grows.
        store_.emplace_back(size_t(w) * h * channels, 0.0f);
        StageImage img;
        img.name = std::move(name);
        img.caption = std::move(caption);
        img.kind = kind;
        img.width = w;
        img.height = h;
        img.channels = channels;
        img.scale = scale;
        img.pixels = store_.back().data();
        img.stride = size_t(w) * channels;
        stage_.images.push_back(std::move(img));
        return store_.back().data();
    }
    // A copy of linear RGBA rows (`src` width*4 floats per row).
    void color(std::string name, std::string caption, const float* src, uint32_t w, uint32_t h,
               uint32_t scale = 1) {
        float* dst =
            image(std::move(name), std::move(caption), StageImageKind::Color, w, h, 4, scale);
        std::copy(src, src + size_t(w) * h * 4, dst);
    }
    StageTable& table(std::string name, std::vector<std::string> columns) {
        stage_.tables.push_back(StageTable{std::move(name), std::move(columns), {}});
        return stage_.tables.back();
    }
    StagePoints& points(std::string name, std::string x_label, std::string y_label) {
        StagePoints p;
        p.name = std::move(name);
        p.x_label = std::move(x_label);
        p.y_label = std::move(y_label);
        stage_.plots.push_back(std::move(p));
        return stage_.plots.back();
    }
    void send(FrameObserver& observer) const { observer.stage(stage_); }

private:
    Stage stage_;
    std::vector<std::vector<float>> store_;
};

// Distance along the view axis of a stored depth D; +inf where nothing was drawn (D >= far).
float distanceOf(const raster::View& view, float stored) {
    return stored < raster::kFarDepth ? raster::distanceFromDepth(view, stored) : INFINITY;
}

void distanceImage(StageBuilder& b, std::string name, std::string caption, const raster::View& view,
                   const raster::DepthBuffer& depth, size_t first, uint32_t w, uint32_t h) {
    float* dst = b.image(std::move(name), std::move(caption), StageImageKind::Distance, w, h, 1);
    for (size_t i = 0; i < size_t(w) * h; ++i)
        dst[i] = distanceOf(view, depth.load(first + i));
}

// Colour times alpha, and alpha: how a target's RGBA is shown over black.
void storePremultiplied(glm::vec4 v, float* dst) {
    dst[0] = v.r * v.a, dst[1] = v.g * v.a, dst[2] = v.b * v.a, dst[3] = v.a;
}

std::string layerName(uint32_t l) {
    return (l < 10 ? "layer 0" : "layer ") + std::to_string(l);
}

// The raster pipeline's stages (docs/raster.md) on the pinhole view every method starts from.
void rasterStages(const raster::View& pin, const raster::RenderOptions& options,
                  const detail::FrameObservation& o, FrameObserver& observer) {
    const uint32_t w = pin.width, h = pin.height;
    const raster::FragmentLists& lists = o.lists;
    {
        StageBuilder b("raster.geometry", "raster", "Geometry: transform, clip, cull", "",
                       "Every triangle of the scene is transformed to clip space, culled when it "
                       "faces away, has no area or lies outside the view frustum, clipped "
                       "against the near and far planes (and the guard band), and set up in "
                       "24.8 fixed point for the edge functions. The picture shows the triangle "
                       "nearest the eye at each pixel (its submission index as a colour).");
        b.ms(o.stats.ms_geometry);
        b.count("triangles_in", double(o.stats.triangles_in));
        b.count("triangles_culled", double(o.stats.triangles_culled));
        b.count("triangles_clipped", double(o.stats.triangles_clipped));
        b.count("triangles_setup", double(o.stats.triangles_setup));
        float* id =
            b.image("nearest triangle", "submission index of the nearest triangle; -1: none",
                    StageImageKind::Id, w, h, 1);
        for (size_t i = 0; i < size_t(w) * h; ++i)
            id[i] = lists.count(i) > 0 ? float(lists.primitive[lists.offsets[i]]) : -1.0f;
        b.send(observer);
    }
    {
        StageBuilder b("raster.binning", "raster", "Binning: triangles per tile", "",
                       "Each set-up triangle is appended, in submission order, to the list of "
                       "every tile its bounding box touches. A tile is then rasterized by one "
                       "worker, which replays its list in order: that is what makes the bytes "
                       "independent of the thread count. The heat map is the list length per "
                       "tile, the work each tile brings.");
        b.ms(o.stats.ms_binning);
        b.count("tile_size", double(options.tile_size));
        b.count("tiles", double(o.tile_triangles.size()));
        uint64_t sum = 0;
        uint32_t most = 0;
        for (uint32_t n : o.tile_triangles) {
            sum += n;
            most = std::max(most, n);
        }
        b.count("binned_triangles", double(sum));
        b.count("max_per_tile", double(most));
        float* heat = b.image("triangles per tile", "triangles binned to each tile",
                              StageImageKind::Count, o.tiles_x, o.tiles_y, 1, options.tile_size);
        for (size_t t = 0; t < o.tile_triangles.size(); ++t)
            heat[t] = float(o.tile_triangles[t]);
        b.send(observer);
    }
    {
        StageBuilder b("raster.coverage", "raster", "Coverage and depth", "",
                       "Inside each tile, the three edge functions are evaluated at pixel "
                       "centres in fixed point with the top-left fill rule, so a pixel on an "
                       "edge shared by two triangles belongs to exactly one. A covered sample "
                       "passes the depth test (reversed-Z, nearer wins, ties to the earlier "
                       "triangle) before it is shaded. The pictures show the depth kept and how "
                       "many triangle fragments covered each pixel (depth complexity).");
        b.ms(o.stats.ms_raster);
        b.count("fragments_covered", double(o.stats.fragments_covered));
        b.count("fragments_passed", double(o.stats.fragments_passed));
        distanceImage(b, "depth", "distance along the view axis; empty: nothing drawn", pin,
                      o.frame.depth, 0, w, h);
        float* n = b.image("fragments per pixel", "triangle fragments covering each pixel",
                           StageImageKind::Count, w, h, 1);
        for (size_t i = 0; i < size_t(w) * h; ++i)
            n[i] = float(lists.list_length[i]);
        b.send(observer);
    }
    {
        StageBuilder b("raster.color", "raster", "Shading: the colour target", "",
                       "The fragment that wins the depth test is shaded (base colour from "
                       "mipmapped, sRGB-decoded textures, the material's alpha mode, the shading "
                       "model) with perspective-correct attributes, and written to the linear "
                       "RGBA colour target. This pinhole image through the lens centre is where "
                       "every depth-of-field method starts.");
        b.color("colour", "linear RGBA, shown sRGB-encoded", o.frame.color.data(), w, h);
        b.send(observer);
    }
    {
        StageBuilder b("targets.fragment_lists", "targets", "Fragment lists",
                       "Selgrad et al. 2015, §4 (per-pixel fragment lists)",
                       "The GPU's per-pixel linked lists, made deterministic: every fragment of "
                       "every triangle is appended in primitive order, then each pixel's list is "
                       "sorted by depth (ties by primitive) and compacted. These are the lists of "
                       "the pinhole view with every fragment kept; the pictures show the first "
                       "entries of each list (nearest first) and their depths.");
        b.count("fragments", double(lists.fragments_kept));
        b.count("max_list_length", double(lists.max_list_length));
        for (uint32_t k = 0; k < kListEntriesShown; ++k) {
            float* c = b.image("entry " + std::to_string(k) + " colour",
                               "colour of the list's entry " + std::to_string(k) +
                                   " times its opacity; black: shorter list",
                               StageImageKind::Color, w, h, 4);
            for (size_t i = 0; i < size_t(w) * h; ++i)
                if (lists.count(i) > k) {
                    storePremultiplied(lists.color.load(lists.offsets[i] + k), c + 4 * i);
                }
        }
        for (uint32_t k = 0; k < kListEntriesShown; ++k) {
            float* d = b.image("entry " + std::to_string(k) + " depth",
                               "distance of the list's entry " + std::to_string(k),
                               StageImageKind::Distance, w, h, 1);
            for (size_t i = 0; i < size_t(w) * h; ++i)
                d[i] = lists.count(i) > k ? distanceOf(pin, lists.depth.load(lists.offsets[i] + k))
                                          : INFINITY;
        }
        b.send(observer);
    }
}

// The time the report gives a stage of the method; -1 when it has none.
double stageMs(const FrameReport& report, const char* name) {
    for (const auto& [n, ms] : report.stage_ms)
        if (n == name)
            return ms;
    return -1.0;
}

void resultStage(const char* method, const FrameImage& image, uint32_t w, uint32_t h,
                 FrameObserver& observer) {
    StageBuilder b("result.image", "result", "The result", "",
                   std::string("The image ") + method +
                       " wrote: linear RGBA, the bytes the frame returns. Compare it with the "
                       "accumulation reference side by side.");
    float* c = b.image("result", "linear RGBA, shown sRGB-encoded", StageImageKind::Color, w, h, 4);
    for (uint32_t y = 0; y < h; ++y)
        std::copy(image.rgba + size_t(y) * image.stride,
                  image.rgba + size_t(y) * image.stride + size_t(w) * 4, c + size_t(y) * w * 4);
    b.send(observer);
}

} // namespace

void detail::FrameObservationDeleter::operator()(FrameObservation* p) const {
    delete p;
}

detail::FrameObservation& FrameRenderer::observation() {
    if (!observation_)
        observation_.reset(new detail::FrameObservation);
    return *observation_;
}

std::vector<float>& FrameRenderer::observedCoc() {
    return observation().coc;
}

std::vector<AccumPixelProbe>& FrameRenderer::observedAccumProbes() {
    return observation().accum_probes;
}

Status FrameRenderer::probeMethod(const raster::Scene& scene, const raster::View& view,
                                  const ThinLens& lens, const raster::RenderOptions& options,
                                  const MethodSettings& method, size_t index, PixelProbe& probe) {
    const uint32_t x = probe.x, y = probe.y;
    if (std::holds_alternative<AccumMethod>(method)) {
        probe.method = observation().accum_probes.at(index);
        return {};
    }
    if (std::holds_alternative<GatherMethod>(method))
        return probeGather(gatherImageOf(pinhole_), lens, pinholeView(view), gather_settings_,
                           gather_scratch_, x, y, probe.method.emplace<GatherPixelProbe>());
    if (const MultiviewMethod* m = std::get_if<MultiviewMethod>(&method)) {
        ShadingInputs shading;
        shading.scene = &scene;
        shading.simd = options.simd;
        return probeMultiview(view, lens, *m->samples, pinhole_, layers_, multiview_settings_,
                              shading, multiview_scratch_, x, y,
                              probe.method.emplace<MultiviewPixelProbe>());
    }
    if (std::holds_alternative<MultilayerMethod>(method))
        return multilayer_.probe(x, y, probe.method.emplace<MultilayerPixelProbe>());
    return {};
}

ProgressFn FrameRenderer::observeAccum(const AccumMethod& m) {
    detail::FrameObservation& o = observation();
    o.views.clear();
    o.averages.clear();
    return [this, &o, &m](uint32_t done, uint32_t total) {
        if (m.progress)
            m.progress(done, total);
        const AccumScratch& a = accum_scratch_;
        if (!a.last_view || done == 0)
            return; // skipped: the pinhole is the result, no view was added
        if (done - 1 < kAccumViewsShown)
            o.views.emplace_back(done - 1, a.last_view->color);
        if ((done & (done - 1)) == 0 || done == total) {
            // sums / weights so far, as renderAccum normalises the final one.
            const double inv = 1.0 / a.weight_sum;
            std::vector<float> avg(a.sums.size());
            for (size_t k = 0; k < avg.size(); ++k)
                avg[k] = float(a.sums[k] * inv);
            o.averages.emplace_back(done, std::move(avg));
        }
    };
}

Status FrameRenderer::observeFrame(const raster::Scene& scene, const raster::View& view,
                                   const ThinLens& lens, const raster::RenderOptions& options,
                                   const MethodSettings& method, const FrameReport& report,
                                   const FrameImage& image, FrameObserver& observer) {
    detail::FrameObservation& o = observation();
    const raster::View pin = pinholeView(view);
    const uint32_t w = view.width, h = view.height;
    const std::span<const glm::uvec2> probes = observer.probePixels();

    // The pinhole view again (the same bytes every method started from), with its counts and
    // bins, and its fragment lists with every fragment (the coverage and the probes' fragments).
    o.stats = {};
    if (Status s = renderer_->render(scene, pin, options, o.frame, &o.stats); !s.ok())
        return s;
    renderer_->tileTriangleCounts(o.tile_triangles, o.tiles_x, o.tiles_y);
    raster::FragmentListDesc desc;
    desc.max_per_pixel = 0;
    desc.early_reject = false;
    desc.color_format = raster::ColorFormat::Float32;
    desc.depth_format = raster::DepthFormat::Float32;
    desc.on_overflow = raster::OverflowPolicy::Grow;
    if (Status s = renderer_->renderFragmentLists(scene, pin, options, desc, o.lists); !s.ok())
        return s;

    rasterStages(pin, options, o, observer);

    if (const AccumMethod* m = std::get_if<AccumMethod>(&method)) {
        const AccumStats& st = std::get<AccumStats>(report.method_stats);
        {
            StageBuilder b("accum.lens", "accum", "Lens samples",
                           "Haeberli & Akeley 1990; Lee et al. 2009, §3",
                           "The reference renders the scene once per point v of the aperture "
                           "(lens units: the unit disk scaled by the aperture radius E), from the "
                           "eye moved to eye + E·v with a frustum sheared so that the focal "
                           "plane's pixels stay fixed. The points and their weights come from "
                           "the lens sample pattern shared with multiview.");
            b.count("samples", double(m->samples->size()));
            b.count("views", double(st.views));
            b.count("skipped", st.skipped ? 1.0 : 0.0);
            StagePoints& p = b.points("lens samples", "u", "v");
            for (const LensSample& s : m->samples->samples())
                p.points.push_back(s.position);
            b.send(observer);
        }
        {
            StageBuilder b("accum.views", "accum", "Single views",
                           "Haeberli & Akeley 1990 (accumulation buffer)",
                           "A few of the sheared pinhole renders, each a full run of the raster "
                           "pipeline from its lens point. Objects at the focus distance stay in "
                           "place; nearer and farther ones move in opposite directions by C(d)·v "
                           "pixels, which is what averaging turns into blur.");
            b.ms(stageMs(report, "views"));
            for (const auto& [i, c] : o.views)
                b.color("view " + std::to_string(i),
                        "lens sample " + std::to_string(i) + " at (" +
                            std::to_string(m->samples->sample(i).position.x) + ", " +
                            std::to_string(m->samples->sample(i).position.y) + ")",
                        c.data(), w, h);
            b.send(observer);
        }
        {
            StageBuilder b("accum.average", "accum", "Running average",
                           "Haeberli & Akeley 1990 (accumulation buffer)",
                           "The views are added one after another in sample order, in double "
                           "precision and weighted by their samples' weights, then normalised by "
                           "the weight sum. The pictures show the average after 1, 2, 4, ... "
                           "views: the noise of the blur falls as more lens samples arrive.");
            b.ms(stageMs(report, "accumulate"));
            for (const auto& [n, c] : o.averages)
                b.color("after " + std::to_string(n) + (n == 1 ? " view" : " views"),
                        "weighted mean of the first " + std::to_string(n) + " views", c.data(), w,
                        h);
            b.send(observer);
        }
    } else if (std::holds_alternative<GatherMethod>(method)) {
        const GatherStats& st = std::get<GatherStats>(report.method_stats);
        const std::vector<float>& coc = std::get<GatherMethod>(method).coc_out
                                            ? *std::get<GatherMethod>(method).coc_out
                                            : o.coc;
        {
            StageBuilder b("gather.coc", "gather", "Circle of confusion",
                           "Zhou, Chen & Pullen 2007, §3 (Eq. 2)",
                           "The signed circle of confusion of every pixel from the depth buffer, "
                           "C = E·f_px·(1/d_f − 1/d): negative in front of the focal plane, "
                           "positive behind, 0 in focus. Its magnitude, clamped to the largest "
                           "radius R, is each pixel's filter radius in both passes.");
            b.ms(stageMs(report, "coc"));
            b.count("min_coc_px", double(st.min_coc_px));
            b.count("max_coc_px", double(st.max_coc_px));
            b.count("clamped_pixels", double(st.clamped_pixels));
            float* c = b.image("signed CoC", "C in pixels: blue in front, red behind",
                               StageImageKind::Signed, w, h, 1);
            std::copy(coc.begin(), coc.begin() + std::min(coc.size(), size_t(w) * h), c);
            b.send(observer);
        }
        {
            StageBuilder b("gather.vertical", "gather", "Vertical pass",
                           "Zhou, Chen & Pullen 2007, §3.1–3.3",
                           "The first of two separable passes: each pixel gathers the samples "
                           "of its column within its radius, each weighted by whether the "
                           "sample's own circle of confusion overlaps the pixel, by its "
                           "intensity (the inverse of its blur area) and by the leakage rule "
                           "that keeps sharp background from bleeding over a blurred "
                           "foreground.");
            b.ms(stageMs(report, "vertical"));
            b.count("tiles", double(st.tiles));
            b.count("tiles_copied_vertical", double(st.tiles_copied_vertical));
            b.color("vertical pass", "linear RGBA after the vertical pass",
                    gather_scratch_.vertical.data(), w, h);
            b.send(observer);
        }
        {
            StageBuilder b("gather.horizontal", "gather", "Horizontal pass",
                           "Zhou, Chen & Pullen 2007, §3.1–3.3",
                           "The second pass gathers along rows from the vertical pass's output "
                           "with the same weights, which completes the separable approximation "
                           "of the circular gather.");
            b.ms(stageMs(report, "horizontal"));
            b.count("tiles_copied_horizontal", double(st.tiles_copied_horizontal));
            b.count("samples", double(st.samples));
            b.color("horizontal pass", "linear RGBA: the result", rgba_.data(), w, h);
            b.send(observer);
        }
    } else if (std::holds_alternative<MultiviewMethod>(method)) {
        multiviewStages(view, lens, std::get<MultiviewMethod>(method), report, observer);
    } else if (std::holds_alternative<MultilayerMethod>(method)) {
        multilayerStages(pin, report, observer);
    }
    resultStage(methodName(method), image, w, h, observer);

    for (size_t n = 0; n < probes.size(); ++n) {
        const glm::uvec2 p = probes[n];
        PixelProbe probe;
        probe.x = p.x;
        probe.y = p.y;
        if (Status s = probeMethod(scene, view, lens, options, method, n, probe); !s.ok())
            return s;
        const float* px = image.rgba + size_t(p.y) * image.stride + size_t(p.x) * 4;
        std::copy(px, px + 4, probe.rgba);
        const size_t i = size_t(p.y) * w + p.x;
        for (uint32_t k = o.lists.offsets[i]; k < o.lists.offsets[i + 1]; ++k) {
            ProbeFragment f;
            f.distance = distanceOf(pin, o.lists.depth.load(k));
            f.primitive = o.lists.primitive[k];
            const glm::vec4 c = o.lists.color.load(k);
            f.rgba[0] = c.r, f.rgba[1] = c.g, f.rgba[2] = c.b, f.rgba[3] = c.a;
            probe.fragments.push_back(f);
        }
        observer.probe(probe);
    }
    return {};
}

void FrameRenderer::multiviewStages(const raster::View& view, const ThinLens& lens,
                                    const MultiviewMethod& m, const FrameReport& report,
                                    FrameObserver& observer) {
    const MultiviewStats& st = std::get<MultiviewStats>(report.method_stats);
    const uint32_t w = view.width, h = view.height;
    const raster::View pin = pinholeView(view);
    const raster::LayeredTarget& t = layers_;
    const bool traced = !st.skipped && t.layer_count > 0;
    {
        StageBuilder b("multiview.decomposition", "multiview", "Layer bounds",
                       "Lee, Eisemann & Seidel 2009, §4.1 (Eq. 4)",
                       "The visible depth range [d_near, d_far] of the pinhole frame is cut into "
                       "M layers uniform in the circle of confusion, δ pixels apart (Eq. 4: C is "
                       "affine in 1/d, so equal steps in C are equal steps in 1/d). A ray's image "
                       "position then moves at most δ·|v| pixels inside one layer.");
        b.ms(stageMs(report, "decomposition"));
        b.count("layers", double(st.layers));
        b.count("layers_empty", double(st.layers_empty));
        b.count("guard_band_px", double(st.guard_band_px));
        b.count("delta_px", double(st.delta_px));
        b.count("d_near", double(st.d_near));
        b.count("d_far", double(st.d_far));
        b.count("skipped", st.skipped ? 1.0 : 0.0);
        StageTable& tab =
            b.table("layer bounds", {"layer", "d_near", "d_far", "C_near px", "C_far px"});
        const std::vector<float>& bounds = t.desc.bounds;
        for (size_t l = 0; traced && l + 1 < bounds.size(); ++l)
            tab.rows.push_back({double(l), double(bounds[l]), double(bounds[l + 1]),
                                double(cocRadiusPx(lens, bounds[l])),
                                double(cocRadiusPx(lens, bounds[l + 1]))});
        b.send(observer);
    }
    if (traced) {
        StageBuilder b("targets.layers", "targets", "The layered target",
                       "Lee, Eisemann & Seidel 2009, §4.2",
                       "Layered rendering: each triangle goes to the layer (or, with the "
                       "overlap, layers) its depth falls in, and every layer has its own depth "
                       "buffer, so a layer keeps the nearest surface of its depth interval even "
                       "where a nearer layer hides it. Colour is shown times coverage; depth is "
                       "the stored distance of the layer's surface. The layers cover the image "
                       "and a guard band around it (§4.3), where rays leaving the image read.");
        b.count("layers", double(t.layer_count));
        b.count("guard_band_px", double(st.guard_band_px));
        const size_t n = t.pixelCount();
        for (uint32_t l = 0; l < t.layer_count; ++l) {
            float* c = b.image(layerName(l) + " colour", "colour times coverage",
                               StageImageKind::Color, t.width, t.height, 4);
            for (size_t i = 0; i < n; ++i)
                storePremultiplied(t.color.load(size_t(l) * n + i), c + 4 * i);
        }
        for (uint32_t l = 0; l < t.layer_count; ++l)
            distanceImage(b, layerName(l) + " depth", "distance of the layer's surface", pin,
                          t.depth, size_t(l) * n, t.width, t.height);
        b.send(observer);
    }
    if (traced) {
        StageBuilder b("multiview.nbuffer", "multiview", "N-buffers",
                       "Lee, Eisemann & Seidel 2009, §4.3 (Décoret 2005)",
                       "Per layer, an N-buffer of its depth: level n holds the nearest depth in "
                       "the 2^n × 2^n window at each pixel, so the nearest depth of any square "
                       "takes four lookups. The tracer asks it whether a layer holds anything a "
                       "ray segment can reach, and skips the layer when not.");
        b.ms(stageMs(report, "nbuffer"));
        b.count("levels", double(st.nbuffer_levels));
        b.count("layer_culled_pixel", double(st.layer_culled_pixel));
        b.count("layer_culled_tile", double(st.layer_culled_tile));
        b.count("layer_culled_ray", double(st.layer_culled_ray));
        const std::vector<NBuffer>& nbs = multiview_scratch_.nbuffers;
        for (size_t l = 0; l < nbs.size(); ++l)
            for (uint32_t n = 0; n < nbs[l].levelCount(); ++n) {
                float* d = b.image(layerName(uint32_t(l)) + " level " + std::to_string(n),
                                   "nearest distance in the 2^" + std::to_string(n) +
                                       " window at each pixel",
                                   StageImageKind::Distance, nbs[l].width, nbs[l].height, 1);
                const std::vector<float>& src = nbs[l].levels[n];
                for (size_t i = 0; i < src.size(); ++i)
                    d[i] = distanceOf(pin, src[i]);
            }
        b.send(observer);
    }
    if (traced) {
        StageBuilder b("multiview.mipmaps", "multiview", "Coverage mipmaps",
                       "Lee, Eisemann & Seidel 2009, §4.4",
                       "Per layer, a mipmap of premultiplied colour with coverage in alpha. A "
                       "ray that hits a layer reads it at the level matching its cone (the "
                       "footprint of the lens area the ray stands for, λ), and a partial "
                       "coverage lets the rest of the ray continue behind.");
        b.ms(stageMs(report, "mipmaps"));
        b.count("mip_levels", double(st.mip_levels));
        b.count("cone_partial", double(st.cone_partial));
        b.count("cone_missed", double(st.cone_missed));
        const MultiviewScratch& s = multiview_scratch_;
        std::vector<float> level; // the whole level: the rows it does not store are 0
        for (size_t l = 0; l < s.mips.size(); ++l)
            for (size_t n = 0; n < s.mips[l].size() && n < s.mip_width.size(); ++n)
                if (!s.mips[l][n].empty()) {
                    level.assign(size_t(s.mip_width[n]) * s.mip_height[n] * 4, 0.0f);
                    std::copy(s.mips[l][n].begin(), s.mips[l][n].end(),
                              level.begin() +
                                  ptrdiff_t(size_t(s.mip_row0[l][n]) * s.mip_width[n] * 4));
                    b.color(layerName(uint32_t(l)) + " level " + std::to_string(n),
                            "premultiplied RGBA, alpha = coverage", level.data(), s.mip_width[n],
                            s.mip_height[n], 1u << n);
                }
        b.send(observer);
    }
    {
        StageBuilder b("multiview.lens", "multiview", "Lens samples and cells",
                       "Lee, Eisemann & Seidel 2009, §4.4–4.5",
                       "The N lens samples every pixel traces (rotated per pixel by a hash of "
                       "its position, §4.5), and the centroid of each sample's cell of the "
                       "aperture: the cone a ray stands for covers its cell, of mean size λ.");
        b.count("samples", double(m.samples->size()));
        b.count("lambda", double(st.lambda));
        StagePoints& p = b.points("lens samples", "u", "v");
        for (const LensSample& s : m.samples->samples())
            p.points.push_back(s.position);
        const std::vector<glm::vec2> cells = lensCellOffsets(*m.samples);
        if (!cells.empty()) {
            StagePoints& c = b.points("cell centroids", "u", "v");
            for (size_t i = 0; i < cells.size(); ++i)
                c.points.push_back(m.samples->sample(uint32_t(i)).position + cells[i]);
        }
        b.send(observer);
    }
    {
        StageBuilder b("multiview.tracing", "multiview", "Tracing lens rays",
                       "Lee, Eisemann & Seidel 2009, §4.3–4.4",
                       "Each pixel sends N rays, one per lens sample, straight lines in (x, y, "
                       "C). A ray walks the layers front to back; in each it searches the "
                       "height field for the first crossing (false position, then a few "
                       "bisection steps), and the first hit, read through its cone, ends it. "
                       "The pixel is the weighted mean of its rays.");
        b.ms(stageMs(report, "tracing"));
        b.count("rays", double(st.rays));
        b.count("pixels_in_focus", double(st.pixels_in_focus));
        b.count("rays_background", double(st.rays_background));
        b.count("rays_discarded", double(st.rays_discarded));
        b.count("layer_steps", double(st.layer_steps));
        b.count("layer_tests", double(st.layer_tests));
        b.count("texel_fetches", double(st.texel_fetches));
        b.color("result", "linear RGBA", rgba_.data(), w, h);
        b.send(observer);
    }
}

void FrameRenderer::multilayerStages(const raster::View& pin, const FrameReport& report,
                                     FrameObserver& observer) {
    const MultilayerStats& st = std::get<MultilayerStats>(report.method_stats);
    const uint32_t w = pin.width, h = pin.height;
    const raster::FragmentLists& lists = multilayer_.lists();
    {
        StageBuilder b("multilayer.collect", "multilayer", "Collected fragment lists",
                       "Selgrad et al. 2015, §4",
                       "The scene is rendered once into per-pixel fragment lists; each list is "
                       "sorted by depth and only the closest N fragments are kept (fragments "
                       "hidden behind an opaque one can be skipped first). These lists are "
                       "level 0 of the filtering.");
        b.ms(st.ms_collect);
        b.count("fragments_collected", double(st.fragments_collected));
        b.count("fragments_rejected", double(st.fragments_rejected));
        b.count("fragments_hidden", double(st.fragments_hidden));
        b.count("fragments_kept", double(st.fragments_kept));
        b.count("max_list_length", double(st.max_list_length));
        float* n = b.image("kept per pixel", "fragments kept in each pixel's list",
                           StageImageKind::Count, w, h, 1);
        for (size_t i = 0; i < size_t(w) * h && i + 1 < lists.offsets.size(); ++i)
            n[i] = float(lists.count(i));
        float* all = b.image("appended per pixel", "fragments appended before the cap",
                             StageImageKind::Count, w, h, 1);
        for (size_t i = 0; i < size_t(w) * h && i < lists.list_length.size(); ++i)
            all[i] = float(lists.list_length[i]);
        b.send(observer);
    }
    {
        StageBuilder b("multilayer.levels", "multilayer", "Filtered levels",
                       "Selgrad et al. 2015, §5 (Fig. 7)",
                       "The lists are filtered into levels of growing blur: mip levels merge "
                       "2×2 lists at half resolution (§5.1), stack levels widen the box "
                       "without downsampling (§5.2), aperture levels weight taps by the "
                       "aperture's shape. The pictures are each level's contribution to the "
                       "final image, as in the paper's Fig. 7, and the background's share.");
        b.ms(st.ms_filter);
        b.count("mip_levels", double(st.mip_levels));
        b.count("stack_levels", double(st.stack_levels));
        b.count("max_coc_px", double(st.max_coc_px));
        const MultilayerImage& img = multilayer_image_;
        for (size_t s = 0; s < img.level_rgba.size(); ++s)
            b.color(s + 1 == img.level_rgba.size() ? "background" : "level " + std::to_string(s),
                    "premultiplied RGB this level adds; A = its share of the coverage",
                    img.level_rgba[s].data(), w, h);
        StageTable& tab =
            b.table("levels", {"level", "width", "height", "fragments", "max list", "truncated"});
        for (const FragmentLevel& l : multilayer_.levels())
            tab.rows.push_back({double(l.index), double(l.width), double(l.height),
                                double(l.fragments), double(l.max_list_length),
                                double(l.truncated)});
        b.send(observer);
    }
    {
        StageBuilder b("multilayer.borders", "multilayer", "The border table T",
                       "Selgrad et al. 2015, §6.1",
                       "T maps depth to the pair of levels whose blur matches the circle of "
                       "confusion there: level S matches radius r_S, and depths between its "
                       "borders z_N,S and z_F,S blend levels S and S+1 with weight t(d) from "
                       "the variances (m2·C(d)² − V_lo) / (V_hi − V_lo).");
        b.count("second_moment", st.second_moment);
        b.count("asymmetric_aperture", st.asymmetric_aperture ? 1.0 : 0.0);
        StageTable& tab = b.table("T", {"S", "level", "radius px", "z_near", "z_far"});
        for (const MultilayerTraversalStats& t : st.traversal)
            tab.rows.push_back(
                {double(t.index), double(t.level), t.radius_px, double(t.z_near), double(t.z_far)});
        b.send(observer);
    }
    {
        StageBuilder b("multilayer.accumulate", "multilayer", "Traversal and blending",
                       "Selgrad et al. 2015, §6.1",
                       "Each pixel walks depth from near to far through T's segments, reads "
                       "the fragments of the two levels the segment blends, and composites "
                       "them front to back with their coverage, then adds the background for "
                       "what is left.");
        b.ms(st.ms_accumulate);
        b.count("slices_blended", double(st.slices_blended));
        b.color("result", "linear RGBA", multilayer_image_.rgba.data(), w, h);
        b.send(observer);
    }
}

} // namespace dof
