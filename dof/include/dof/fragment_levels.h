// The filtered multi-layer hierarchy of Selgrad et al. 2015 §5: fragment lists of level 0 (the
// collected base, §4) filtered into levels 1..n by 2x2 mip steps (§5.1) and then 2x2 stack steps
// (§5.2, the Y-map), each step a merge-sort-like combine that merges fragments of similar depth.
// Aperture-shaped levels read a box level through a grid of taps weighted by the aperture
// (dof/aperture_grid.h), so that the blur they stand for has the lens's shape (the paper's §5.2
// names other filters as possible; §8 suggests per-level post-processing). Also the per-frame
// level border table T (§6.1) and the truncation rule (§6.2) that both follow from the thin
// lens. Consumes raster::FragmentLists and a ThinLens; produces FragmentLevels that the caller
// owns (dof::Multilayer keeps their memory between frames).
//
// Fragments are stored premultiplied: (α·c, α, d). The paper's merged colour c' is stored as α'c',
// which makes the over operator and the additive combine of §5.1 plain sums (no 1/α').
// Depth d is the distance along the view axis (raster::distanceFromDepth), float32.
//
// Memory: these are the stages dof::Multilayer runs. They fill containers the caller owns
// (levels, border tables, merged lists), reusing their capacity, and return plain values: an
// allocation that fails throws std::bad_alloc out of them, as from the std::vector they fill.
// Their only failure is running out of memory, and a frame reaches them only through
// Multilayer::render or renderFromLists, which turn it into a Status; a Status per stage would
// only carry that same failure one stage further.
#pragma once

#include <dof/aperture_grid.h>
#include <dof/lens.h>
#include <raster/camera.h>
#include <raster/check.h>
#include <raster/fragment_lists.h>
#include <raster/status.h>
#include <raster/task_pool.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <vector>

namespace dof {

// One fragment of a level: premultiplied colour, opacity, view distance.
struct LayerFragment {
    float r = 0.0f; // α·red (linear)
    float g = 0.0f;
    float b = 0.0f;
    float a = 0.0f;     // opacity α in [0,1]
    float depth = 0.0f; // distance along the view axis (world units), > 0
};

// The first step of a list's blend in a merge window (§5.1, "within one source list"): the
// opacity so far is pa = 0 there, so fragment f adds (pr, pg, pb, pa, pd) = 0 + t·(αc, α, α·d)
// with t = shareInList(f, pieces, 0), whatever the window and the cell (firstStep). A level
// read by many cells (an aperture level's G x G taps) computes it once per fragment.
struct FirstStep {
    float r = 0.0f;
    float g = 0.0f;
    float b = 0.0f;
    float a = 0.0f;
    float depth = 0.0f; // t·α·d, for the mean depth
};

enum class LevelKind : uint8_t {
    Base,     // level 0: the collected lists (§4)
    Mip,      // 2x2 lists of the level below merged into one, half the resolution (§5.1)
    Stack,    // 2x2 box without downsampling: the image grows by the dilation per level (§5.2)
    Aperture, // G x G taps of a box level, 2^source base pixels apart, weighted by the aperture
              // (dof/aperture_grid.h): a disc (or polygon, or image) of diameter G·2^source
};

// The kind's name in --stats and probes: "base", "mip", "stack", "aperture".
const char* levelKindName(LevelKind kind);

// One level of the hierarchy: width x height cells, each a depth-sorted fragment list. Cells are
// stored row by row (each row a consecutive array, the row's lists compacted with a prefix sum),
// so one task can build one row without knowing the other rows' sizes.
//
// Geometry: cell (i, j) is centred at base-pixel coordinates
//   (origin_x + i·spacing, origin_y + j·spacing)           (pixel p's centre is p + 1/2)
// and holds a 2^S x 2^S box filter of the base level's point samples (box levels: S = index;
// an aperture level holds its grid of taps of box level `source`, and `index` is its place in
// T).
struct FragmentLevel {
    uint32_t index = 0;
    LevelKind kind = LevelKind::Base;
    uint32_t width = 0;
    uint32_t height = 0;
    float spacing = 1.0f;  // base pixels between neighbouring cell centres (2^mip steps)
    float origin_x = 0.5f; // base-pixel coordinate of cell (0, 0)'s centre
    float origin_y = 0.5f;
    uint32_t dilation = 0; // Stack: cells between the two taps combined per axis; Mip: 1;
                           // Aperture: cells between neighbouring taps
    uint32_t source = 0;   // Aperture: the box level its taps read
    uint32_t grid = 0;     // Aperture: G, taps per axis
    // Variance per axis, in base pixels², of the level's filter: the box of 2^S point samples,
    // (4^S - 1)/12 (Aperture: the taps' second moment about the centre plus the variance of
    // the source's box), plus the mean variance the bilinear lookup at pixel centres adds.
    double filter_variance = 0.0;
    double lookup_variance = 0.0;

    std::vector<std::vector<LayerFragment>> rows; // one array per row of cells
    std::vector<uint32_t> starts;                 // height * (width + 1): list of cell (i, j) is
                                  // rows[j][starts[j*(width+1)+i] .. starts[j*(width+1)+i+1])
    uint64_t fragments = 0; // total over all cells
    uint32_t max_list_length = 0;
    uint64_t truncated = 0; // merged fragments dropped by the §6.2 rule
    uint64_t skipped = 0;   // cells left empty, never read by the traversal (LevelReads)

    // Working memory of the stage that fills the level (per-row counts, shapeLevel's read
    // flags), kept with it between frames so that a warm level allocates nothing. Not part of
    // the level's content.
    struct Scratch {
        std::vector<uint32_t> longest;
        std::vector<uint64_t> dropped;
        std::vector<uint64_t> skipped;
        std::vector<uint8_t> flag;
        std::vector<uint8_t> near_x;
        std::vector<uint8_t> need;
        std::vector<const uint32_t*> row_starts;
        std::vector<const LayerFragment*> row_data;
        std::vector<size_t> step_row; // shapeLevel: each box row's first FirstStep
        std::vector<FirstStep> steps; // shapeLevel: the box fragments' first steps
        std::vector<float> dense;     // shapeLevel: the box cells for one-window merges
    };
    Scratch scratch;

    double variance() const { return filter_variance + lookup_variance; }
    const LayerFragment* list(uint32_t i, uint32_t j, uint32_t& count) const {
        const size_t s = size_t(j) * (width + 1) + i;
        count = starts[s + 1] - starts[s];
        return rows[j].data() + starts[s];
    }
};

// How the base level is filtered into levels 1..n (the Y-map of §5.2 / Schwarz & Stamminger
// 2008): the first `mip_steps` levels are mip levels, the remaining `stack_steps` stack levels.
// The paper's configurations: 1/3, 2/2 and 4/0.
struct LevelPlan {
    uint32_t mip_steps = 2;
    uint32_t stack_steps = 2;
    float epsilon = 0.2f; // §5.1 depth threshold, relative: merge while d <= d0·(1 + ε)
    bool truncate = true; // §6.2: drop the depth intervals a level is never asked for
    // The depth a merged fragment carries: the mean of what it merged, weighted by visible
    // opacity (true), or the paper's, the closest one's d0 (false). The mean puts a level's
    // copy of a surface at the depth the surface has on average over the cell, rather than at
    // its nearest corner, and T then picks the level for that depth.
    bool mean_depth = true;
    uint32_t levels() const { return mip_steps + stack_steps; }
};

constexpr uint32_t kMaxFilterLevels = 12;
constexpr uint32_t kMaxApertureGrid = 8; // taps per axis of an aperture-shaped level
constexpr uint32_t kMaxMergeLists = kMaxApertureGrid * kMaxApertureGrid;
// Aperture levels built from one box level: grids G increasing in [G0, 2·G0) with G0 >= 2 and
// G <= kMaxApertureGrid allow at most four (e.g. 4,5,6,7 or 5,6,7,8).
constexpr uint32_t kMaxApertureGridsPerBox = 4;
// Levels of T: the base and, at most, every grid of every box level.
constexpr uint32_t kMaxTraversalLevels = 1 + (kMaxFilterLevels + 1) * kMaxApertureGridsPerBox;

// The level border table T of §6.1, computed per frame. The paper matches Coc(z) = F|z - z_f|
// with the level's filter size fs_S(z) = 2^S G z; in pixels that is |C(d)| = r_S with r_S
// proportional to 2^S. focal matches second moments instead (Eq. in docs/dof/multilayer.md):
// the aperture's per-axis second moment m2 (1/4 for the uniform disk) times C(d)² against the
// level's variance V_S, so r_S = sqrt(V_S / m2) and
//   z_{N,S} = d_f / (1 + r_S d_f / (E f_px)),   z_{F,S} = d_f / (1 - r_S d_f / (E f_px))
// which are the paper's z_{N,S} = z_f / (1 + 2^S G/F), z_{F,S} = z_f / (1 - 2^S G/F) with
// 2^S G/F = r_S d_f / (E f_px). z_{F,S} is +inf past the plateau (Fig. 8: r_S >= C(inf)).
struct LevelBorders {
    uint32_t levels = 0;          // n: levels 0..n
    std::vector<double> radius;   // r_S, S = 0..n (r_0 = 0 for the unfiltered base)
    std::vector<double> variance; // V_S
    std::vector<float> z_near;    // z_{N,S}, S = 0..n (z_{N,0} = d_f)
    std::vector<float> z_far;     // z_{F,S} (+inf past the plateau)
    double second_moment = 0.25;  // m2 of the aperture, per axis, lens units²

    // One traversal segment: depths [begin, end) use levels lo and hi = lo + 1 blended with
    // t(d) = (m2 C(d)² - V_lo) / (V_hi - V_lo) in [0,1]; hi == lo past the top level.
    struct Segment {
        float begin = 0.0f;
        float end = 0.0f;
        uint32_t lo = 0;
        uint32_t hi = 0;
    };
    // T as segments sorted by depth, near to far (the paper's (border, level) pairs).
    std::vector<Segment> segments;
};

// Builds T for the levels' variances and the lens.
LevelBorders levelBorders(const ThinLens& lens, const std::vector<double>& level_variance,
                          double aperture_second_moment);
// The same into `out`, reusing its memory.
void levelBorders(const ThinLens& lens, const std::vector<double>& level_variance,
                  double aperture_second_moment, LevelBorders& out);

// Interpolation weight of level hi at depth d in `segment` (0 when lo == hi).
float levelBlend(const LevelBorders& borders, const ThinLens& lens,
                 const LevelBorders::Segment& segment, float depth);

// §6.2: true when level `level` (>= 1) of T is never asked for depth d, and no level above it
// needs it either: z_{N,S-1} < d < z_{F,S-1}, the middle interval (which also covers the far
// field past the plateau, Fig. 8).
inline bool truncatedAt(const LevelBorders& borders, uint32_t level, float depth) {
    return level >= 1 && depth > borders.z_near[level - 1] && depth < borders.z_far[level - 1];
}

// The share of fragment f that joins the blend of one list's fragments in a merge window whose
// opacity so far is `pa` (§5.1, "within one source list"). A base list is one pixel's stack,
// blended with the over operator: 1 - pa. A filtered cell's list holds pieces of the cell side
// by side (a slanted surface's ε-depth bins, neighbouring leaves), not one behind the other:
// they add up to full opacity, min(α, 1 - pa) / α. The over operator would count two halves of
// the cell as 1 - (1 - 1/2)² = 3/4 of it and let the background show through opaque surfaces.
// The cost: translucent surfaces stacked within ε of each other over the same part of a cell
// (two α = 0.5 panes) add up too (1 instead of 0.75) in the filtered levels.
inline float shareInList(const LayerFragment& f, bool pieces, float pa) {
    if (!pieces)
        return 1.0f - pa;
    // A list's first fragment (pa = 0) with 0 < α <= 1, the usual case: min(α, 1) / α = α / α,
    // which IEEE division makes exactly 1, without dividing.
    if (pa == 0.0f && f.a > 0.0f && f.a <= 1.0f)
        return 1.0f;
    return f.a > 0.0f ? std::max(std::min(f.a, 1.0f - pa), 0.0f) / f.a : 0.0f;
}

// §5.1 merge of up to kMaxMergeLists depth-sorted lists into one sorted list, like merge
// sort's combine: take the closest fragment d0 of all lists; from every list take its fragments
// with d <= d0·(1 + ε) and blend them within the list (shareInList: the over operator for a base
// list, additive for the pieces of a filtered cell); add
// the lists' results weighted (the paper: 1/4 each for 2x2 lists, empty lists count as α' = 0);
// emit (Σ w α'c', Σ w α', depth) with depth d0 or, with mean_depth, the mean depth of what was
// merged weighted by its visible opacity (in [d0, d0·(1 + ε)], so the output stays sorted);
// repeat. Merged fragments with zero opacity are not emitted.
// `keep(depth)` may drop a merged fragment (§6.2). Appends to `out`. The lists of one merge are
// all of one kind (`pieces`, as the cells of one level are); mixing them is a contract
// violation (FOCAL_CHECK).
struct ListRef {
    const LayerFragment* data = nullptr;
    uint32_t count = 0;
    float weight = 0.0f;
    bool pieces = false; // a filtered cell's list (shareInList)
};
template <class Keep>
void mergeLists(const ListRef* lists, uint32_t list_count, float epsilon, bool mean_depth,
                Keep&& keep, std::vector<LayerFragment>& out, uint64_t& dropped);

// f's FirstStep: what it adds as the first fragment of its list in a merge window.
inline FirstStep firstStep(const LayerFragment& f, bool pieces) {
    const float t = shareInList(f, pieces, 0.0f);
    // 0 + x as the blend's sums start (x = -0 gives +0).
    return {0.0f + t * f.r, 0.0f + t * f.g, 0.0f + t * f.b, 0.0f + t * f.a,
            0.0f + t * f.a * f.depth};
}

// mergeLists on lists given as arrays, the form the level stages hold a cell's taps in: list k
// runs from next[k] (advanced past what is merged) to end[k] with weight[k], k < m <=
// kMaxMergeLists, none of them empty, all pieces or all not (kPieces). mergeLists runs this
// after leaving out its empty lists (they would add w·0 = +0 to sums that start at +0 and so are
// never -0: the same bytes), so the unit tests of mergeLists test what the render runs. With
// kSteps, step[k] is next[k]'s firstStep (advanced with it), used instead of computing it.
template <bool kPieces, bool kSteps = false, class Keep>
void mergeListArrays(const LayerFragment** next, const LayerFragment* const* end,
                     const float* weight, uint32_t m, float epsilon, bool mean_depth, Keep&& keep,
                     std::vector<LayerFragment>& out, uint64_t& dropped,
                     const FirstStep** step = nullptr);

// The end of one merge window: emits the merged fragment (Σ w α'c', Σ w α') at depth d0 or,
// with mean_depth, at depth_sum / α clamped to [d0, limit], unless its opacity is 0 or keep
// drops it (counted in dropped).
template <class Keep>
void emitMerged(LayerFragment merged, float depth_sum, float d0, float limit, bool mean_depth,
                Keep&& keep, std::vector<LayerFragment>& out, uint64_t& dropped) {
    if (!(merged.a > 0.0f))
        return;
    merged.depth = mean_depth ? std::clamp(depth_sum / merged.a, d0, limit) : d0;
    if (!keep(merged.depth)) {
        ++dropped;
        return;
    }
    out.push_back(merged);
}

// Level 0 from the collected lists: premultiplies colour by opacity and converts stored depth D
// to view distance. Fragments with zero opacity are dropped.
void makeBaseLevel(const raster::FragmentLists& lists, const raster::View& view,
                   raster::TaskPool& pool, FragmentLevel& out);

// The geometry (size, spacing, origin, dilation, variances) of every level of `plan` over a
// base of width x height, without building them.
std::vector<FragmentLevel> planLevels(uint32_t width, uint32_t height, const LevelPlan& plan);
// The same into `levels`, reusing its memory (what it held is replaced).
void planLevels(uint32_t width, uint32_t height, const LevelPlan& plan,
                std::vector<FragmentLevel>& levels);

// Fills level `next` (geometry from planLevels) from `prev` (§5.1 mip or §5.2 stack step),
// one task per row of cells, each cell merged in a fixed order: the bytes do not depend on the
// thread count. With plan.truncate, merged fragments that level `border_level` of T and every
// level above it never ask for are dropped (truncatedAt).
void filterLevel(const FragmentLevel& prev, const LevelPlan& plan, const LevelBorders& borders,
                 uint32_t border_level, raster::TaskPool& pool, FragmentLevel& next);

// What the traversal (§6.1) can read of a level: the cells [x0, x1] x [y0, y1] that some pixel's
// bilinear lookup reaches, and the depth intervals [begin, end) of the segments of T that read
// the level (a segment's cursors skip what lies in front of it and stop at its end). A merged
// fragment anywhere else never reaches the image.
struct LevelReads {
    uint32_t x0 = 0;
    uint32_t x1 = 0;
    uint32_t y0 = 0;
    uint32_t y1 = 0;
    struct Depths {
        float begin = 0.0f;
        float end = 0.0f;
    };
    std::vector<Depths> depths;
};

// The geometry of the aperture-shaped level that reads `box` through `grid`: its taps sit
// 2^box.index base pixels apart (an integer number of box cells, border cells clamped), so the
// level covers a G·2^box.index square and keeps box's cell spacing; the image grows by the
// taps' reach. `index` is the level's place in T.
FragmentLevel planApertureLevel(const FragmentLevel& box, const ApertureGrid& grid, uint32_t index,
                                uint32_t base_width, uint32_t base_height);

// Fills the aperture-shaped level `out` (geometry from planApertureLevel) by the §5.1 merge of
// its G x G taps, weighted by the grid (disjoint areas: additive across taps), one task per row
// in a fixed order. With plan.truncate, merged fragments level out.index of T never needs are
// dropped. With `reads`, only the cells that can hold a fragment it asks for are merged and the
// others are left empty (out.skipped counts them), which the traversal cannot tell apart;
// nullptr merges every cell.
void shapeLevel(const FragmentLevel& box, const ApertureGrid& grid, const LevelPlan& plan,
                const LevelBorders& borders, const LevelReads* reads, raster::TaskPool& pool,
                FragmentLevel& out);

// ---------------------------------------------------------------------------------------------

template <bool kPieces, bool kSteps, class Keep>
void mergeListArrays(const LayerFragment** next, const LayerFragment* const* end,
                     const float* weight, uint32_t m, float epsilon, bool mean_depth, Keep&& keep,
                     std::vector<LayerFragment>& out, uint64_t& dropped, const FirstStep** step) {
    static_assert(kMaxMergeLists <= 64);
    FOCAL_CHECK(m <= kMaxMergeLists);
    const float scale = 1.0f + epsilon;
    // The lists that still hold fragments, as a bit mask in list order. Only the lists with a
    // fragment in a merge window are blended: another would add w·0 = +0 to sums that start at
    // +0 and so are never -0, which leaves them unchanged (the same bytes).
    uint64_t live = m >= 64 ? ~uint64_t{0} : (uint64_t{1} << m) - 1;
    while (live != 0) {
        // Closest head over all lists, in list order (a value: ties do not matter).
        float d0 = next[std::countr_zero(live)]->depth;
        for (uint64_t bits = live & (live - 1); bits != 0; bits &= bits - 1)
            d0 = std::min(d0, next[std::countr_zero(bits)]->depth);
        const float limit = d0 * scale;
        LayerFragment merged;
        float depth_sum = 0.0f; // Σ w·(visible opacity)·depth, for the mean depth
        for (uint64_t bits = live; bits != 0; bits &= bits - 1) {
            const int k = std::countr_zero(bits);
            const LayerFragment* f = next[k];
            if (!(f->depth <= limit))
                continue;
            // Within list k, front to back (§5.1, first case). The first step has pa = 0; a
            // list of one fragment (the common case) takes only that step.
            const FirstStep s = kSteps ? *step[k] : firstStep(*f, kPieces);
            float pr = s.r, pg = s.g, pb = s.b, pa = s.a, pd = s.depth;
            if (end[k] - f == 1) {
                live &= ~(uint64_t{1} << k);
            } else {
                const LayerFragment* const first = f;
                for (++f; f != end[k] && f->depth <= limit; ++f) {
                    const float t = shareInList(*f, kPieces, pa);
                    pr += t * f->r, pg += t * f->g, pb += t * f->b, pa += t * f->a;
                    pd += t * f->a * f->depth;
                }
                next[k] = f;
                if constexpr (kSteps)
                    step[k] += f - first;
                if (f == end[k])
                    live &= ~(uint64_t{1} << k);
            }
            // Additive blending across lists (§5.1, second case), weighted.
            const float w = weight[k];
            merged.r += w * pr, merged.g += w * pg, merged.b += w * pb, merged.a += w * pa;
            depth_sum += w * pd;
        }
        emitMerged(merged, depth_sum, d0, limit, mean_depth, keep, out, dropped);
    }
}

template <class Keep>
void mergeLists(const ListRef* lists, uint32_t list_count, float epsilon, bool mean_depth,
                Keep&& keep, std::vector<LayerFragment>& out, uint64_t& dropped) {
    FOCAL_CHECK(list_count <= kMaxMergeLists);
    // The non-empty lists, in list order.
    const LayerFragment* next[kMaxMergeLists];
    const LayerFragment* end[kMaxMergeLists];
    float weight[kMaxMergeLists];
    uint32_t m = 0;
    bool pieces = false;
    for (uint32_t k = 0; k < list_count; ++k) {
        if (lists[k].count == 0)
            continue;
        FOCAL_CHECK(m == 0 || lists[k].pieces == pieces);
        pieces = lists[k].pieces;
        next[m] = lists[k].data;
        end[m] = lists[k].data + lists[k].count;
        weight[m] = lists[k].weight;
        ++m;
    }
    if (pieces)
        mergeListArrays<true>(next, end, weight, m, epsilon, mean_depth, keep, out, dropped);
    else
        mergeListArrays<false>(next, end, weight, m, epsilon, mean_depth, keep, out, dropped);
}

} // namespace dof
