#include "out_of_memory.h"

#include <dof/multilayer.h>
#include <raster/check.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <new>
#include <string>

namespace dof {
namespace {

double msSince(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

using AxisTap = Multilayer::AxisTap;

// The cells [lo, hi] that taps with a weight > 0 read along one axis.
void readRange(const std::vector<AxisTap>& taps, uint32_t& lo, uint32_t& hi) {
    lo = std::numeric_limits<uint32_t>::max();
    hi = 0;
    for (const AxisTap& t : taps) {
        if (1.0f - t.f > 0.0f)
            lo = std::min(lo, t.i0), hi = std::max(hi, t.i0);
        if (t.f > 0.0f)
            lo = std::min(lo, t.i1), hi = std::max(hi, t.i1);
    }
}

// The bilinear taps of one level along one axis for every pixel (into `taps`, kept).
void axisTaps(uint32_t pixels, float origin, float spacing, uint32_t cells,
              std::vector<AxisTap>& taps) {
    taps.resize(pixels);
    const int64_t last = int64_t(cells) - 1;
    for (uint32_t p = 0; p < pixels; ++p) {
        const double u = (double(p) + 0.5 - double(origin)) / double(spacing);
        const double fl = std::floor(u);
        const int64_t i = int64_t(fl);
        taps[p].i0 = uint32_t(std::clamp<int64_t>(i, 0, last));
        taps[p].i1 = uint32_t(std::clamp<int64_t>(i + 1, 0, last));
        taps[p].f = float(u - fl);
    }
}

// A list being traversed: its next fragment, its end, the bilinear weight, and the next
// fragment's depth (+inf at the end: one compare tests both, as a sentinel would).
struct Cursor {
    const LayerFragment* next = nullptr;
    const LayerFragment* end = nullptr;
    float weight = 0.0f;
    float depth = 0.0f;

    void advance() {
        ++next;
        depth = next != end ? next->depth : std::numeric_limits<float>::infinity();
    }
};

// The rows of cells a level's bilinear taps read on one row of pixels: cell row j0 with weight
// 1 - f, then j1 with weight f, each kept only with a weight > 0 and fragments in it.
struct TapRows {
    uint32_t count = 0;
    uint32_t cell_row[2] = {};      // j0 or j1
    const uint32_t* starts[2] = {}; // the row's list starts (FragmentLevel::starts)
    const LayerFragment* data[2] = {};
    float weight[2] = {};
    bool pieces = false; // a filtered level (shareInList)
};

TapRows tapRows(const FragmentLevel& level, const AxisTap& ay) {
    TapRows t;
    t.pieces = level.kind != LevelKind::Base;
    const uint32_t cy[2] = {ay.i0, ay.i1};
    const float wy[2] = {1.0f - ay.f, ay.f};
    for (int r = 0; r < 2; ++r) {
        if (!(wy[r] > 0.0f) || level.rows[cy[r]].empty())
            continue;
        t.cell_row[t.count] = cy[r];
        t.starts[t.count] = level.starts.data() + size_t(cy[r]) * (level.width + 1);
        t.data[t.count] = level.rows[cy[r]].data();
        t.weight[t.count] = wy[r];
        ++t.count;
    }
    return t;
}

constexpr float kOpaque = 1.0f - 1.0f / 1024.0f; // stop once the pixel is this opaque

using Plan = Multilayer::Plan;

// What every pixel's traversal (§6.1) reads, set up once per frame from the kept state: by the
// render and by probe() alike. Points into the Multilayer it was made from.
struct TraversalFrame {
    const FragmentLevel* tlevel[2][kMaxTraversalLevels] = {}; // the levels of T, [near, far]
    uint32_t n = 0;                                           // T holds levels 0..n
    uint32_t sides = 1; // 2: the near and far sides read their own aperture levels
    const Multilayer::Traversal* st = nullptr;
    const LevelBorders* borders = nullptr;

    uint32_t sideOf(const LevelBorders::Segment& seg) const {
        return sides == 2 && seg.begin >= st->lens.focus_distance ? 1u : 0u;
    }
};

TraversalFrame traversalFrame(const Plan& plan, const std::vector<FragmentLevel>& levels,
                              const std::vector<FragmentLevel>& apertures,
                              const LevelBorders& borders, const Multilayer::Traversal& st) {
    TraversalFrame tf;
    tf.n = uint32_t(plan.traversal.size()) - 1;
    FOCAL_CHECK(tf.n + 1 <= kMaxTraversalLevels);
    tf.sides = st.asymmetric ? 2 : 1;
    tf.st = &st;
    tf.borders = &borders;
    // Near-side aperture levels follow the far side's when the aperture is asymmetric.
    const size_t shaped_count = plan.apertures.size();
    for (uint32_t s = 0; s <= tf.n; ++s) {
        const Plan::Entry& e = plan.traversal[s];
        tf.tlevel[1][s] = e.aperture ? &apertures[e.level] : &levels[e.level];
        tf.tlevel[0][s] =
            e.aperture && st.asymmetric ? &apertures[shaped_count + e.level] : tf.tlevel[1][s];
    }
    return tf;
}

// The rows of cells every level's bilinear taps read on row y of pixels.
void rowTaps(const TraversalFrame& tf, uint32_t y, TapRows (&rows)[2][kMaxTraversalLevels]) {
    for (uint32_t side = 0; side < tf.sides; ++side)
        for (uint32_t s = 0; s <= tf.n; ++s)
            rows[side][s] = tapRows(*tf.tlevel[side][s], tf.st->ty[s][y]);
}

// The cursors of one pixel's taps, per side and level of T: working memory a row's task reuses
// for its pixels (not initialised per pixel: traversePixel sets what it reads). `closest` is the
// smallest next depth among a level's cursors (+inf when it has none left): a segment whose
// levels have nothing closer than its end is passed with two compares, not a scan of the taps.
struct PixelCursors {
    Cursor cursors[2][kMaxTraversalLevels][4];
    uint32_t count[2][kMaxTraversalLevels];
    float closest[2][kMaxTraversalLevels];
};

// The smallest next depth among `count` cursors (+inf for none).
float closestOf(const Cursor* cur, uint32_t count) {
    float d = std::numeric_limits<float>::infinity();
    for (uint32_t k = 0; k < count; ++k)
        d = std::min(d, cur[k].depth);
    return d;
}

// The render's recorder: records nothing (every call compiles away).
struct NoRecorder {
    void tap(uint32_t, uint32_t, uint32_t, uint32_t, uint32_t, const LayerFragment*, float) {}
    void skip(uint32_t, uint32_t, uint32_t, uint32_t, const LayerFragment&) {}
    void read(uint32_t, uint32_t, uint32_t, uint32_t, const LayerFragment&, float, float) {}
    void slice(uint32_t, const LevelBorders::Segment&, float, float, float, const float (&)[2][4],
               bool, bool, float, float, float) {}
    void done(float, float) {}
};

// §6.1 for pixel x of the row whose taps are `rows`: traverse T near to far and blend the slices
// met front to back into `out` (RGBA, alpha 1); with `level_rgba`, add each level's share at
// pixel index p. Returns the slices blended. `rec` sees every tap (side, level, tap index, cell,
// first fragment, bilinear weight), every fragment skipped or read (side, level, tap, segment,
// fragment[, level weight, share]), every slice and the final coverage.
template <class Recorder>
uint64_t traversePixel(const TraversalFrame& tf, const TapRows (&rows)[2][kMaxTraversalLevels],
                       PixelCursors& pc, uint32_t x, float* out,
                       std::vector<std::vector<float>>* level_rgba, size_t p, Recorder& rec) {
    const Multilayer::Traversal& st = *tf.st;
    const std::vector<LevelBorders::Segment>& segments = st.segments;
    // Bilinear taps of every level at the pixel centre, in the order (i0, j0), (i1, j0),
    // (i0, j1), (i1, j1); taps with weight 0 or an empty list are left out, since they add w·0
    // to every slice.
    Cursor(&cursors)[2][kMaxTraversalLevels][4] = pc.cursors;
    uint32_t(&cursor_count)[2][kMaxTraversalLevels] = pc.count;
    float(&closest)[2][kMaxTraversalLevels] = pc.closest;
    for (uint32_t side = 0; side < tf.sides; ++side)
        for (uint32_t s = 0; s <= tf.n; ++s) {
            const TapRows& tr = rows[side][s];
            if (tr.count == 0) {
                cursor_count[side][s] = 0;
                closest[side][s] = std::numeric_limits<float>::infinity();
                continue;
            }
            const AxisTap ax = st.tx[s][x];
            const uint32_t cx[2] = {ax.i0, ax.i1};
            const float wx[2] = {1.0f - ax.f, ax.f};
            Cursor* cur = cursors[side][s];
            uint32_t c = 0;
            for (uint32_t r = 0; r < tr.count; ++r)
                for (int k = 0; k < 2; ++k) {
                    const float w = wx[k] * tr.weight[r];
                    const uint32_t first = tr.starts[r][cx[k]];
                    const uint32_t last = tr.starts[r][cx[k] + 1];
                    if (!(w > 0.0f) || last == first)
                        continue;
                    cur[c] = {tr.data[r] + first, tr.data[r] + last, w, tr.data[r][first].depth};
                    rec.tap(side, s, c, cx[k], tr.cell_row[r], cur[c].next, w);
                    ++c;
                }
            cursor_count[side][s] = c;
            closest[side][s] = closestOf(cur, c);
        }
    float cr = 0.0f, cg = 0.0f, cb = 0.0f, ca = 0.0f;
    float ca_g = 0.0f, ga = 0.0f, last_d = 0.0f;
    bool first = true;
    uint64_t slices = 0;
    for (uint32_t si = 0; si < segments.size(); ++si) {
        if (ca >= kOpaque)
            break;
        const uint32_t side = st.seg_side[si];
        const LevelBorders::Segment& seg = segments[si];
        float* closest_side = closest[side];
        if (!(std::min(closest_side[seg.lo], closest_side[seg.hi]) < seg.end))
            continue; // nothing to read in this segment
        Cursor(&cur_side)[kMaxTraversalLevels][4] = cursors[side];
        const uint32_t* count_side = cursor_count[side];
        const uint32_t lv[2] = {seg.lo, seg.hi};
        const uint32_t classes = seg.hi == seg.lo ? 1 : 2;
        while (ca < kOpaque) {
            // The closest fragment in the segment over both levels' taps, after skipping what
            // lies in front of the segment (not asked of this level there; only a level whose
            // cursors last moved in an earlier segment has any, since cursors only advance).
            float d0 = seg.end;
            bool any = false;
            for (uint32_t c = 0; c < classes; ++c) {
                if (closest_side[lv[c]] < seg.begin) {
                    for (uint32_t k = 0; k < count_side[lv[c]]; ++k) {
                        Cursor& cur = cur_side[lv[c]][k];
                        while (cur.depth < seg.begin) {
                            rec.skip(side, lv[c], k, si, *cur.next);
                            cur.advance();
                        }
                    }
                    closest_side[lv[c]] = closestOf(cur_side[lv[c]], count_side[lv[c]]);
                }
                if (closest_side[lv[c]] < d0)
                    d0 = closest_side[lv[c]], any = true;
            }
            if (!any)
                break;
            // One slice: the §5.1 merge across taps and the two levels, weighted by the
            // bilinear weights and the level interpolation t(d0).
            const float limit = std::min(d0 * st.scale, st.seg_last[si]);
            const float t = levelBlend(*tf.borders, st.lens, seg, d0);
            float part[2][4] = {{0.0f, 0.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 0.0f, 0.0f}};
            for (uint32_t c = 0; c < classes; ++c) {
                const float level_weight = classes == 1 ? 1.0f : (c == 0 ? 1.0f - t : t);
                const bool pieces = rows[side][lv[c]].pieces;
                for (uint32_t k = 0; k < count_side[lv[c]]; ++k) {
                    Cursor& cur = cur_side[lv[c]][k];
                    float pr = 0.0f, pg = 0.0f, pb = 0.0f, pa = 0.0f;
                    for (; cur.depth <= limit; cur.advance()) {
                        const LayerFragment& f = *cur.next;
                        const float tr = shareInList(f, pieces, pa);
                        pr += tr * f.r, pg += tr * f.g, pb += tr * f.b, pa += tr * f.a;
                        rec.read(side, lv[c], k, si, f, level_weight, tr);
                    }
                    const float w = level_weight * cur.weight;
                    part[c][0] += w * pr, part[c][1] += w * pg, part[c][2] += w * pb;
                    part[c][3] += w * pa;
                }
                closest_side[lv[c]] = closestOf(cur_side[lv[c]], count_side[lv[c]]);
            }
            const float sa = part[0][3] + part[1][3];
            if (!(sa > 0.0f)) {
                rec.slice(si, seg, d0, limit, t, part, false, false, 0.0f, 0.0f, ca);
                continue;
            }
            ++slices;
            // Front-to-back blending of the slice (§6.1): additive within a group of slices
            // (disjoint pieces of one layer, §7), the over operator between groups (layers at
            // clearly different depths, whose holes the lens sees independently).
            const bool new_group = first || !(d0 <= last_d * st.group_scale);
            if (new_group) {
                ca_g = ca;
                ga = 0.0f;
            }
            first = false;
            last_d = d0;
            const float take = std::min(sa, 1.0f - ga);
            const float k = (1.0f - ca_g) * take / sa;
            ga += take;
            cr += k * (part[0][0] + part[1][0]);
            cg += k * (part[0][1] + part[1][1]);
            cb += k * (part[0][2] + part[1][2]);
            ca = ca_g + (1.0f - ca_g) * ga;
            rec.slice(si, seg, d0, limit, t, part, true, new_group, take, k, ca);
            if (level_rgba)
                for (uint32_t c = 0; c < classes; ++c) {
                    float* o = (*level_rgba)[lv[c]].data() + 4 * p;
                    for (int i = 0; i < 4; ++i)
                        o[i] += k * part[c][i];
                }
        }
    }
    ca = std::min(ca, 1.0f);
    const float rest = 1.0f - ca;
    const glm::vec3 background = st.background;
    out[0] = cr + rest * background.r;
    out[1] = cg + rest * background.g;
    out[2] = cb + rest * background.b;
    out[3] = 1.0f;
    rec.done(ca, rest);
    if (level_rgba) {
        float* bg = (*level_rgba)[tf.n + 1].data() + 4 * p;
        bg[0] = rest * background.r, bg[1] = rest * background.g;
        bg[2] = rest * background.b, bg[3] = rest;
    }
    return slices;
}

// r_S of level s of T: the |C| whose aperture variance m2·C² is the level's (§6.1).
double radius(const Plan& p, size_t s, double m2) {
    return std::sqrt(p.variance[s] / m2);
}

// The planned levels hold up to N fragments per cell (N = fragments_per_pixel, 16 when all are
// kept): an estimate of what filtering them takes, checked before any level is allocated.
raster::Status checkLevelMemory(const Plan& plan, const MultilayerSettings& settings,
                                float max_coc) {
    uint64_t cells = 0;
    for (const std::vector<FragmentLevel>* levels : {&plan.boxes, &plan.apertures})
        for (const FragmentLevel& l : *levels)
            cells = raster::addBytes(cells, uint64_t{l.width} * l.height);
    const uint64_t per_cell =
        sizeof(uint32_t) +
        uint64_t{settings.fragments_per_pixel == 0 ? 16u : settings.fragments_per_pixel} *
            sizeof(LayerFragment);
    char what[160];
    std::snprintf(what, sizeof(what),
                  "multilayer: %zu filter levels for a CoC of up to %.0f px (%llu cells)",
                  plan.boxes.size() + plan.apertures.size(), double(max_coc),
                  static_cast<unsigned long long>(cells));
    return raster::checkMemory(settings.memory_budget, what, raster::mulBytes(cells, per_cell));
}

// T over the boxes: the boxes themselves, or box 0 and then the aperture levels of box 0, 1, ...
// (one per grid of settings.aperture_grids), each kept only if it blurs more than the previous
// one, up to the first whose radius reaches the largest |C| of the frame.
void planTraversal(Plan& p, uint32_t width, uint32_t height, const MultilayerSettings& settings,
                   const std::vector<ApertureGrid>& grids, double m2, float max_coc_px) {
    p.apertures.clear();
    p.traversal.clear();
    p.variance.clear();
    if (settings.filter == LevelFilter::Box) {
        for (uint32_t s = 0; s < p.boxes.size(); ++s) {
            p.traversal.push_back({false, s});
            p.variance.push_back(p.boxes[s].variance());
        }
        return;
    }
    p.traversal.push_back({false, 0});
    p.variance.push_back(p.boxes[0].variance());
    for (const FragmentLevel& box : p.boxes)
        for (const ApertureGrid& grid : grids) {
            if (radius(p, p.variance.size() - 1, m2) >= double(max_coc_px))
                return;
            FragmentLevel a =
                planApertureLevel(box, grid, uint32_t(p.traversal.size()), width, height);
            if (!(a.variance() > p.variance.back()))
                continue;
            p.traversal.push_back({true, uint32_t(p.apertures.size())});
            p.variance.push_back(a.variance());
            p.apertures.push_back(std::move(a));
        }
}

// The frame's plan into `p`, reusing its memory.
void makePlan(uint32_t width, uint32_t height, const MultilayerSettings& settings,
              const std::vector<ApertureGrid>& grids, double m2, float max_coc_px, Plan& p) {
    p.plan = LevelPlan{};
    p.plan.mip_steps = settings.mip_levels;
    p.plan.epsilon = settings.epsilon;
    p.plan.truncate = settings.truncate;
    p.plan.mean_depth = settings.mean_depth;
    if (settings.stack_levels >= 0) {
        p.plan.stack_steps = uint32_t(settings.stack_levels);
        planLevels(width, height, p.plan, p.boxes);
        planTraversal(p, width, height, settings, grids, m2, max_coc_px);
        return;
    }
    // Auto: the fewest stack steps whose top level of T matches the largest |C| in the frame.
    for (uint32_t stack = 0;; ++stack) {
        p.plan.stack_steps = stack;
        planLevels(width, height, p.plan, p.boxes);
        planTraversal(p, width, height, settings, grids, m2, max_coc_px);
        if (radius(p, p.variance.size() - 1, m2) >= double(max_coc_px) ||
            p.plan.levels() >= kMaxFilterLevels)
            return;
    }
}

// The first level of T that reads box `box` or a box above it (T.size() if none does): box
// levels are truncated by its lower border (§6.2), since T's borders nest outwards.
uint32_t firstReader(const Plan& p, uint32_t box) {
    for (uint32_t s = 0; s < p.traversal.size(); ++s) {
        const Plan::Entry& e = p.traversal[s];
        if ((e.aperture ? p.apertures[e.level].source : e.level) >= box)
            return s;
    }
    return uint32_t(p.traversal.size());
}

// Gives `level` the geometry of `geometry` (from planLevels or planApertureLevel) and keeps its
// rows' memory, so that a warm Multilayer does not reallocate them.
void adoptGeometry(const FragmentLevel& geometry, FragmentLevel& level) {
    std::vector<std::vector<LayerFragment>> rows = std::move(level.rows);
    std::vector<uint32_t> starts = std::move(level.starts);
    FragmentLevel::Scratch scratch = std::move(level.scratch);
    level = geometry;
    level.rows = std::move(rows);
    level.starts = std::move(starts);
    level.scratch = std::move(scratch);
}

MultilayerLevelStats levelStats(const FragmentLevel& l) {
    MultilayerLevelStats ls;
    ls.index = l.index;
    ls.kind = l.kind;
    ls.width = l.width;
    ls.height = l.height;
    ls.dilation = l.dilation;
    ls.source = l.source;
    ls.grid = l.grid;
    ls.fragments = l.fragments;
    ls.max_list_length = l.max_list_length;
    ls.mean_list_length = double(l.fragments) / (double(l.width) * double(l.height));
    ls.truncated = l.truncated;
    ls.cells_skipped = l.skipped;
    return ls;
}

} // namespace

raster::Status Multilayer::outOfMemory(const raster::View& view) noexcept {
    // The kept buffers may be half resized: give them back (moves of empty buffers, which
    // allocate nothing), so that the next frame starts as a first one does.
    *this = Multilayer{};
    return detail::outOfMemoryWhile([&] {
        return "rendering multilayer at " + std::to_string(view.width) + "x" +
               std::to_string(view.height);
    });
}

raster::Status Multilayer::render(const raster::View& view, const ThinLens& lens,
                                  glm::vec3 background, const MultilayerSettings& settings,
                                  const CollectFn& collect, raster::TaskPool& pool,
                                  MultilayerImage& out, MultilayerStats* stats) try {
    if (raster::Status s = validate(settings); !s.ok())
        return s;
    if (raster::Status s = validate(lens, view); !s.ok())
        return s;
    if (!collect)
        return raster::Status::error("multilayer: no fragment-list collector");
    // §4: collect, sort, keep the closest N, compact.
    raster::FragmentListDesc desc;
    desc.node_capacity = settings.node_capacity;
    desc.max_per_pixel = settings.fragments_per_pixel;
    // Hidden fragments only matter when they compete for the N slots.
    const bool skip_hidden = settings.skip_hidden && settings.fragments_per_pixel > 0;
    desc.hidden_epsilon = skip_hidden ? settings.epsilon : 0.0f;
    desc.color_format = settings.color_format;
    desc.depth_format = settings.depth_format;
    desc.on_overflow = raster::OverflowPolicy::Grow;
    traversal_.ready = false; // the collection replaces lists_
    const auto t0 = std::chrono::steady_clock::now();
    if (raster::Status s = collect(desc, lists_); !s.ok())
        return s;
    const double ms_lists = msSince(t0);
    if (lists_.width != view.width || lists_.height != view.height)
        return raster::Status::error("multilayer: the collected lists do not match the view");
    raster::Status s = renderFromLists(lists_, view, lens, background, settings, pool, out, stats);
    if (s.ok() && stats)
        stats->ms_collect += ms_lists;
    return s;
} catch (const std::bad_alloc&) {
    return outOfMemory(view);
}

raster::Status Multilayer::renderFromLists(const raster::FragmentLists& lists,
                                           const raster::View& view, const ThinLens& lens,
                                           glm::vec3 background, const MultilayerSettings& settings,
                                           raster::TaskPool& pool, MultilayerImage& out,
                                           MultilayerStats* stats) try {
    if (raster::Status s = validate(settings); !s.ok())
        return s;
    if (raster::Status s = validate(lens, view); !s.ok())
        return s;
    const uint32_t width = lists.width;
    const uint32_t height = lists.height;
    if (width == 0 || height == 0 || lists.offsets.size() != size_t(width) * height + 1)
        return raster::Status::error("multilayer: empty or malformed fragment lists");
    Multilayer::Traversal& trav = traversal_;
    trav.ready = false; // until this frame is complete

    // Level 0 (§4): premultiplied colour, view distance.
    auto t0 = std::chrono::steady_clock::now();
    if (levels_.empty())
        levels_.resize(1);
    makeBaseLevel(lists, view, pool, levels_[0]);
    std::vector<float>& row_min = row_min_;
    std::vector<float>& row_max = row_max_;
    row_min.assign(height, std::numeric_limits<float>::infinity());
    row_max.assign(height, 0.0f);
    pool.parallelFor(height, [&](uint32_t y, uint32_t) {
        float lo = row_min[y], hi = row_max[y]; // stored once: neighbouring rows share lines
        for (const LayerFragment& f : levels_[0].rows[y]) {
            lo = std::min(lo, f.depth);
            hi = std::max(hi, f.depth);
        }
        row_min[y] = lo;
        row_max[y] = hi;
    });
    float max_coc = 0.0f;
    for (uint32_t y = 0; y < height; ++y)
        if (row_max[y] > 0.0f)
            max_coc = std::max({max_coc, std::fabs(cocRadiusPx(lens, row_min[y])),
                                std::fabs(cocRadiusPx(lens, row_max[y]))});
    const double ms_base = msSince(t0);

    // The aperture drawn on the tap grids, for both sides of the focal plane (timed with the
    // filter stage, which they belong to).
    t0 = std::chrono::steady_clock::now();
    const bool shaped = settings.filter == LevelFilter::Aperture;
    std::vector<ApertureGrid>(&grids)[2] = grids_; // [far, near], one per aperture_grids
    double m2 = settings.aperture_second_moment;
    bool asymmetric = false;
    if (shaped) {
        // The grids are a pure function of the shape and the sizes: the last frame's are kept.
        const ApertureShape& a = settings.aperture;
        const ApertureShape& b = grid_shape_;
        const bool same = !grids_[0].empty() && grid_sizes_ == settings.aperture_grids &&
                          a.kind == b.kind && a.blades == b.blades &&
                          a.rotation_deg == b.rotation_deg && a.mask.width == b.mask.width &&
                          a.mask.height == b.mask.height &&
                          a.mask.transmission == b.mask.transmission;
        if (!same) {
            grids[0].clear();
            grids[1].clear();
            // One set of samples for every grid: making it costs more than binning it.
            raster::Result<LensSampleSet> samples = apertureGridSamples(settings.aperture);
            if (!samples.ok())
                return raster::Status::error("multilayer: " + samples.status().message());
            for (uint32_t size : settings.aperture_grids)
                for (FocalSide side : {FocalSide::Far, FocalSide::Near}) {
                    raster::Result<ApertureGrid> r =
                        apertureGrid(*samples, settings.aperture, size, side);
                    if (!r.ok()) {
                        grids[0].clear();
                        return raster::Status::error("multilayer: " + r.status().message());
                    }
                    grids[side == FocalSide::Far ? 0 : 1].push_back(std::move(*r));
                }
            grid_shape_ = settings.aperture;
            grid_sizes_ = settings.aperture_grids;
            grid_m2_ = grids[0][0].second_moment;
            grid_asymmetric_ = false;
            for (size_t g = 0; g < grids[0].size(); ++g)
                grid_asymmetric_ = grid_asymmetric_ || !sameWeights(grids[0][g], grids[1][g]);
        }
        m2 = grid_m2_;
        asymmetric = grid_asymmetric_;
    }

    // §5: plan the Y-map and T, compute the border table (§6.1).
    Plan& plan = plan_;
    makePlan(width, height, settings, grids[0], m2, max_coc, plan);
    if (raster::Status s = checkLevelMemory(plan, settings, max_coc); !s.ok())
        return s;
    levelBorders(lens, plan.variance, m2, borders_);
    // Box levels up to the highest one T reads (all of them with box levels), then the
    // aperture levels, far side then (asymmetric aperture) near side.
    uint32_t boxes_needed = uint32_t(plan.boxes.size());
    if (shaped)
        boxes_needed = plan.apertures.empty() ? 1u : plan.apertures.back().source + 1u;
    levels_.resize(boxes_needed);
    for (uint32_t s = 1; s < boxes_needed; ++s)
        adoptGeometry(plan.boxes[s], levels_[s]);
    const size_t shaped_count = plan.apertures.size();
    apertures_.resize(asymmetric ? 2 * shaped_count : shaped_count);
    for (size_t a = 0; a < apertures_.size(); ++a)
        adoptGeometry(plan.apertures[a % shaped_count], apertures_[a]);

    // The levels of T on each side of the focal plane ([near, far]), and what the traversal
    // reads besides them (kept for probe()).
    trav.own_lists = &lists == &lists_;
    trav.view = view;
    trav.lens = lens;
    trav.background = background;
    trav.scale = 1.0f + settings.epsilon;
    // Slices join the group of the previous one while within this factor of its depth.
    trav.group_scale = settings.blend == LayerBlend::Additive ? 1.0f + settings.additive_gap : 0.0f;
    trav.asymmetric = asymmetric;
    const TraversalFrame tf = traversalFrame(plan, levels_, apertures_, borders_, trav);
    const uint32_t n = tf.n;
    const auto& tlevel = tf.tlevel;
    // T as segments; with an asymmetric aperture the one across the focal plane is split there,
    // so that every slice reads the levels of its own side.
    std::vector<LevelBorders::Segment>& segments = trav.segments;
    segments.clear();
    for (const LevelBorders::Segment& seg : borders_.segments) {
        if (asymmetric && seg.begin < lens.focus_distance && seg.end > lens.focus_distance) {
            segments.push_back({seg.begin, lens.focus_distance, seg.lo, seg.hi});
            segments.push_back({lens.focus_distance, seg.end, seg.lo, seg.hi});
        } else {
            segments.push_back(seg);
        }
    }
    // The bilinear taps of every level of T at the pixel centres (§6.1).
    std::vector<std::vector<AxisTap>>& tx = trav.tx;
    std::vector<std::vector<AxisTap>>& ty = trav.ty;
    if (tx.size() < n + 1) {
        tx.resize(n + 1);
        ty.resize(n + 1);
    }
    for (uint32_t s = 0; s <= n; ++s) {
        const FragmentLevel& l = *tlevel[1][s];
        axisTaps(width, l.origin_x, l.spacing, l.width, tx[s]);
        axisTaps(height, l.origin_y, l.spacing, l.height, ty[s]);
    }
    // What the traversal reads of a level: the cells its taps reach and the segments of T
    // that read it, merged where they touch.
    const auto readsOf = [&](const FragmentLevel& level, LevelReads& r) {
        r.depths.clear();
        readRange(tx[level.index], r.x0, r.x1);
        readRange(ty[level.index], r.y0, r.y1);
        for (const LevelBorders::Segment& seg : segments) {
            const uint32_t side = tf.sideOf(seg);
            if (tlevel[side][seg.lo] != &level && tlevel[side][seg.hi] != &level)
                continue;
            if (!r.depths.empty() && r.depths.back().end == seg.begin)
                r.depths.back().end = seg.end;
            else
                r.depths.push_back({seg.begin, seg.end});
        }
    };

    // §5: filter level by level.
    for (uint32_t s = 1; s < boxes_needed; ++s)
        filterLevel(levels_[s - 1], plan.plan, borders_, firstReader(plan, s), pool, levels_[s]);
    for (size_t a = 0; a < apertures_.size(); ++a) {
        FragmentLevel& l = apertures_[a];
        const size_t side = a / shaped_count; // 0: far, 1: near
        const auto grid = std::find_if(grids[side].begin(), grids[side].end(),
                                       [&](const ApertureGrid& g) { return g.size == l.grid; });
        readsOf(l, reads_);
        shapeLevel(levels_[l.source], *grid, plan.plan, borders_,
                   settings.skip_unread_cells ? &reads_ : nullptr, pool, l);
    }
    const double ms_filter = msSince(t0);

    // §6.1: traverse T near to far per pixel, blend the slices met front to back.
    t0 = std::chrono::steady_clock::now();
    out.width = width;
    out.height = height;
    // Not cleared: the traversal below writes every pixel's colour and depth.
    out.rgba.resize(size_t(width) * height * 4);
    out.depth.resize(size_t(width) * height);
    const bool contributions = settings.level_contributions;
    if (contributions) {
        out.level_rgba.resize(n + 2);
        for (std::vector<float>& level : out.level_rgba)
            level.assign(size_t(width) * height * 4, 0.0f);
    } else {
        out.level_rgba.clear();
    }
    // Per segment of T: the last depth a slice may reach (below its end) and the side whose
    // levels it reads (looked up, not recomputed, per pixel).
    std::vector<float>& seg_last = trav.seg_last;
    std::vector<uint8_t>& seg_side = trav.seg_side;
    seg_last.resize(segments.size());
    seg_side.resize(segments.size());
    for (size_t i = 0; i < segments.size(); ++i) {
        seg_last[i] = std::nextafter(segments[i].end, 0.0f);
        seg_side[i] = uint8_t(tf.sideOf(segments[i]));
    }
    std::vector<uint64_t>& row_slices = row_slices_;
    row_slices.assign(height, 0);
    pool.parallelFor(height, [&](uint32_t y, uint32_t) {
        // The rows of cells every level's bilinear taps read on this row of pixels: those with
        // a weight > 0 that hold fragments (the others add w·0 to no slice).
        TapRows rows[2][kMaxTraversalLevels];
        rowTaps(tf, y, rows);
        PixelCursors cursors;
        NoRecorder none;
        uint64_t slices = 0; // stored once: neighbouring rows' counts share cache lines
        for (uint32_t x = 0; x < width; ++x) {
            const size_t p = size_t(y) * width + x;
            {
                // The closest collected fragment's depth; +inf where the base list is empty.
                uint32_t count = 0;
                const LayerFragment* base = levels_[0].list(x, y, count);
                out.depth[p] = count > 0 ? base[0].depth : std::numeric_limits<float>::infinity();
            }
            slices += traversePixel(tf, rows, cursors, x, out.rgba.data() + 4 * p,
                                    contributions ? &out.level_rgba : nullptr, p, none);
        }
        row_slices[y] = slices;
    });
    const double ms_accumulate = msSince(t0);

    if (stats) {
        MultilayerStats& st = *stats;
        // Reset, keeping the per-level arrays' memory (a warm caller's stats do not allocate).
        std::vector<MultilayerLevelStats> level_stats = std::move(st.levels);
        std::vector<MultilayerLevelStats> aperture_stats = std::move(st.apertures);
        std::vector<MultilayerTraversalStats> traversal_stats = std::move(st.traversal);
        st = MultilayerStats{};
        st.levels = std::move(level_stats);
        st.apertures = std::move(aperture_stats);
        st.traversal = std::move(traversal_stats);
        st.levels.clear();
        st.apertures.clear();
        st.traversal.clear();
        st.ms_collect = ms_base;
        st.ms_filter = ms_filter;
        st.ms_accumulate = ms_accumulate;
        st.fragments_collected = lists.fragments_collected;
        st.fragments_rejected = lists.fragments_rejected;
        st.fragments_hidden = lists.fragments_hidden;
        st.skipped_hidden = lists.desc.hidden_epsilon > 0.0f;
        st.fragments_kept = lists.fragments_kept;
        st.max_list_length = lists.max_list_length;
        st.node_pool_grew = lists.grew;
        st.mip_levels = plan.plan.mip_steps;
        st.stack_levels = plan.plan.stack_steps;
        st.max_coc_px = max_coc;
        st.second_moment = m2;
        st.asymmetric_aperture = asymmetric;
        for (uint64_t c : row_slices)
            st.slices_blended += c;
        for (const FragmentLevel& l : levels_)
            st.levels.push_back(levelStats(l));
        for (const FragmentLevel& l : apertures_)
            st.apertures.push_back(levelStats(l));
        for (uint32_t s = 0; s <= n; ++s) {
            MultilayerTraversalStats ts;
            ts.index = s;
            ts.kind = tlevel[1][s]->kind;
            ts.level = plan.traversal[s].level;
            ts.radius_px = borders_.radius[s];
            ts.z_near = borders_.z_near[s];
            ts.z_far = borders_.z_far[s];
            st.traversal.push_back(ts);
        }
    }
    trav.ready = true;
    return {};
} catch (const std::bad_alloc&) {
    return outOfMemory(view);
}

namespace {

// probe()'s recorder: the taps, reads and slices of one pixel's traversal into `out`.
struct ProbeRecorder {
    const TraversalFrame& tf;
    MultilayerPixelProbe& out;
    struct Tap {
        uint32_t x = 0, y = 0;
        const LayerFragment* first = nullptr;
        float weight = 0.0f;
    };
    Tap taps[2][kMaxTraversalLevels][4] = {};
    size_t slice_reads = 0; // the first read of the current slice

    void tap(uint32_t side, uint32_t s, uint32_t c, uint32_t cx, uint32_t cy,
             const LayerFragment* first, float w) {
        taps[side][s][c] = {cx, cy, first, w};
    }
    MultilayerProbeRead readOf(uint32_t side, uint32_t s, uint32_t c, uint32_t si,
                               const LayerFragment& f) const {
        const Tap& t = taps[side][s][c];
        MultilayerProbeRead r;
        r.level = s;
        r.kind = tf.tlevel[side][s]->kind;
        r.side = side;
        r.slice = uint32_t(&f - t.first);
        r.x = int32_t(t.x);
        r.y = int32_t(t.y);
        r.segment = si;
        r.blend = uint32_t(out.slices.size());
        r.depth = f.depth;
        r.coc_px = cocRadiusPx(tf.st->lens, f.depth);
        r.tap_weight = t.weight;
        r.rgba[0] = f.r, r.rgba[1] = f.g, r.rgba[2] = f.b, r.rgba[3] = f.a;
        return r;
    }
    void skip(uint32_t side, uint32_t s, uint32_t c, uint32_t si, const LayerFragment& f) {
        out.reads.push_back(readOf(side, s, c, si, f));
    }
    void read(uint32_t side, uint32_t s, uint32_t c, uint32_t si, const LayerFragment& f,
              float level_weight, float share) {
        MultilayerProbeRead r = readOf(side, s, c, si, f);
        r.accepted = true;
        r.level_weight = level_weight;
        r.share = share;
        out.reads.push_back(r);
    }
    void slice(uint32_t si, const LevelBorders::Segment& seg, float d0, float limit, float t,
               const float (&part)[2][4], bool blended, bool new_group, float take, float k,
               float coverage) {
        MultilayerProbeSlice sl;
        sl.segment = si;
        sl.lo = seg.lo;
        sl.hi = seg.hi;
        sl.depth = d0;
        sl.limit = limit;
        sl.t = t;
        std::copy_n(&part[0][0], 8, &sl.part[0][0]);
        sl.blended = blended;
        sl.new_group = new_group;
        sl.take = take;
        sl.k = k;
        sl.coverage = coverage;
        out.slices.push_back(sl);
        // The slice's reads join the result with k times their weight in the slice's sums.
        for (size_t i = slice_reads; i < out.reads.size(); ++i) {
            MultilayerProbeRead& r = out.reads[i];
            if (r.accepted)
                r.weight = k * ((r.level_weight * r.tap_weight) * r.share);
        }
        slice_reads = out.reads.size();
    }
    void done(float coverage, float rest) {
        out.coverage = coverage;
        const glm::vec3 bg = tf.st->background;
        out.background[0] = rest * bg.r, out.background[1] = rest * bg.g;
        out.background[2] = rest * bg.b;
    }
};

} // namespace

raster::Status Multilayer::probe(uint32_t x, uint32_t y, MultilayerPixelProbe& out) const try {
    const Traversal& st = traversal_;
    if (!st.ready || levels_.empty())
        return raster::Status::error(
            "multilayer probe: no frame to probe (render one first; the last one failed)");
    const uint32_t width = levels_[0].width, height = levels_[0].height;
    if (x >= width || y >= height)
        return raster::Status::error(
            "multilayer probe: pixel (" + std::to_string(x) + ", " + std::to_string(y) +
            ") is outside the " + std::to_string(width) + "x" + std::to_string(height) + " image");
    out = MultilayerPixelProbe{};
    out.x = x;
    out.y = y;
    // The collected list (§4), as stored.
    if (st.own_lists) {
        const size_t p = size_t(y) * width + x;
        for (uint32_t i = lists_.offsets[p]; i < lists_.offsets[p + 1]; ++i) {
            MultilayerProbeFragment f;
            f.stored_depth = lists_.depth.load(i);
            f.depth = raster::distanceFromDepth(st.view, f.stored_depth);
            f.coc_px = cocRadiusPx(st.lens, f.depth);
            f.primitive = lists_.primitive[i];
            const glm::vec4 c = lists_.color.load(i);
            f.rgba[0] = c.r, f.rgba[1] = c.g, f.rgba[2] = c.b, f.rgba[3] = c.a;
            out.fragments.push_back(f);
        }
    }
    // §6.1 on the kept levels, through the render's own per-pixel code.
    const TraversalFrame tf = traversalFrame(plan_, levels_, apertures_, borders_, st);
    TapRows rows[2][kMaxTraversalLevels];
    rowTaps(tf, y, rows);
    PixelCursors cursors;
    ProbeRecorder rec{tf, out};
    traversePixel(tf, rows, cursors, x, out.rgba, nullptr, 0, rec);
    return {};
} catch (const std::bad_alloc&) {
    return detail::outOfMemory("probing multilayer");
}

} // namespace dof
