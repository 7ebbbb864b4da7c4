#include <dof/fragment_levels.h>
#include <raster/check.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace dof {

const char* levelKindName(LevelKind kind) {
    switch (kind) {
    case LevelKind::Base:
        return "base";
    case LevelKind::Mip:
        return "mip";
    case LevelKind::Stack:
        return "stack";
    case LevelKind::Aperture:
        return "aperture";
    }
    return "?";
}
namespace {

// Mean over the pixel centres of one period of the variance a bilinear lookup adds per axis:
// a lookup at fractional cell position f blends two cells `spacing` apart with weights (1-f, f),
// which adds spacing² f(1-f).
double lookupVariance(double origin, double spacing, uint32_t extent) {
    const uint32_t period = std::max(1u, std::min(extent, uint32_t(spacing)));
    double sum = 0.0;
    for (uint32_t p = 0; p < period; ++p) {
        const double u = (double(p) + 0.5 - origin) / spacing;
        const double f = u - std::floor(u);
        sum += f * (1.0 - f);
    }
    return spacing * spacing * sum / double(period);
}

// A level's totals from its rows' counts.
void sumRows(const std::vector<uint32_t>& longest, const std::vector<uint64_t>& dropped,
             const std::vector<uint64_t>& skipped, FragmentLevel& level) {
    level.fragments = 0;
    level.max_list_length = 0;
    level.truncated = 0;
    level.skipped = 0;
    for (uint32_t j = 0; j < level.height; ++j) {
        level.fragments += level.rows[j].size();
        level.max_list_length = std::max(level.max_list_length, longest[j]);
        level.truncated += dropped[j];
        level.skipped += skipped[j];
    }
}

// The taps of one cell, in merge order, empty lists left out (they would add w·0 = +0 to sums
// that start at +0 and so are never -0: the same bytes).
// With kSteps, each tap also carries its first fragment's FirstStep.
template <bool kSteps> struct CellTaps {
    const LayerFragment* next[kMaxMergeLists];
    const LayerFragment* end[kMaxMergeLists];
    float weight[kMaxMergeLists];
    const FirstStep* step[kSteps ? kMaxMergeLists : 1];
    uint32_t m = 0;

    void add(const LayerFragment* f, uint32_t count, float w) {
        next[m] = f, end[m] = f + count, weight[m] = w;
        ++m;
    }
    void add(const LayerFragment* f, uint32_t count, float w, const FirstStep* s) {
        step[m] = s;
        add(f, count, w);
    }
    // Appends the §5.1 merge of the taps (mergeListArrays) and consumes them.
    template <class Keep>
    void merge(const LevelPlan& plan, bool pieces, Keep&& keep, std::vector<LayerFragment>& out,
               uint64_t& dropped) {
        const float e = plan.epsilon;
        const bool md = plan.mean_depth;
        const FirstStep** s = kSteps ? step : nullptr;
        if (pieces)
            mergeListArrays<true, kSteps>(next, end, weight, m, e, md, keep, out, dropped, s);
        else
            mergeListArrays<false, kSteps>(next, end, weight, m, e, md, keep, out, dropped, s);
    }
};

// Fills every cell (i, j) of `out` for which `needed(i, j)` holds with the §5.1 merge
// `row_merge(j)(i, keep, out_row, dropped)` appends to the row, one task per row of cells and
// the cells of a row in order, so the bytes do not depend on the thread count; the other cells
// are left empty. With plan.truncate, merged fragments that level `border_level` of T and every
// level above it never ask for are dropped (truncatedAt).
template <class Needed, class RowMerge>
void mergeCells(const LevelPlan& plan, const LevelBorders& borders, uint32_t border_level,
                raster::TaskPool& pool, FragmentLevel& out, Needed&& needed, RowMerge&& row_merge) {
    out.rows.resize(out.height);
    out.starts.assign(size_t(out.height) * (out.width + 1), 0);
    std::vector<uint32_t>& longest = out.scratch.longest;
    std::vector<uint64_t>& dropped = out.scratch.dropped;
    std::vector<uint64_t>& skipped = out.scratch.skipped;
    longest.assign(out.height, 0);
    dropped.assign(out.height, 0);
    skipped.assign(out.height, 0);
    pool.parallelFor(out.height, [&](uint32_t j, uint32_t) {
        // The row is filled in a local vector and moved back (no allocation): neighbouring
        // rows' vectors share cache lines, and a store to this one's end per fragment made the
        // two workers' rows fight over them.
        std::vector<LayerFragment> row = std::move(out.rows[j]);
        row.clear();
        uint32_t* starts = out.starts.data() + size_t(j) * (out.width + 1);
        auto keep = [&](float d) {
            return !plan.truncate || !truncatedAt(borders, border_level, d);
        };
        auto merge = row_merge(j);
        // Counted on the stack and stored once: neighbouring rows' counts share cache lines.
        uint32_t row_longest = 0;
        uint64_t row_dropped = 0;
        uint64_t row_skipped = 0;
        for (uint32_t i = 0; i < out.width; ++i) {
            starts[i] = uint32_t(row.size());
            if (!needed(i, j)) {
                ++row_skipped;
                continue;
            }
            merge(i, keep, row, row_dropped);
            row_longest = std::max(row_longest, uint32_t(row.size()) - starts[i]);
        }
        starts[out.width] = uint32_t(row.size());
        out.rows[j] = std::move(row);
        longest[j] = row_longest;
        dropped[j] = row_dropped;
        skipped[j] = row_skipped;
    });
    sumRows(longest, dropped, skipped, out);
}

// mergeCells over every cell.
template <class RowMerge>
void mergeCells(const LevelPlan& plan, const LevelBorders& borders, uint32_t border_level,
                raster::TaskPool& pool, FragmentLevel& out, RowMerge&& row_merge) {
    const auto every = [](uint32_t, uint32_t) { return true; };
    mergeCells(plan, borders, border_level, pool, out, every, row_merge);
}

// shapeLevel's dense box rows: kDense arrays per row (FragmentLevel::Scratch::dense).
enum Dense : uint32_t { kLo, kHi, kR, kG, kB, kA, kD, kDense };
constexpr uint32_t kLanes = 8; // cells per OneWindowBlock

// The one-window merge of kLanes neighbouring cells inside an aperture level (no clamped
// column): per lane the closest and farthest head over the taps (lo = -inf if a tap holds two
// fragments or more) and, if some lane's heads fall into one window, the sums Σ w·FirstStep in
// tap order.
struct OneWindowBlock {
    uint32_t first = std::numeric_limits<uint32_t>::max(); // the block's first cell
    float v[kDense][kLanes];

    // Taps `taps[k]` read dense box rows of `stride` floats per array at column i + dx. The
    // sums are left out when no lane's taps fall into one window (dense foliage: most blocks).
    template <class RowTap>
    void fill(uint32_t i, const RowTap* taps, uint32_t count, size_t stride, float scale) {
        first = i;
        for (uint32_t l = 0; l < kLanes; ++l) {
            v[kLo][l] = std::numeric_limits<float>::infinity();
            v[kHi][l] = 0.0f;
        }
        for (uint32_t k = 0; k < count; ++k) {
            const float* src = taps[k].dense + (int32_t(i) + taps[k].dx);
            for (uint32_t l = 0; l < kLanes; ++l) {
                v[kLo][l] = std::min(v[kLo][l], src[kLo * stride + l]);
                v[kHi][l] = std::max(v[kHi][l], src[kHi * stride + l]);
            }
        }
        bool any = false;
        for (uint32_t l = 0; l < kLanes; ++l)
            any = any || v[kHi][l] <= v[kLo][l] * scale;
        if (!any)
            return;
        for (uint32_t c = kR; c < kDense; ++c)
            for (uint32_t l = 0; l < kLanes; ++l)
                v[c][l] = 0.0f;
        for (uint32_t k = 0; k < count; ++k) {
            const float* src = taps[k].dense + (int32_t(i) + taps[k].dx);
            const float w = taps[k].w;
            for (uint32_t c = kR; c < kDense; ++c)
                for (uint32_t l = 0; l < kLanes; ++l)
                    v[c][l] += w * src[c * stride + l];
        }
    }
};

void finishGeometry(FragmentLevel& level, uint32_t base_width, uint32_t base_height) {
    const double n = std::ldexp(1.0, int(level.index)); // 2^S point samples per axis
    level.filter_variance = (n * n - 1.0) / 12.0;       // discrete box of 2^S samples
    const double vx = lookupVariance(double(level.origin_x), double(level.spacing), base_width);
    const double vy = lookupVariance(double(level.origin_y), double(level.spacing), base_height);
    level.lookup_variance = 0.5 * (vx + vy);
}

} // namespace

std::vector<FragmentLevel> planLevels(uint32_t width, uint32_t height, const LevelPlan& plan) {
    std::vector<FragmentLevel> levels;
    planLevels(width, height, plan, levels);
    return levels;
}

void planLevels(uint32_t width, uint32_t height, const LevelPlan& plan,
                std::vector<FragmentLevel>& levels) {
    // Every level starts as a default one; geometry holds no fragments, so this moves empty
    // arrays and allocates nothing once `levels` has the capacity.
    levels.resize(plan.levels() + 1);
    for (FragmentLevel& l : levels)
        l = FragmentLevel{};
    FragmentLevel& base = levels[0];
    base.index = 0;
    base.kind = LevelKind::Base;
    base.width = width;
    base.height = height;
    base.spacing = 1.0f;
    base.origin_x = base.origin_y = 0.5f;
    base.dilation = 0;
    for (uint32_t s = 1; s < levels.size(); ++s) {
        const FragmentLevel& prev = levels[s - 1];
        FragmentLevel& next = levels[s];
        next.index = s;
        if (s <= plan.mip_steps) {
            // §5.1: cell i merges cells 2i and 2i+1; its centre is their mean.
            next.kind = LevelKind::Mip;
            next.width = (prev.width + 1) / 2;
            next.height = (prev.height + 1) / 2;
            next.spacing = 2.0f * prev.spacing;
            next.origin_x = prev.origin_x + 0.5f * prev.spacing;
            next.origin_y = prev.origin_y + 0.5f * prev.spacing;
            next.dilation = 1;
        } else {
            // §5.2: cell i merges cells i-Δ and i (clamped), Δ = 2^(S-1) / spacing so that the
            // box doubles to 2^S base pixels; the image grows by Δ (by 1 on the first step).
            next.kind = LevelKind::Stack;
            next.dilation =
                std::max(1u, uint32_t(std::ldexp(1.0, int(s - 1)) / double(prev.spacing)));
            next.width = prev.width + next.dilation;
            next.height = prev.height + next.dilation;
            next.spacing = prev.spacing;
            const float shift = 0.5f * float(next.dilation) * prev.spacing;
            next.origin_x = prev.origin_x - shift;
            next.origin_y = prev.origin_y - shift;
        }
    }
    for (FragmentLevel& l : levels)
        finishGeometry(l, width, height);
    levels[0].lookup_variance = 0.0; // pixel centres are the base cells' centres
}

LevelBorders levelBorders(const ThinLens& lens, const std::vector<double>& level_variance,
                          double aperture_second_moment) {
    LevelBorders t;
    levelBorders(lens, level_variance, aperture_second_moment, t);
    return t;
}

void levelBorders(const ThinLens& lens, const std::vector<double>& level_variance,
                  double aperture_second_moment, LevelBorders& t) {
    t.levels = level_variance.empty() ? 0 : uint32_t(level_variance.size() - 1);
    t.second_moment = aperture_second_moment;
    t.variance = level_variance;
    t.radius.clear();
    t.z_near.clear();
    t.z_far.clear();
    t.segments.clear();
    const double k = double(lens.aperture_radius) * double(lens.focal_length_px); // E f_px
    const double inv_f = 1.0 / double(lens.focus_distance);
    const float inf = std::numeric_limits<float>::infinity();
    for (uint32_t s = 0; s <= t.levels; ++s) {
        const double r = s == 0 ? 0.0 : std::sqrt(level_variance[s] / aperture_second_moment);
        t.radius.push_back(r);
        // Coc(z) = fs_S(z) (§6.1) with |C(d)| = E f_px |1/d_f - 1/d| = r_S.
        if (!(k > 0.0)) {
            t.z_near.push_back(s == 0 ? lens.focus_distance : 0.0f);
            t.z_far.push_back(s == 0 ? lens.focus_distance : inf);
            continue;
        }
        t.z_near.push_back(float(1.0 / (inv_f + r / k)));
        const double inv_far = inv_f - r / k;
        t.z_far.push_back(inv_far > 0.0 ? float(1.0 / inv_far) : inf);
    }
    // Segments near to far: [0, z_N,n) level n; [z_N,S+1, z_N,S) levels S, S+1 (S = n-1..1);
    // [z_N,1, z_F,1) levels 0, 1; then the mirror image behind the focal plane.
    const uint32_t n = t.levels;
    auto add = [&](float begin, float end, uint32_t lo, uint32_t hi) {
        if (end > begin)
            t.segments.push_back({begin, end, lo, hi});
    };
    if (n == 0) {
        add(0.0f, inf, 0, 0);
        return;
    }
    add(0.0f, t.z_near[n], n, n);
    for (uint32_t s = n - 1; s >= 1; --s)
        add(t.z_near[s + 1], t.z_near[s], s, s + 1);
    add(t.z_near[1], t.z_far[1], 0, 1);
    for (uint32_t s = 1; s < n; ++s)
        add(t.z_far[s], t.z_far[s + 1], s, s + 1);
    add(t.z_far[n], inf, n, n);
}

float levelBlend(const LevelBorders& borders, const ThinLens& lens,
                 const LevelBorders::Segment& segment, float depth) {
    if (segment.hi == segment.lo)
        return 0.0f;
    const double c = double(cocRadiusPx(lens, depth));
    const double v = borders.second_moment * c * c;
    const double v_lo = borders.variance[segment.lo];
    const double v_hi = borders.variance[segment.hi];
    const double t = (v - v_lo) / (v_hi - v_lo);
    return float(std::clamp(t, 0.0, 1.0));
}

void makeBaseLevel(const raster::FragmentLists& lists, const raster::View& view,
                   raster::TaskPool& pool, FragmentLevel& out) {
    out.index = 0;
    out.kind = LevelKind::Base;
    out.width = lists.width;
    out.height = lists.height;
    out.rows.resize(lists.height);
    out.starts.assign(size_t(lists.height) * (lists.width + 1), 0);
    std::vector<uint32_t>& longest = out.scratch.longest;
    longest.assign(lists.height, 0);
    pool.parallelFor(lists.height, [&](uint32_t y, uint32_t) {
        std::vector<LayerFragment> row = std::move(out.rows[y]); // filled locally (see mergeCells)
        row.clear();
        uint32_t* starts = out.starts.data() + size_t(y) * (lists.width + 1);
        uint32_t row_longest = 0; // stored once (see mergeCells)
        for (uint32_t x = 0; x < lists.width; ++x) {
            const size_t p = size_t(y) * lists.width + x;
            starts[x] = uint32_t(row.size());
            for (uint32_t f = lists.offsets[p]; f < lists.offsets[p + 1]; ++f) {
                const glm::vec4 c = lists.color.load(f);
                const float d = raster::distanceFromDepth(view, lists.depth.load(f));
                if (!(c.a > 0.0f) || !(d < std::numeric_limits<float>::infinity()))
                    continue;
                const float a = std::min(c.a, 1.0f);
                row.push_back({a * c.r, a * c.g, a * c.b, a, d});
            }
            row_longest = std::max(row_longest, uint32_t(row.size()) - starts[x]);
        }
        starts[lists.width] = uint32_t(row.size());
        out.rows[y] = std::move(row);
        longest[y] = row_longest;
    });
    std::vector<uint64_t>& none = out.scratch.dropped;
    none.assign(lists.height, 0);
    sumRows(longest, none, none, out);
}

void filterLevel(const FragmentLevel& prev, const LevelPlan& plan, const LevelBorders& borders,
                 uint32_t border_level, raster::TaskPool& pool, FragmentLevel& next) {
    const bool mip = next.kind == LevelKind::Mip;
    const int32_t delta = int32_t(next.dilation);
    const int32_t max_x = int32_t(prev.width) - 1;
    const int32_t max_y = int32_t(prev.height) - 1;
    const bool pieces = prev.kind != LevelKind::Base;
    mergeCells(plan, borders, border_level, pool, next, [&](uint32_t j) {
        return [&, j](uint32_t i, auto& keep, std::vector<LayerFragment>& row, uint64_t& dropped) {
            // Source rows and columns: mip 2i, 2i+1; stack i-Δ, i (border cells clamped, Fig. 4).
            const int32_t x0 = std::clamp(mip ? 2 * int32_t(i) : int32_t(i) - delta, 0, max_x);
            const int32_t x1 = std::clamp(mip ? 2 * int32_t(i) + 1 : int32_t(i), 0, max_x);
            const int32_t y0 = std::clamp(mip ? 2 * int32_t(j) : int32_t(j) - delta, 0, max_y);
            const int32_t y1 = std::clamp(mip ? 2 * int32_t(j) + 1 : int32_t(j), 0, max_y);
            const int32_t xs[4] = {x0, x1, x0, x1};
            const int32_t ys[4] = {y0, y0, y1, y1};
            CellTaps<false> taps;
            for (int k = 0; k < 4; ++k) {
                uint32_t count = 0;
                const LayerFragment* f = prev.list(uint32_t(xs[k]), uint32_t(ys[k]), count);
                if (count > 0)
                    taps.add(f, count, 0.25f); // §5.1: α_merged = (α'_1 + ... + α'_4) / 4
            }
            taps.merge(plan, pieces, keep, row, dropped);
        };
    });
}

FragmentLevel planApertureLevel(const FragmentLevel& box, const ApertureGrid& grid, uint32_t index,
                                uint32_t base_width, uint32_t base_height) {
    FragmentLevel level;
    level.index = index;
    level.kind = LevelKind::Aperture;
    level.source = box.index;
    level.grid = grid.size;
    const double tap_px = std::ldexp(1.0, int(box.index)); // the source's box: 2^L base pixels
    level.dilation = std::max(1u, uint32_t(tap_px / double(box.spacing)));
    const uint32_t reach = (grid.size - 1) * level.dilation; // cells from the first tap to the last
    level.width = box.width + reach;
    level.height = box.height + reach;
    level.spacing = box.spacing;
    // Cell i reads box cells i - reach + a·dilation (a = 0..G-1): its centre is their mean.
    const float shift = 0.5f * float(reach) * box.spacing;
    level.origin_x = box.origin_x - shift;
    level.origin_y = box.origin_y - shift;
    // Second moment of the taps about the centre, (a - (G-1)/2)·2^L per axis, plus the box
    // each tap reads (its 2^L point samples, as finishGeometry).
    const double mid = 0.5 * double(grid.size - 1);
    double mx = 0.0, my = 0.0;
    for (uint32_t b = 0; b < grid.size; ++b)
        for (uint32_t a = 0; a < grid.size; ++a) {
            const double w = double(grid.at(a, b));
            mx += w * (double(a) - mid) * (double(a) - mid);
            my += w * (double(b) - mid) * (double(b) - mid);
        }
    level.filter_variance = 0.5 * (mx + my) * tap_px * tap_px + (tap_px * tap_px - 1.0) / 12.0;
    level.lookup_variance =
        0.5 * (lookupVariance(double(level.origin_x), double(level.spacing), base_width) +
               lookupVariance(double(level.origin_y), double(level.spacing), base_height));
    return level;
}

void shapeLevel(const FragmentLevel& box, const ApertureGrid& grid, const LevelPlan& plan,
                const LevelBorders& borders, const LevelReads* reads, raster::TaskPool& pool,
                FragmentLevel& out) {
    FOCAL_CHECK(grid.size >= 1 && grid.size <= kMaxApertureGrid);
    const int32_t step = int32_t(out.dilation);
    const int32_t reach = int32_t(grid.size - 1) * step;
    const int32_t max_x = int32_t(box.width) - 1;
    const int32_t max_y = int32_t(box.height) - 1;
    // Built only where read: a merged fragment lies in [d0, d0·(1 + ε)] (the product mergeLists
    // takes as its limit) for a tap's fragment d0, so a cell can hold a fragment `reads` asks
    // for only if one of its taps holds a d0 < end with d0·(1 + ε) >= begin. Such box cells are
    // flagged, then the flags are widened by the taps' reach, along x on every box row
    // (near_x) and along y per cell (the G x G square: a superset of the taps with weight).
    const float scale = 1.0f + plan.epsilon;
    std::vector<uint8_t>& flag = out.scratch.flag;
    std::vector<uint8_t>& near_x = out.scratch.near_x;
    flag.resize(reads ? size_t(box.width) * box.height : 0);
    near_x.resize(reads ? size_t(box.height) * out.width : 0);
    // (Sizes and pointers are copied into locals: the byte stores below may alias them.)
    const uint32_t box_width = box.width;
    const uint32_t out_width = out.width;
    const LevelReads::Depths* depths = reads ? reads->depths.data() : nullptr;
    const uint32_t depth_count = reads ? uint32_t(reads->depths.size()) : 0;
    pool.parallelFor(reads ? box.height : 0, [&](uint32_t y, uint32_t) {
        uint8_t* f = flag.data() + size_t(y) * box_width;
        const uint32_t* st = box.starts.data() + size_t(y) * (box_width + 1);
        const LayerFragment* data = box.rows[y].data();
        for (uint32_t x = 0; x < box_width; ++x) {
            bool hit = false;
            for (uint32_t k = st[x]; k < st[x + 1] && !hit; ++k) {
                const float d = data[k].depth;
                for (uint32_t r = 0; r < depth_count; ++r)
                    hit = hit || (d < depths[r].end && d * scale >= depths[r].begin);
            }
            f[x] = hit ? 1 : 0;
        }
    });
    pool.parallelFor(reads ? box.height : 0, [&](uint32_t y, uint32_t) {
        const uint8_t* f = flag.data() + size_t(y) * box_width;
        uint8_t* o = near_x.data() + size_t(y) * out_width;
        // Inside, no column is clamped: the OR of the shifted flag rows (vectorised); at the
        // borders, clamped columns.
        const int32_t lo = std::min(reach, int32_t(out_width));
        const int32_t hi = std::max(lo, max_x + 1); // [lo, hi) inside
        for (int32_t i = lo; i < hi; ++i)
            o[i] = 0;
        for (int32_t a = 0; a <= reach; a += step) {
            const uint8_t* src = f + a - reach;
            for (int32_t i = lo; i < hi; ++i)
                o[i] |= src[i];
        }
        for (int32_t i = 0; i < int32_t(out_width); ++i) {
            if (i == lo)
                i = hi;
            if (i >= int32_t(out_width))
                break;
            uint8_t any = 0;
            for (int32_t a = 0; a <= reach; a += step)
                any |= f[std::clamp(i + a - reach, 0, max_x)];
            o[i] = any;
        }
    });
    // The cells to merge: inside the reads' window, with a flag within the taps' reach along
    // y (the OR of near_x's rows, vectorised), one byte per cell.
    std::vector<uint8_t>& need = out.scratch.need;
    need.resize(reads ? size_t(out.height) * out_width : 0);
    pool.parallelFor(reads ? out.height : 0, [&](uint32_t j, uint32_t) {
        uint8_t* o = need.data() + size_t(j) * out_width;
        std::fill(o, o + out_width, uint8_t{0});
        if (j < reads->y0 || j > reads->y1 || reads->x0 > reads->x1)
            return;
        const uint32_t x0 = reads->x0;
        const uint32_t x1 = std::min(reads->x1, out_width - 1);
        for (int32_t b = 0; b <= reach; b += step) {
            const uint8_t* src =
                near_x.data() + size_t(std::clamp(int32_t(j) + b - reach, 0, max_y)) * out_width;
            for (uint32_t i = x0; i <= x1; ++i)
                o[i] |= src[i];
        }
    });
    const uint8_t* need_map = need.data();
    const auto needed = [need_map, out_width, all = !reads](uint32_t i, uint32_t j) {
        return all || need_map[size_t(j) * out_width + i] != 0;
    };
    // Every box row's list starts and fragments, looked up once instead of per tap.
    std::vector<const uint32_t*>& row_starts = out.scratch.row_starts;
    std::vector<const LayerFragment*>& row_data = out.scratch.row_data;
    row_starts.resize(box.height);
    row_data.resize(box.height);
    for (uint32_t y = 0; y < box.height; ++y) {
        row_starts[y] = box.starts.data() + size_t(y) * (box.width + 1);
        row_data[y] = box.rows[y].data();
    }
    const bool pieces = box.kind != LevelKind::Base;
    // Every box fragment's FirstStep, row by row as the fragments: each is read by up to G²
    // cells (and again in later windows), which would each compute it.
    std::vector<size_t>& step_row = out.scratch.step_row;
    std::vector<FirstStep>& steps = out.scratch.steps;
    step_row.resize(size_t(box.height) + 1);
    step_row[0] = 0;
    for (uint32_t y = 0; y < box.height; ++y)
        step_row[y + 1] = step_row[y] + box.rows[y].size();
    steps.resize(step_row[box.height]);
    pool.parallelFor(box.height, [&](uint32_t y, uint32_t) {
        FirstStep* o = steps.data() + step_row[y];
        for (const LayerFragment& f : box.rows[y])
            *o++ = firstStep(f, pieces);
    });
    // Every box cell as the one-window sum below reads it, row by row: kDense arrays of
    // box.width + kLanes floats (padded for the lanes past the last cell). A cell holding one
    // fragment has its depth as both head bounds and its FirstStep; an empty cell adds +0 and
    // leaves the bounds alone (lo = +inf, hi = 0); a cell of two or more fragments sets lo =
    // -inf, which fails the test of one window.
    const size_t dense_row = size_t(kDense) * (box_width + kLanes);
    std::vector<float>& dense = out.scratch.dense;
    dense.resize(dense_row * box.height);
    pool.parallelFor(box.height, [&](uint32_t y, uint32_t) {
        float* o = dense.data() + dense_row * y;
        const size_t n = box_width + kLanes;
        std::fill(o, o + n, std::numeric_limits<float>::infinity()); // kLo
        std::fill(o + n, o + dense_row, 0.0f);                       // kHi, kR.. kD
        const uint32_t* st = box.starts.data() + size_t(y) * (box_width + 1);
        const FirstStep* fs = steps.data() + step_row[y];
        for (uint32_t x = 0; x < box_width; ++x) {
            const uint32_t count = st[x + 1] - st[x];
            if (count == 0)
                continue;
            if (count > 1) {
                o[kLo * n + x] = -std::numeric_limits<float>::infinity();
                continue;
            }
            const FirstStep& f = fs[st[x]];
            o[kLo * n + x] = o[kHi * n + x] = box.rows[y][st[x]].depth;
            o[kR * n + x] = f.r, o[kG * n + x] = f.g, o[kB * n + x] = f.b;
            o[kA * n + x] = f.a, o[kD * n + x] = f.depth;
        }
    });
    // The taps with weight, in grid order: box cell offsets from the cell (before clamping).
    struct Tap {
        int32_t dx = 0;
        uint32_t row = 0; // b
        float w = 0.0f;
    };
    Tap taps[kMaxMergeLists];
    uint32_t tap_count = 0;
    for (uint32_t b = 0; b < grid.size; ++b)
        for (uint32_t a = 0; a < grid.size; ++a)
            if (grid.at(a, b) > 0.0f)
                taps[tap_count++] = {int32_t(a) * step - reach, b, grid.at(a, b)};
    const uint32_t box_cells = box.width;
    mergeCells(plan, borders, out.index, pool, out, needed, [&](uint32_t j) {
        // The taps on this row of cells that read a box row with fragments (border rows
        // clamped, as the stack's, Fig. 4), in grid order: that row's list starts and
        // fragments, the column offset and the weight.
        struct RowTap {
            const uint32_t* starts = nullptr;
            const LayerFragment* data = nullptr;
            const FirstStep* steps = nullptr;
            const float* dense = nullptr;
            int32_t dx = 0;
            float w = 0.0f;
        };
        std::array<RowTap, kMaxMergeLists> row_taps;
        uint32_t row_tap_count = 0;
        for (uint32_t k = 0; k < tap_count; ++k) {
            const Tap& tap = taps[k];
            const int32_t y = std::clamp(int32_t(j) + int32_t(tap.row) * step - reach, 0, max_y);
            const uint32_t* st = row_starts[size_t(y)];
            if (st[0] != st[box_cells])
                row_taps[row_tap_count++] = {st,
                                             row_data[size_t(y)],
                                             steps.data() + step_row[size_t(y)],
                                             dense.data() + dense_row * size_t(y),
                                             tap.dx,
                                             tap.w};
        }
        return [&, row_taps, row_tap_count,
                block = OneWindowBlock{}](uint32_t i, auto& keep, std::vector<LayerFragment>& row,
                                          uint64_t& dropped) mutable {
            // Border cells clamped, as the stack's (Fig. 4); inside, no column is.
            const bool inside = int32_t(i) >= reach && int32_t(i) <= max_x;
            if (inside) {
                // The one-window sums of this cell and the next kLanes - 1, computed together
                // (lane by lane the same operations: the compiler vectorises them). A cell
                // whose taps hold one fragment each, all in the first merge window (the common
                // case), is that window's sum of first steps in tap order: mergeListArrays'
                // sums without its loops. Empty taps add w·(+0) to sums that start at +0 and
                // so are never -0: the same bytes.
                if (i < block.first || i - block.first >= kLanes)
                    block.fill(i, row_taps.data(), row_tap_count, box_width + kLanes, scale);
                const uint32_t l = i - block.first;
                const float d0 = block.v[kLo][l];
                const float limit = d0 * scale;
                if (block.v[kHi][l] <= limit) {
                    LayerFragment merged;
                    merged.r = block.v[kR][l], merged.g = block.v[kG][l];
                    merged.b = block.v[kB][l], merged.a = block.v[kA][l];
                    emitMerged(merged, block.v[kD][l], d0, limit, plan.mean_depth, keep, row,
                               dropped);
                    return;
                }
            }
            // The taps with weight in grid order (a fixed merge order); empty lists are left
            // out (CellTaps).
            CellTaps<true> cell;
            for (uint32_t k = 0; k < row_tap_count; ++k) {
                const RowTap& tap = row_taps[k];
                const int32_t xt = int32_t(i) + tap.dx;
                const uint32_t x = uint32_t(inside ? xt : std::clamp(xt, 0, max_x));
                const uint32_t first = tap.starts[x];
                const uint32_t count = tap.starts[x + 1] - first;
                if (count > 0)
                    cell.add(tap.data + first, count, tap.w, tap.steps + first);
            }
            cell.merge(plan, pieces, keep, row, dropped);
        };
    });
}

} // namespace dof
