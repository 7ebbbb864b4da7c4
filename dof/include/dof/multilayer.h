// `multilayer`: real-time depth of field by multi-layer filtering (Selgrad et al. 2015). Consumes
// a view, a thin lens and a callback that collects per-pixel fragment lists (§4; the app passes
// raster::Renderer::renderFragmentLists); builds the filtered level hierarchy (§5, see
// dof/fragment_levels.h) and accumulates it per pixel guided by the circle of confusion (§6).
// Produces a linear RGBA image owned by the caller. A Multilayer object keeps the lists and the
// levels between frames (no reallocation once warm) and exposes them for stepping and dumps;
// probe() re-runs one pixel's traversal on them and records what it read.
//
// Determinism: every cell and every output pixel is computed by one task in a fixed order
// (merges break depth ties by list index), so the bytes do not depend on the thread count.
#pragma once

#include <dof/fragment_levels.h>
#include <dof/lens.h>
#include <dof/lens_samples.h>
#include <dof/settings_table.h>
#include <raster/camera.h>
#include <raster/fragment_lists.h>
#include <raster/memory_budget.h>
#include <raster/status.h>
#include <raster/storage.h>
#include <raster/task_pool.h>

#include <glm/vec3.hpp>

#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

namespace dof {

// How the slices met during the traversal are blended front to back (§6.1, §7).
enum class LayerBlend : uint8_t {
    Over,     // α-blending with the over operator, as for fragments of one list (§5.1)
    Additive, // additive: Σ α_i c_i until the opacities sum to 1 (§7: avoids light leaks at
              // grazing angles, over-estimates partly transparent middle layers), within groups
              // of slices closer in depth than MultilayerSettings::additive_gap; the over
              // operator between groups
};

// Which filter the traversed levels stand for.
enum class LevelFilter : uint8_t {
    Box,      // the paper's levels themselves: 2^S x 2^S boxes (§2, §5), square bokeh
    Aperture, // aperture-shaped levels read from the boxes (FragmentLevel, LevelKind::Aperture):
              // the lens's own blur, so bokeh has the aperture's shape
};

struct MultilayerSettings {
    uint32_t fragments_per_pixel = 4; // §4: closest N kept per pixel (paper: 3-4; 16); 0 = all
    // §4 cap over the fragments that can be seen: a fragment within ε (the merge threshold)
    // behind a kept opaque fragment of its own pixel takes no slot (raster::FragmentListDesc::
    // hidden_epsilon), so that a stack of leaves does not take every slot and push the ground
    // behind them out of the lists. No effect with fragments_per_pixel = 0 (no slots to compete
    // for) or ε = 0. false: the paper's closest N of all fragments.
    bool skip_hidden = true;
    uint32_t mip_levels = 1;   // §5.2 Y-map: mip steps before the stack (Table 3: 1/3)
    int32_t stack_levels = -1; // stack steps; -1 = auto: until the top level's filter
                               // matches the largest |C(d)| of the collected fragments
    float epsilon = 0.2f;      // §5.1 depth threshold, relative to the depth
    bool truncate = true;      // §6.2 fragment list truncation
    bool mean_depth = true;    // merged fragments carry their mean depth (LevelPlan::mean_depth);
                               // false: the closest one's, as the paper
    LayerBlend blend = LayerBlend::Additive; // §7: the paper's general choice
    // Additive blending: a slice joins the group of the previous one when its depth is within
    // a factor (1 + additive_gap) of it; groups are combined with the over operator. +inf:
    // one group, the paper's additive blending; 0: every slice its own group (over).
    float additive_gap = 1.0f;
    LevelFilter filter = LevelFilter::Aperture;
    // Aperture levels: the shape (shared with accum and multiview) and the tap grids built
    // from each box level L, G x G taps 2^L base pixels apart (a level G·2^L pixels wide).
    // Increasing, each in [2, kMaxApertureGrid] and below twice the first, so that every
    // octave of blur gets one level per grid: {4, 5, 6} gives the widths 4, 5, 6, 8, 10, 12,
    // 16, ... pixels.
    ApertureShape aperture;
    std::vector<uint32_t> aperture_grids = {4, 5, 6};
    // Per-axis second moment of the aperture in lens units² (1/4: uniform disk); the level
    // borders match m2·C(d)² to the level's variance (docs/dof/multilayer.md). Box levels
    // only: aperture levels take it from the aperture grid's samples.
    double aperture_second_moment = 0.25;
    // Aperture levels are merged only in the cells whose fragments the traversal can read
    // (dof::LevelReads); the other cells stay empty and the image is the same bytes. false:
    // every cell, for looking at whole levels.
    bool skip_unread_cells = true;
    // §4 storage of the collected lists: half colour + opacity, float depth (the paper's).
    raster::ColorFormat color_format = raster::ColorFormat::Half;
    raster::DepthFormat depth_format = raster::DepthFormat::Float32;
    uint32_t node_capacity = 1u << 22; // initial fragment node pool (it grows on overflow)
    // Also write each level's contribution to the image (Fig. 7) into MultilayerImage.
    bool level_contributions = false;
    // Checked once the filter levels are planned (§5.2's stack levels grow the image by their
    // dilation, so a CoC of thousands of pixels plans levels far larger than the image): their
    // cells times fragments_per_pixel fragments must fit, or filter() fails naming the sizes.
    raster::MemoryBudget memory_budget;
};

// The parameters of MultilayerSettings a caller chooses (settings_table.h). Not in it, because
// the caller or dof::FrameRenderer sets them: the aperture and its second moment (from the lens
// samples), the storage formats, node_capacity, level_contributions and the memory budget.
std::span<const Param<MultilayerSettings>> multilayerParams();

// Rejects bad settings: every parameter of the table in its range, then the checks between them
// (messages "multilayer settings: NAME ...", naming the fields).
raster::Status validate(const MultilayerSettings& settings);

// One level built this frame: a box level of the hierarchy or an aperture level.
struct MultilayerLevelStats {
    uint32_t index = 0;
    LevelKind kind = LevelKind::Base;
    uint32_t width = 0;
    uint32_t height = 0;
    uint32_t dilation = 0;
    uint32_t source = 0; // Aperture: the box level read
    uint32_t grid = 0;   // Aperture: taps per axis
    uint64_t fragments = 0;
    uint32_t max_list_length = 0;
    double mean_list_length = 0.0; // fragments / cells
    uint64_t truncated = 0;        // merged fragments dropped by §6.2
    uint64_t cells_skipped = 0;    // Aperture: cells left empty, never read (skip_unread_cells)
};

// One level of the border table T (§6.1): the level the traversal reads between its borders.
struct MultilayerTraversalStats {
    uint32_t index = 0; // S in T
    LevelKind kind = LevelKind::Base;
    uint32_t level = 0;     // Box: index into MultilayerStats::levels; Aperture: into apertures
    double radius_px = 0.0; // r_S: the |C| this level matches
    float z_near = 0.0f;    // z_{N,S}
    float z_far = 0.0f;     // z_{F,S} (+inf past the plateau)
};

struct MultilayerStats {
    double ms_collect = 0.0;          // §4: raster, sort/cap/compact, conversion to level 0
    double ms_filter = 0.0;           // §5: levels 1..n
    double ms_accumulate = 0.0;       // §6.1: traversal and blending
    uint64_t fragments_collected = 0; // before the N cap (after early rejection)
    uint64_t fragments_rejected = 0;  // rejected before shading: N nearer ones already collected
                                      // (with skip_hidden: N spaced by more than 1 + ε)
    uint64_t fragments_hidden = 0;    // skipped by the cap as hidden (skip_hidden)
    bool skipped_hidden = false;  // the cap skipped hidden fragments (skip_hidden, N > 0, ε > 0)
    uint64_t fragments_kept = 0;  // after the cap
    uint32_t max_list_length = 0; // longest list appended (after early rejection, before the cap)
    bool node_pool_grew = false;
    uint32_t mip_levels = 0;
    uint32_t stack_levels = 0;
    float max_coc_px = 0.0f;          // largest |C(d)| over the collected fragments
    uint64_t slices_blended = 0;      // merged slices composited during the traversal
    double second_moment = 0.0;       // m2 the border table used
    bool asymmetric_aperture = false; // near and far aperture levels built apart
    // The box levels built (§5): those T reads, directly or through aperture levels, so fewer
    // than mip_levels + stack_levels + 1 when the frame's blur needs fewer.
    std::vector<MultilayerLevelStats> levels;
    // Aperture levels in T order, far side first; with asymmetric_aperture the near side's
    // follow in the same order.
    std::vector<MultilayerLevelStats> apertures;
    std::vector<MultilayerTraversalStats> traversal; // T
};

struct MultilayerImage {
    uint32_t width = 0;
    uint32_t height = 0;
    std::vector<float> rgba;  // linear RGBA (alpha 1), top row first
    std::vector<float> depth; // distance of the closest collected fragment (+inf: background)
    // With settings.level_contributions: per level S of T the premultiplied RGB it adds to
    // the final image (A = its share of the coverage), and the background's share last; they
    // sum to rgba.
    std::vector<std::vector<float>> level_rgba;
};

// --- Probing a pixel (focal steps / focal probe) ---------------------------------------------

// One fragment of the probed pixel's collected list (§4), as stored: nearest first.
struct MultilayerProbeFragment {
    float depth = 0.0f;        // view distance d (raster::distanceFromDepth of the stored D)
    float stored_depth = 0.0f; // D as stored (camera.h)
    float coc_px = 0.0f;       // signed C(d) (Eq. 2 in pixels, lens.h)
    uint32_t primitive = 0;    // submission index of its triangle
    float rgba[4] = {};        // colour and opacity as stored (not premultiplied)
};

// One fragment the traversal (§6.1) met for the probed pixel, in the order it met them.
struct MultilayerProbeRead {
    uint32_t level = 0; // S: the level of T read (Fig. 7); MultilayerStats::traversal[S]
    LevelKind kind = LevelKind::Base;
    uint32_t side = 0;         // 0: the level built for the near side, 1: the far side's (the same
                               // level unless the aperture is asymmetric under a half turn)
    uint32_t slice = 0;        // the fragment's entry in its cell's depth-sorted list
    int32_t x = 0, y = 0;      // the cell at that level (FragmentLevel geometry)
    uint32_t segment = 0;      // the segment of T (LevelBorders::Segment, split at d_f when the
                               // aperture is asymmetric) whose cursor met it
    uint32_t blend = 0;        // the slice it joined (skipped: whose search skipped it; equal
                               // to slices.size() if none followed): MultilayerPixelProbe::slices
    bool accepted = false;     // merged into that slice; false: skipped, since it lies in front of
                               // the segment (that level is not asked for its depth, §6.1)
    float depth = 0.0f;        // view distance of the (merged) fragment
    float coc_px = 0.0f;       // signed C(depth)
    float tap_weight = 0.0f;   // bilinear weight of the cell at the pixel centre
    float level_weight = 0.0f; // 1 - t(d0) for level lo, t(d0) for hi (§6.1 interpolation)
    float share = 0.0f;        // its share in its list's blend (shareInList, §5.1)
    // Its weight in the result: k · tap_weight · level_weight · share, k the slice's blending
    // factor; weight · rgba sums, over the reads, to the result's colour before the background
    // (to float rounding: the render sums per list, then per slice).
    float weight = 0.0f;
    float rgba[4] = {}; // premultiplied (α·c, α), as the level stores it
};

// One slice the traversal blended (or found empty): the §5.1 merge of every tap's fragments
// within [depth, limit] across the segment's levels lo and hi, then §6.1's front-to-back blend.
struct MultilayerProbeSlice {
    uint32_t segment = 0;
    uint32_t lo = 0, hi = 0; // the levels of T the segment reads (hi == lo: one)
    float depth = 0.0f;      // d0: the closest fragment over both levels' taps
    float limit = 0.0f;      // min(d0 (1 + ε), just below the segment's end)
    float t = 0.0f;          // levelBlend: the weight of level hi
    float part[2][4] = {};   // lo's and hi's premultiplied sums, weighted
    bool blended = false;    // its opacity was > 0 (else nothing changed)
    bool new_group = false;  // started a group (LayerBlend): the over operator against before
    float take = 0.0f;       // the opacity it added to its group: min(α, 1 - group's)
    float k = 0.0f;          // the factor its premultiplied colour joined the result with
    float coverage = 0.0f;   // the pixel's opacity after it
};

// What made one pixel of Multilayer's image. Owns its vectors.
struct MultilayerPixelProbe {
    uint32_t x = 0, y = 0;
    // The pixel's collected list (§4), nearest first; empty when the frame came from
    // renderFromLists (the lists were the caller's).
    std::vector<MultilayerProbeFragment> fragments;
    std::vector<MultilayerProbeRead> reads;   // in traversal order
    std::vector<MultilayerProbeSlice> slices; // in traversal order
    float coverage = 0.0f;                    // the opacity the slices reached, up to 1
    float background[3] = {};                 // (1 - coverage) · the background colour, added last
    float rgba[4] = {}; // the result at (x, y), bit-equal to MultilayerImage::rgba
};

// Collects the fragment lists of the view (§4), e.g. raster::Renderer::renderFragmentLists.
using CollectFn =
    std::function<raster::Status(const raster::FragmentListDesc&, raster::FragmentLists&)>;

class Multilayer {
public:
    // Renders one frame: collect, filter, accumulate. `background` is the colour behind every
    // fragment (raster::Scene::background). Fails on invalid settings or lens, or when the
    // collection fails; `out` is then unchanged. Running out of memory anywhere in the frame,
    // on any thread of the pool, is a Status too ("out of memory while rendering multilayer at
    // WxH", or the collection's own), never an exception: this object then releases its kept
    // buffers, `out` may be partly written, and the next call renders as a first frame does.
    raster::Status render(const raster::View& view, const ThinLens& lens, glm::vec3 background,
                          const MultilayerSettings& settings, const CollectFn& collect,
                          raster::TaskPool& pool, MultilayerImage& out,
                          MultilayerStats* stats = nullptr);

    // Runs §5 and §6 on lists collected elsewhere (stage-by-stage use and tests). Fails as
    // render() does, out of memory included.
    raster::Status renderFromLists(const raster::FragmentLists& lists, const raster::View& view,
                                   const ThinLens& lens, glm::vec3 background,
                                   const MultilayerSettings& settings, raster::TaskPool& pool,
                                   MultilayerImage& out, MultilayerStats* stats = nullptr);

    // The last frame's data: the box hierarchy, the aperture levels (far side first, then the
    // near side when the aperture is not symmetric under a half turn), T.
    const raster::FragmentLists& lists() const { return lists_; }
    const std::vector<FragmentLevel>& levels() const { return levels_; }
    const std::vector<FragmentLevel>& apertureLevels() const { return apertures_; }
    const LevelBorders& borders() const { return borders_; }

    // After a successful render() or renderFromLists(): re-runs pixel (x, y)'s traversal (§6.1)
    // on the kept levels with the render's own per-pixel code and a recorder, into `out` (which
    // it overwrites and allocates). out.rgba equals the rendered pixel bit for bit. Fails when
    // no frame is kept (none rendered, or the last one failed) or (x, y) is outside it.
    raster::Status probe(uint32_t x, uint32_t y, MultilayerPixelProbe& out) const;

    // The bilinear taps of a level along one axis at a pixel centre: cells i0, i1 and the
    // weight f of i1 (an implementation detail, public for the scratch below).
    struct AxisTap {
        uint32_t i0 = 0;
        uint32_t i1 = 0;
        float f = 0.0f;
    };
    // The frame's plan: the geometry of the box hierarchy (§5) and of the aperture levels read
    // from it, and T, the levels the traversal reads in order of their variance (§6.1). An
    // implementation detail, public for the scratch below.
    struct Plan {
        LevelPlan plan;
        std::vector<FragmentLevel> boxes;     // geometry of box levels 0..n
        std::vector<FragmentLevel> apertures; // geometry of the aperture levels, in T order
        struct Entry {
            bool aperture = false;
            uint32_t level = 0; // into boxes or apertures
        };
        std::vector<Entry> traversal; // T
        std::vector<double> variance; // V_S of T
    };
    // What the traversal of the last frame read besides the levels, T and the border table:
    // kept so that probe() re-runs a pixel on the same data. An implementation detail, public
    // for the scratch below.
    struct Traversal {
        bool ready = false;     // a frame finished rendering with these
        bool own_lists = false; // the frame's lists are lists_ (render(), not renderFromLists)
        raster::View view;
        ThinLens lens;
        glm::vec3 background{0.0f};
        float scale = 1.0f;       // 1 + ε: a slice's merge window (§5.1)
        float group_scale = 0.0f; // LayerBlend::Additive: 1 + additive_gap, else 0
        bool asymmetric = false;  // near and far aperture levels built apart
        // T as segments (split at d_f when asymmetric), each one's last depth and side
        // (TraversalFrame::sideOf).
        std::vector<LevelBorders::Segment> segments;
        std::vector<float> seg_last;
        std::vector<uint8_t> seg_side;
        // The bilinear taps of every level of T at the pixel centres, per axis.
        std::vector<std::vector<AxisTap>> tx, ty;
    };

private:
    // After std::bad_alloc: releases every kept buffer and returns the out-of-memory Status.
    raster::Status outOfMemory(const raster::View& view) noexcept;

    raster::FragmentLists lists_;
    std::vector<FragmentLevel> levels_;
    std::vector<FragmentLevel> apertures_;
    LevelBorders borders_;
    // The aperture grids [far, near] of the last frame and what they were made from: they are
    // a pure function of the shape and the grid sizes, so a frame with the same ones reuses
    // them.
    std::vector<ApertureGrid> grids_[2];
    ApertureShape grid_shape_;
    std::vector<uint32_t> grid_sizes_;
    double grid_m2_ = 0.0;
    bool grid_asymmetric_ = false;
    // Working memory kept between frames, resized in place, so that a second frame of the same
    // size and settings allocates nothing.
    Plan plan_;
    std::vector<float> row_min_, row_max_;
    Traversal traversal_;
    std::vector<uint64_t> row_slices_;
    LevelReads reads_;
};

} // namespace dof
