// Tests of multi-layer filtering (dof/multilayer.h, dof/fragment_levels.h; Selgrad et al. 2015):
// the §5.1 merge, the §6.1 border table, analytic DOF checks and determinism.
#include "dof_test_util.h"

#include <dof/fragment_levels.h>
#include <dof/metrics.h>
#include <dof/multilayer.h>
#include <raster/fragment_lists.h>
#include <raster/renderer.h>
#include <scenes/builtin.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

namespace focal::test {
namespace {

constexpr uint32_t kW = 64, kH = 64;
constexpr float kFocus = 100.0f; // pixelView: f_px = d_f = 100

raster::View testView(uint32_t w = kW, uint32_t h = kH) {
    return pixelView(w, h, kFocus);
}

struct MlRun {
    dof::MultilayerImage image;
    dof::MultilayerStats stats;
    std::vector<dof::FragmentLevel> levels;
    std::vector<dof::FragmentLevel> apertures;
};

MlRun runMultilayer(const raster::Scene& scene, const raster::View& view, const dof::ThinLens& lens,
                    dof::MultilayerSettings settings = {}, uint32_t threads = 0) {
    raster::TaskPool pool(threads);
    raster::Renderer renderer(pool);
    dof::Multilayer ml;
    MlRun run;
    const dof::CollectFn collect = [&](const raster::FragmentListDesc& desc,
                                       raster::FragmentLists& lists) {
        return renderer.renderFragmentLists(scene, view, {}, desc, lists);
    };
    const raster::Status s =
        ml.render(view, lens, scene.background, settings, collect, pool, run.image, &run.stats);
    EXPECT_TRUE(s.ok()) << s.message();
    run.levels = ml.levels();
    run.apertures = ml.apertureLevels();
    return run;
}

float channel(const dof::MultilayerImage& img, uint32_t x, uint32_t y, int c) {
    return img.rgba[(size_t(y) * img.width + x) * 4 + size_t(c)];
}

uint64_t hashImage(const dof::MultilayerImage& img) {
    uint64_t h = 1469598103934665603ull;
    for (float v : img.rgba) {
        uint32_t bits = 0;
        std::memcpy(&bits, &v, 4);
        for (int i = 0; i < 4; ++i) {
            h ^= (bits >> (8 * i)) & 0xffu;
            h *= 1099511628211ull;
        }
    }
    return h;
}

raster::Scene checkerWall(float d) {
    raster::Scene scene;
    const int32_t white = addMaterial(scene, flatMaterial({1.0f, 1.0f, 1.0f, 1.0f}));
    const int32_t dark = addMaterial(scene, flatMaterial({0.1f, 0.3f, 0.05f, 1.0f}));
    const float s = d / kFocus;
    for (int j = -12; j < 12; ++j)
        for (int i = -12; i < 12; ++i)
            addQuad(scene, float(4 * i) * s, float(4 * j) * s, float(4 * i + 4) * s,
                    float(4 * j + 4) * s, d, ((i + j) & 1) ? white : dark);
    return scene;
}

// --- §5.1 merge ---------------------------------------------------------------------------

dof::LayerFragment frag(float c, float a, float d) {
    return {a * c, a * c, a * c, a, d};
}

TEST(Multilayer, MergeOpaqueStaysOpaqueAndSilhouettesTurnTransparent) {
    const dof::LayerFragment l0[] = {frag(1.0f, 1.0f, 10.0f)};
    const dof::LayerFragment l1[] = {frag(0.5f, 1.0f, 10.1f)};
    const dof::LayerFragment l2[] = {frag(0.0f, 1.0f, 10.05f)};
    const dof::LayerFragment l3[] = {frag(0.25f, 1.0f, 10.0f)};
    dof::ListRef lists[4] = {{l0, 1, 0.25f}, {l1, 1, 0.25f}, {l2, 1, 0.25f}, {l3, 1, 0.25f}};
    std::vector<dof::LayerFragment> out;
    uint64_t dropped = 0;
    auto all = [](float) { return true; };
    dof::mergeLists(lists, 4, 0.02f, false, all, out, dropped);
    ASSERT_EQ(out.size(), 1u);
    EXPECT_FLOAT_EQ(out[0].a, 1.0f);         // opaque stays opaque
    EXPECT_FLOAT_EQ(out[0].r, 1.75f / 4.0f); // mean colour
    EXPECT_FLOAT_EQ(out[0].depth, 10.0f);    // the closest fragment starts the group

    // Silhouette: two of four lists empty -> half coverage.
    lists[2].count = 0;
    lists[3].count = 0;
    out.clear();
    dof::mergeLists(lists, 4, 0.02f, false, all, out, dropped);
    ASSERT_EQ(out.size(), 1u);
    EXPECT_FLOAT_EQ(out[0].a, 0.5f);
}

TEST(Multilayer, MergeUsesOverWithinAListAndSplitsBeyondEpsilon) {
    // List 0: two half-transparent fragments within ε, then one far behind.
    const dof::LayerFragment l0[] = {frag(1.0f, 0.5f, 10.0f), frag(0.0f, 0.5f, 10.1f),
                                     frag(1.0f, 1.0f, 20.0f)};
    dof::ListRef lists[1] = {{l0, 3, 1.0f}};
    std::vector<dof::LayerFragment> out;
    uint64_t dropped = 0;
    dof::mergeLists(
        lists, 1, 0.02f, false, [](float) { return true; }, out, dropped);
    ASSERT_EQ(out.size(), 2u);
    // α' = 1 - (1 - αa)(1 - αb) = 0.75; α'c' = αa ca + (1 - αa) αb cb = 0.5.
    EXPECT_FLOAT_EQ(out[0].a, 0.75f);
    EXPECT_FLOAT_EQ(out[0].r, 0.5f);
    EXPECT_FLOAT_EQ(out[1].depth, 20.0f);
    // ε = 0: three groups; a keep() that drops the far one counts it.
    out.clear();
    dof::mergeLists(
        lists, 1, 0.0f, false, [](float d) { return d < 15.0f; }, out, dropped);
    EXPECT_EQ(out.size(), 2u);
    EXPECT_EQ(dropped, 1u);
}

TEST(Multilayer, MergeCarriesTheMeanDepthOfWhatItMerged) {
    // Two lists within ε: an opaque fragment at 10 (weight 3/4) and one at 11 (weight 1/4).
    // The paper's merged fragment lies at the closest depth, 10; the mean depth weights each
    // by its visible opacity: 10.25. Within one list the over operator hides what is behind
    // an opaque fragment, so it adds nothing to the mean. The output stays sorted.
    const dof::LayerFragment l0[] = {frag(1.0f, 1.0f, 10.0f), frag(1.0f, 1.0f, 10.5f),
                                     frag(1.0f, 1.0f, 30.0f)};
    const dof::LayerFragment l1[] = {frag(0.0f, 1.0f, 11.0f)};
    const dof::ListRef lists[2] = {{l0, 3, 0.75f}, {l1, 1, 0.25f}};
    auto all = [](float) { return true; };
    std::vector<dof::LayerFragment> out;
    uint64_t dropped = 0;
    dof::mergeLists(lists, 2, 0.2f, false, all, out, dropped);
    ASSERT_EQ(out.size(), 2u);
    EXPECT_EQ(out[0].depth, 10.0f);
    out.clear();
    dof::mergeLists(lists, 2, 0.2f, true, all, out, dropped);
    ASSERT_EQ(out.size(), 2u);
    EXPECT_FLOAT_EQ(out[0].depth, 10.25f);
    EXPECT_FLOAT_EQ(out[0].a, 1.0f);
    EXPECT_FLOAT_EQ(out[1].depth, 30.0f);
    EXPECT_LE(out[0].depth, out[1].depth);
}

// A level of width x height cells, row by row; fill(i, j, row) appends cell (i, j)'s list.
template <class Fill> dof::FragmentLevel levelOf(uint32_t width, uint32_t height, Fill&& fill) {
    dof::FragmentLevel level;
    level.width = width;
    level.height = height;
    level.rows.resize(height);
    level.starts.assign(size_t(height) * (width + 1), 0);
    for (uint32_t j = 0; j < height; ++j)
        for (uint32_t i = 0; i < width; ++i) {
            fill(i, j, level.rows[j]);
            level.starts[j * (width + 1) + i + 1] = uint32_t(level.rows[j].size());
        }
    return level;
}

TEST(Multilayer, ShapeLevelMergesEveryCellItsReadsCanSee) {
    // A 6x4 base whose columns alternate between depths 0.95 and 1.1, read through a 2x2 grid:
    // cells 1-5 merge one of each (ε = 0.2) into a fragment at their mean depth, 1.025,
    // although neither lies in the depths read, [1, 1.05). Those cells must still be merged,
    // as in the full level; column 0 lies outside the cells read and column 6 (two clamped
    // taps at 1.1) holds nothing read: both are left empty.
    const dof::FragmentLevel base =
        levelOf(6, 4, [](uint32_t i, uint32_t, std::vector<dof::LayerFragment>& cell) {
            cell.push_back(frag(0.5f, 1.0f, i % 2 ? 1.1f : 0.95f));
        });
    dof::ApertureGrid grid;
    grid.size = 2;
    grid.weight = {0.25f, 0.25f, 0.25f, 0.25f};
    dof::LevelPlan plan;
    plan.truncate = false;
    raster::TaskPool pool(0);
    dof::LevelReads reads;
    reads.x0 = 1, reads.x1 = 6, reads.y0 = 0, reads.y1 = 4;
    reads.depths = {{1.0f, 1.05f}};
    dof::FragmentLevel full = dof::planApertureLevel(base, grid, 1, base.width, base.height);
    dof::FragmentLevel part = full;
    dof::shapeLevel(base, grid, plan, {}, nullptr, pool, full);
    dof::shapeLevel(base, grid, plan, {}, &reads, pool, part);
    ASSERT_EQ(full.width, 7u);
    ASSERT_EQ(full.height, 5u);
    EXPECT_EQ(full.skipped, 0u);
    EXPECT_EQ(part.skipped, 2u * part.height);
    for (uint32_t j = 0; j < full.height; ++j)
        for (uint32_t i = 0; i < full.width; ++i) {
            uint32_t nf = 0, np = 0;
            const dof::LayerFragment* f = full.list(i, j, nf);
            const dof::LayerFragment* p = part.list(i, j, np);
            ASSERT_EQ(nf, 1u);
            if (i == 0 || i == 6) {
                EXPECT_EQ(np, 0u) << i << "," << j;
                continue;
            }
            ASSERT_EQ(np, 1u) << i << "," << j;
            EXPECT_EQ(std::memcmp(f, p, sizeof(dof::LayerFragment)), 0) << i << "," << j;
            EXPECT_NEAR(p->depth, 1.025f, 1e-6f);
        }
}

TEST(Multilayer, ShapeLevelMergesEachCellAsMergeListsDoes) {
    // shapeLevel's one-window sums and its first steps (computed once per box fragment) must
    // give mergeLists' bytes: a 13x9 box level of lists of 0-3 fragments (random depths and
    // opacities, so cells fall into one window, several, or lists that span windows), read
    // through a 4x4 grid with some weights 0, as a base level (over operator within a list)
    // and as a filtered one (pieces), with both depth rules.
    uint32_t seed = 12345;
    auto next = [&seed] {
        seed = seed * 1664525u + 1013904223u;
        return float(seed >> 8) / float(1u << 24);
    };
    dof::FragmentLevel box =
        levelOf(13, 9, [&](uint32_t, uint32_t, std::vector<dof::LayerFragment>& cell) {
            const uint32_t count = uint32_t(next() * 4.0f) % 4;
            float d = 1.0f + next();
            for (uint32_t k = 0; k < count; ++k) {
                const float a = k == 0 && next() < 0.5f ? 1.0f : 0.1f + 0.9f * next();
                cell.push_back({a * next(), a * next(), a * next(), a, d});
                d *= 1.0f + 0.3f * next();
            }
        });
    dof::ApertureGrid grid;
    grid.size = 4;
    grid.weight.assign(16, 0.0f);
    float sum = 0.0f;
    for (float& w : grid.weight) {
        w = next() < 0.2f ? 0.0f : next();
        sum += w;
    }
    for (float& w : grid.weight)
        w /= sum;
    raster::TaskPool pool(0);
    for (const dof::LevelKind kind : {dof::LevelKind::Base, dof::LevelKind::Mip})
        for (const bool mean_depth : {true, false}) {
            box.kind = kind;
            dof::LevelPlan plan;
            plan.truncate = false;
            plan.mean_depth = mean_depth;
            dof::FragmentLevel level = dof::planApertureLevel(box, grid, 1, box.width, box.height);
            dof::shapeLevel(box, grid, plan, {}, nullptr, pool, level);
            const int32_t reach = int32_t(grid.size - 1);
            for (uint32_t j = 0; j < level.height; ++j)
                for (uint32_t i = 0; i < level.width; ++i) {
                    dof::ListRef lists[dof::kMaxMergeLists];
                    uint32_t n = 0;
                    for (uint32_t b = 0; b < grid.size; ++b)
                        for (uint32_t a = 0; a < grid.size; ++a) {
                            if (!(grid.at(a, b) > 0.0f))
                                continue;
                            const int32_t x = std::clamp(int32_t(i + a) - reach, 0, 12);
                            const int32_t y = std::clamp(int32_t(j + b) - reach, 0, 8);
                            uint32_t count = 0;
                            const dof::LayerFragment* f = box.list(uint32_t(x), uint32_t(y), count);
                            lists[n++] = {f, count, grid.at(a, b), kind != dof::LevelKind::Base};
                        }
                    std::vector<dof::LayerFragment> want;
                    uint64_t dropped = 0;
                    dof::mergeLists(
                        lists, n, plan.epsilon, mean_depth, [](float) { return true; }, want,
                        dropped);
                    uint32_t count = 0;
                    const dof::LayerFragment* got = level.list(i, j, count);
                    ASSERT_EQ(count, want.size()) << i << "," << j;
                    if (count > 0) { // an empty list may have no storage (memcmp takes no null)
                        EXPECT_EQ(std::memcmp(got, want.data(), count * sizeof(dof::LayerFragment)),
                                  0)
                            << i << "," << j;
                    }
                }
        }
}

// --- §6.1 border table --------------------------------------------------------------------

TEST(Multilayer, BorderTableSolvesCocEqualsFilterSize) {
    const raster::View view = testView();
    const dof::ThinLens lens = dof::makeThinLens(view, 12.0f, kFocus); // C(inf) = 12 px
    const std::vector<dof::FragmentLevel> levels = dof::planLevels(kW, kH, {2, 3, 0.02f, true});
    std::vector<double> var;
    for (const dof::FragmentLevel& l : levels)
        var.push_back(l.variance());
    const dof::LevelBorders t = dof::levelBorders(lens, var, 0.25);
    ASSERT_EQ(t.levels, 5u);
    for (uint32_t s = 1; s <= t.levels; ++s) {
        EXPECT_GT(var[s], var[s - 1]);
        // |C(z_N,S)| = r_S and, where finite, |C(z_F,S)| = r_S.
        EXPECT_NEAR(std::fabs(dof::cocRadiusPx(lens, t.z_near[s])), t.radius[s], 1e-3);
        EXPECT_LT(t.z_near[s], t.z_near[s - 1]);
        if (std::isfinite(t.z_far[s]))
            EXPECT_NEAR(std::fabs(dof::cocRadiusPx(lens, t.z_far[s])), t.radius[s], 1e-3);
        else
            EXPECT_GE(t.radius[s], 12.0); // plateau (Fig. 8)
        // The paper's closed form with 2^S G / F = r_S d_f / (E f_px).
        const double q = t.radius[s] * double(kFocus) / (12.0 * 100.0);
        EXPECT_NEAR(double(t.z_near[s]), double(kFocus) / (1.0 + q), 1e-3);
    }
    // Segments tile (0, inf) near to far without gaps.
    ASSERT_FALSE(t.segments.empty());
    EXPECT_EQ(t.segments.front().begin, 0.0f);
    EXPECT_TRUE(std::isinf(t.segments.back().end));
    for (size_t i = 1; i < t.segments.size(); ++i)
        EXPECT_EQ(t.segments[i].begin, t.segments[i - 1].end);
    // Stack levels keep the mip spacing and grow by their dilation (1, then 2, 4).
    EXPECT_EQ(levels[3].kind, dof::LevelKind::Stack);
    EXPECT_EQ(levels[3].dilation, 1u);
    EXPECT_EQ(levels[4].dilation, 2u);
    EXPECT_EQ(levels[3].width, levels[2].width + 1);
    EXPECT_EQ(levels[4].width, levels[3].width + 2);
    EXPECT_EQ(levels[2].width, kW / 4);
}

// --- analytic DOF checks ------------------------------------------------------------------

TEST(Multilayer, InFocusWallIsUnchanged) {
    const raster::View view = testView();
    const raster::Scene scene = checkerWall(kFocus);
    const raster::Frame pinhole = render(scene, view);
    dof::MultilayerSettings settings;
    settings.color_format = raster::ColorFormat::Float32;
    const MlRun ml = runMultilayer(scene, view, dof::makeThinLens(view, 12.0f, kFocus), settings);
    float max_diff = 0.0f;
    for (size_t i = 0; i < pinhole.color.size(); ++i)
        max_diff = std::max(max_diff, std::fabs(pinhole.color[i] - ml.image.rgba[i]));
    EXPECT_LT(max_diff, 1e-5f);
    // Half storage: within half precision.
    const MlRun half = runMultilayer(scene, view, dof::makeThinLens(view, 12.0f, kFocus));
    max_diff = 0.0f;
    for (size_t i = 0; i < pinhole.color.size(); ++i)
        max_diff = std::max(max_diff, std::fabs(pinhole.color[i] - half.image.rgba[i]));
    EXPECT_LT(max_diff, 1e-3f);
}

TEST(Multilayer, OffFocusWallIsBlurred) {
    const raster::View view = testView();
    const raster::Scene scene = checkerWall(200.0f);
    const raster::Frame pinhole = render(scene, view);
    const MlRun ml = runMultilayer(scene, view, dof::makeThinLens(view, 12.0f, kFocus));
    float max_diff = 0.0f;
    for (size_t i = 0; i < pinhole.color.size(); ++i)
        max_diff = std::max(max_diff, std::fabs(pinhole.color[i] - ml.image.rgba[i]));
    EXPECT_GT(max_diff, 0.2f);
}

TEST(Multilayer, ConstantImageStaysConstant) {
    for (float d : {200.0f / 3.0f, 200.0f}) {
        raster::Scene scene;
        scene.background = {0.9f, 0.1f, 0.1f};
        const int32_t m = addMaterial(scene, flatMaterial({0.25f, 0.5f, 0.75f, 1.0f}));
        const float s = d / kFocus;
        addQuad(scene, -100.0f * s, -100.0f * s, 100.0f * s, 100.0f * s, d, m);
        const raster::View view = testView();
        dof::MultilayerSettings settings;
        settings.color_format = raster::ColorFormat::Float32;
        for (uint32_t mip : {0u, 2u, 4u}) {
            settings.mip_levels = mip;
            const MlRun ml =
                runMultilayer(scene, view, dof::makeThinLens(view, 12.0f, kFocus), settings);
            for (uint32_t y = 0; y < kH; ++y)
                for (uint32_t x = 0; x < kW; ++x) {
                    ASSERT_NEAR(channel(ml.image, x, y, 0), 0.25f, 1e-5f) << x << "," << y;
                    ASSERT_NEAR(channel(ml.image, x, y, 1), 0.5f, 1e-5f);
                    ASSERT_NEAR(channel(ml.image, x, y, 2), 0.75f, 1e-5f);
                }
        }
    }
}

TEST(Multilayer, OpaqueSurfacesStayOpaqueThroughTheLevels) {
    // A wall covering the whole view behind the focal plane and a small quad in front of it:
    // every cell of every level, box and aperture-shaped, holds the wall with opacity 1
    // (over-composited list), also where the quad's silhouette makes its own fragment partly
    // transparent.
    const raster::View view = testView();
    raster::Scene scene = checkerWall(200.0f);
    const int32_t red = addMaterial(scene, flatMaterial({1.0f, 0.0f, 0.0f, 1.0f}));
    addQuad(scene, -10.0f, -10.0f, 10.0f, 10.0f, 60.0f, red);
    for (dof::LevelFilter filter : {dof::LevelFilter::Box, dof::LevelFilter::Aperture}) {
        dof::MultilayerSettings settings;
        settings.truncate = false;
        settings.stack_levels = 3;
        settings.filter = filter;
        settings.skip_unread_cells = false; // look at every cell
        const MlRun ml =
            runMultilayer(scene, view, dof::makeThinLens(view, 12.0f, kFocus), settings);
        std::vector<const dof::FragmentLevel*> levels;
        for (const dof::FragmentLevel& l : ml.levels)
            levels.push_back(&l);
        for (const dof::FragmentLevel& l : ml.apertures)
            levels.push_back(&l);
        if (filter == dof::LevelFilter::Box)
            ASSERT_EQ(levels.size(), 5u); // 1 mip + 3 stack levels over the base
        else
            ASSERT_GT(ml.apertures.size(), 3u);
        bool partial_seen = false;
        for (const dof::FragmentLevel* l : levels)
            for (uint32_t j = 0; j < l->height; ++j)
                for (uint32_t i = 0; i < l->width; ++i) {
                    uint32_t count = 0;
                    const dof::LayerFragment* f = l->list(i, j, count);
                    float a = 0.0f;
                    for (uint32_t k = 0; k < count; ++k) {
                        a += (1.0f - a) * f[k].a;
                        if (f[k].a < 0.99f)
                            partial_seen = true;
                    }
                    ASSERT_NEAR(a, 1.0f, 1e-5f) << "level " << l->index << " cell " << i << "," << j
                                                << (l->grid ? " (aperture)" : "");
                    ASSERT_NEAR(f[count - 1].depth, 200.0f, 0.5f); // the wall is last
                }
        EXPECT_TRUE(partial_seen); // the quad's silhouette
    }
}

TEST(Multilayer, StackedLeavesLeaveASlotForTheWallBehind) {
    // Four opaque 8 px squares stacked within ε at d = 50..53 (C = -12 px) in front of a red
    // wall in focus that fills the view, over a blue background. The blurred stack covers
    // little of its own pixels, so they show the wall. With the paper's closest N = 4 the
    // stack takes all four slots there, the wall is dropped and the background shows through
    // instead; skipping the hidden fragments keeps the wall in every list.
    const raster::View view = testView();
    raster::Scene scene;
    scene.background = glm::vec3(0.0f, 0.0f, 1.0f);
    const int32_t red = addMaterial(scene, flatMaterial({1.0f, 0.0f, 0.0f, 1.0f}));
    const int32_t green = addMaterial(scene, flatMaterial({0.0f, 1.0f, 0.0f, 1.0f}));
    addQuad(scene, -60.0f, -60.0f, 60.0f, 60.0f, kFocus, red);
    for (float d : {50.0f, 51.0f, 52.0f, 53.0f})
        addQuad(scene, -0.04f * d, -0.04f * d, 0.04f * d, 0.04f * d, d, green);
    const dof::ThinLens lens = dof::makeThinLens(view, 12.0f, kFocus);
    float max_blue[2] = {0.0f, 0.0f};
    for (bool skip : {false, true}) {
        dof::MultilayerSettings settings;
        settings.skip_hidden = skip;
        const MlRun ml = runMultilayer(scene, view, lens, settings);
        EXPECT_EQ(ml.stats.fragments_hidden > 0, skip);
        for (uint32_t y = 0; y < kH; ++y)
            for (uint32_t x = 0; x < kW; ++x)
                max_blue[skip] = std::max(max_blue[skip], channel(ml.image, x, y, 2));
    }
    EXPECT_GT(max_blue[0], 0.5f);  // the hole the cap makes
    EXPECT_LT(max_blue[1], 2e-3f); // kOpaque: the traversal stops 1/1024 short of opaque
}

TEST(Multilayer, SlantedOpaqueSurfaceHidesTheBackground) {
    // A black plane slanted from depth 40 to 70 in front of the focal plane (C = -18 ... -5 px)
    // covers the view and more, in front of a white background: every lens ray meets it, so
    // the image is black. With ε = 0.05 the aperture levels' cells cut the plane into depth
    // bins that lie side by side (the box levels' cells are too small to split here, so only
    // aperture levels are run); blended with the over operator within a cell's list, two
    // halves of a cell would cover 3/4 of it (measured: 3.2 % of white on average, 9.4 % at
    // most). What still shows (0.8 %, 3.2 % at most) is where a level's copy of the plane
    // straddles a border of T, and the part beyond the border is not read there.
    const raster::View view = testView();
    raster::Scene scene;
    scene.background = {1.0f, 1.0f, 1.0f};
    const int32_t black = addMaterial(scene, flatMaterial({0.0f, 0.0f, 0.0f, 1.0f}));
    addMesh(scene,
            {{-40.0f, -60.0f, -40.0f},
             {80.0f, -60.0f, -70.0f},
             {80.0f, 60.0f, -70.0f},
             {-40.0f, 60.0f, -40.0f}},
            {0, 1, 2, 0, 2, 3}, black);
    {
        dof::MultilayerSettings settings;
        settings.filter = dof::LevelFilter::Aperture;
        settings.truncate = false;
        settings.epsilon = 0.05f;
        const MlRun ml =
            runMultilayer(scene, view, dof::makeThinLens(view, 12.0f, kFocus), settings);
        uint32_t split_cells = 0; // cells holding more than one bin, what the test is about
        for (const dof::FragmentLevel& l : ml.apertures)
            for (uint32_t j = 0; j < l.height; ++j)
                for (uint32_t i = 0; i < l.width; ++i) {
                    uint32_t count = 0;
                    l.list(i, j, count);
                    split_cells += count > 1 ? 1 : 0;
                }
        EXPECT_GT(split_cells, 0u);
        float brightest = 0.0f;
        double mean = 0.0;
        for (uint32_t y = 0; y < kH; ++y)
            for (uint32_t x = 0; x < kW; ++x) {
                brightest = std::max(brightest, channel(ml.image, x, y, 0));
                mean += double(channel(ml.image, x, y, 0)) / double(kW * kH);
            }
        EXPECT_LT(mean, 0.012);
        EXPECT_LT(brightest, 0.05f);
    }
}

// --- aperture-shaped levels, mean depth, grouped blending --------------------------------

// Two small white squares on black, one behind the focal plane (C = +12 px) and one in front
// of it (C = -12 px), rendered by accum with 256 lens samples on `shape` and by multilayer.
struct SpotCase {
    raster::Scene scene;
    raster::View view = testView(128, 64);
    dof::ThinLens lens = dof::makeThinLens(view, 24.0f, kFocus);
    SpotCase() {
        const int32_t white = addMaterial(scene, flatMaterial({1.0f, 1.0f, 1.0f, 1.0f}));
        const float far = 200.0f, near = 200.0f / 3.0f; // C = E f (1/d_f - 1/d) = ±12 px
        addQuad(scene, -34.0f * far / kFocus, -2.0f * far / kFocus, -30.0f * far / kFocus,
                2.0f * far / kFocus, far, white);
        addQuad(scene, 30.0f * near / kFocus, -2.0f * near / kFocus, 34.0f * near / kFocus,
                2.0f * near / kFocus, near, white);
    }
    double psnr(const dof::ApertureShape& lens_shape, const dof::MultilayerSettings& settings) {
        const raster::Frame ref = renderAccum(scene, view, lens, makeSamples(256, lens_shape));
        const MlRun ml = runMultilayer(scene, view, lens, settings);
        const raster::Result<dof::ErrorMetrics> m =
            dof::compareImages({ref.color.data(), view.width, view.height, 4},
                               {ml.image.rgba.data(), view.width, view.height, 4});
        FOCAL_CHECK(m.ok());
        return m->psnr_linear_db;
    }
};

TEST(Multilayer, ApertureLevelsGiveTheBokehTheAperturesShape) {
    // The paper's box levels turn a point into a square; the aperture levels into the lens's
    // disc, closer to accum.
    SpotCase c;
    dof::MultilayerSettings box;
    box.filter = dof::LevelFilter::Box;
    const double psnr_box = c.psnr({}, box);
    const double psnr_disc = c.psnr({}, {});
    EXPECT_GT(psnr_disc, psnr_box + 6.0); // measured: 54.2 against 45.1 dB
    EXPECT_GT(psnr_disc, 50.0);
    RecordProperty("psnr_box_db", std::to_string(psnr_box));
    RecordProperty("psnr_aperture_db", std::to_string(psnr_disc));
}

TEST(Multilayer, ApertureLevelsTurnAnAsymmetricApertureInFrontOfTheFocalPlane) {
    // A triangle (not symmetric under a half turn): behind the focal plane the bokeh is the
    // triangle, in front of it the triangle turned by 180 degrees (dof/lens.h). Near and far
    // aperture levels are built apart; the triangle turned the wrong way scores worse.
    SpotCase c;
    dof::ApertureShape triangle;
    triangle.kind = dof::ApertureKind::Polygon;
    triangle.blades = 3;
    dof::MultilayerSettings right;
    right.aperture = triangle;
    dof::MultilayerSettings wrong = right;
    wrong.aperture.rotation_deg = 180.0f;
    const double psnr_right = c.psnr(triangle, right);
    const double psnr_wrong = c.psnr(triangle, wrong);
    EXPECT_GT(psnr_right, psnr_wrong + 5.0); // measured: 49.6 against 41.2 dB
    EXPECT_GT(psnr_right, 46.0);
    const MlRun ml = runMultilayer(c.scene, c.view, c.lens, right);
    EXPECT_TRUE(ml.stats.asymmetric_aperture);
    // Near and far aperture levels, the same number of each.
    EXPECT_EQ(ml.apertures.size(), ml.stats.apertures.size());
    EXPECT_EQ(ml.apertures.size(), 2 * (ml.stats.traversal.size() - 1));
    RecordProperty("psnr_right_db", std::to_string(psnr_right));
    RecordProperty("psnr_wrong_db", std::to_string(psnr_wrong));
}

TEST(Multilayer, HugeBlurWithFourGridsPerBoxLevel) {
    // A wall filling the view at C = -320 px with four grids per box level: T holds more
    // levels than two grids per box level could (1 + 13·2), and the uniform wall stays uniform.
    const raster::View view = testView();
    const float d = 20.0f; // C = E f (1/d_f - 1/d) = -4 E
    raster::Scene scene;
    const int32_t white = addMaterial(scene, flatMaterial({1.0f, 1.0f, 1.0f, 1.0f}));
    addQuad(scene, -100.0f, -100.0f, 100.0f, 100.0f, d, white);
    dof::MultilayerSettings settings;
    settings.aperture_grids = {5, 6, 7, 8};
    const MlRun ml = runMultilayer(scene, view, dof::makeThinLens(view, 80.0f, kFocus), settings);
    EXPECT_NEAR(ml.stats.max_coc_px, 320.0f, 0.5f);
    EXPECT_GT(ml.stats.traversal.size(), 27u);
    EXPECT_GE(ml.stats.traversal.back().radius_px, 320.0);
    for (uint32_t y = 0; y < kH; y += 7)
        for (uint32_t x = 0; x < kW; x += 7)
            ASSERT_NEAR(channel(ml.image, x, y, 0), 1.0f, 1e-4f) << x << "," << y;
}

TEST(Multilayer, LayersFarApartCompositeWithTheOverOperator) {
    // Two large BLEND panes (α = 0.5), red in focus and green three times farther, over a blue
    // background. Their depths are far apart, so they are separate groups: the over operator
    // gives 0.5 red + 0.25 green + 0.25 blue at the centre. The paper's single additive group
    // (additive_gap = inf) sums the opacities to 1 and hides the background.
    const raster::View view = testView();
    raster::Scene scene;
    scene.background = {0.0f, 0.0f, 1.0f};
    const int32_t red =
        addMaterial(scene, flatMaterial({1.0f, 0.0f, 0.0f, 0.5f}, raster::AlphaMode::Blend));
    const int32_t green =
        addMaterial(scene, flatMaterial({0.0f, 1.0f, 0.0f, 0.5f}, raster::AlphaMode::Blend));
    addQuad(scene, -300.0f, -300.0f, 300.0f, 300.0f, 300.0f, green);
    addQuad(scene, -100.0f, -100.0f, 100.0f, 100.0f, kFocus, red);
    const dof::ThinLens lens = dof::makeThinLens(view, 2.0f, kFocus);
    dof::MultilayerSettings settings;
    settings.color_format = raster::ColorFormat::Float32;
    const MlRun grouped = runMultilayer(scene, view, lens, settings);
    EXPECT_NEAR(channel(grouped.image, 32, 32, 0), 0.5f, 1e-3f);
    EXPECT_NEAR(channel(grouped.image, 32, 32, 1), 0.25f, 1e-3f);
    EXPECT_NEAR(channel(grouped.image, 32, 32, 2), 0.25f, 1e-3f);
    settings.additive_gap = std::numeric_limits<float>::infinity();
    const MlRun one_group = runMultilayer(scene, view, lens, settings);
    EXPECT_NEAR(channel(one_group.image, 32, 32, 1), 0.5f, 1e-3f);
    EXPECT_NEAR(channel(one_group.image, 32, 32, 2), 0.0f, 1e-3f);
}

// Variance of the line-spread function of a vertical step edge in one row (see accum_test.cpp):
// a uniform disk of radius R has an LSF with variance R^2 / 4.
double edgeVariance(const dof::MultilayerImage& f, uint32_t row) {
    double sum = 0.0, mean = 0.0, var = 0.0;
    std::vector<double> lsf(f.width, 0.0);
    for (uint32_t x = 1; x < f.width; ++x) {
        lsf[x] = double(channel(f, x, row, 0)) - double(channel(f, x - 1, row, 0));
        sum += lsf[x];
        mean += lsf[x] * double(x);
    }
    mean /= sum;
    for (uint32_t x = 1; x < f.width; ++x)
        var += lsf[x] * (double(x) - mean) * (double(x) - mean);
    return var / sum;
}

TEST(Multilayer, BlurSizeTracksTheLens) {
    // The blur radius of a step edge, from the LSF variance minus the 1/12 px² of point
    // sampling, matches |C(d)|. Mip levels blur edges that fall on a cell boundary less than
    // edges inside a cell (the mip-map's pixel structure, §5.2 Fig. 3), so the variance is
    // averaged over four edge positions one pixel apart.
    const raster::View view = testView();
    for (float aperture : {6.0f, 12.0f, 24.0f})
        for (float d : {200.0f / 3.0f, 200.0f}) {
            const dof::ThinLens lens = dof::makeThinLens(view, aperture, kFocus);
            const double coc = double(std::fabs(dof::cocRadiusPx(lens, d)));
            for (uint32_t mip : {0u, 2u}) {
                double var = 0.0;
                for (int shift = 0; shift < 4; ++shift) {
                    raster::Scene scene;
                    const int32_t white =
                        addMaterial(scene, flatMaterial({1.0f, 1.0f, 1.0f, 1.0f}));
                    const int32_t black =
                        addMaterial(scene, flatMaterial({0.0f, 0.0f, 0.0f, 1.0f}));
                    const float s = d / kFocus;
                    const float x0 = float(shift) * s;
                    addQuad(scene, x0, -200.0f * s, 200.0f * s, 200.0f * s, d, white);
                    addQuad(scene, -200.0f * s, -200.0f * s, x0, 200.0f * s, d, black);
                    dof::MultilayerSettings settings;
                    settings.mip_levels = mip;
                    const MlRun ml = runMultilayer(scene, view, lens, settings);
                    for (uint32_t row : {20u, 32u, 44u})
                        var += edgeVariance(ml.image, row) / 12.0;
                }
                const double radius = 2.0 * std::sqrt(std::max(0.0, var - 1.0 / 12.0));
                EXPECT_NEAR(radius, coc, 0.1 * coc + 0.25)
                    << "E = " << aperture << " d = " << d << " mip " << mip;
            }
        }
}

TEST(Multilayer, TruncationKeepsTheImageAndShortensLists) {
    const raster::View view = testView();
    raster::Scene scene = checkerWall(200.0f);
    const int32_t red = addMaterial(scene, flatMaterial({1.0f, 0.0f, 0.0f, 1.0f}));
    addQuad(scene, -10.0f, -10.0f, 10.0f, 10.0f, 60.0f, red);
    const dof::ThinLens lens = dof::makeThinLens(view, 12.0f, kFocus);
    dof::MultilayerSettings settings;
    settings.stack_levels = 3;
    settings.truncate = false;
    const MlRun full = runMultilayer(scene, view, lens, settings);
    settings.truncate = true;
    const MlRun cut = runMultilayer(scene, view, lens, settings);
    uint64_t full_frags = 0, cut_frags = 0, dropped = 0;
    // Box and aperture levels (the default filter) counted together.
    for (const auto* levels : {&full.stats.levels, &full.stats.apertures})
        for (const dof::MultilayerLevelStats& l : *levels)
            full_frags += l.fragments;
    for (const auto* levels : {&cut.stats.levels, &cut.stats.apertures})
        for (const dof::MultilayerLevelStats& l : *levels)
            cut_frags += l.fragments, dropped += l.truncated;
    EXPECT_LT(cut_frags, full_frags);
    EXPECT_GT(dropped, 0u);
    float max_diff = 0.0f;
    for (size_t i = 0; i < full.image.rgba.size(); ++i)
        max_diff = std::max(max_diff, std::fabs(full.image.rgba[i] - cut.image.rgba[i]));
    EXPECT_LT(max_diff, 1e-6f);
}

TEST(Multilayer, AutoLevelsCoverTheLargestCoc) {
    const raster::View view = testView();
    const raster::Scene scene = checkerWall(200.0f / 3.0f); // C = -12 px for E = 24
    const dof::ThinLens lens = dof::makeThinLens(view, 24.0f, kFocus);
    const MlRun ml = runMultilayer(scene, view, lens);
    EXPECT_NEAR(ml.stats.max_coc_px, 12.0f, 1e-3f);
    ASSERT_FALSE(ml.stats.levels.empty());
    ASSERT_GE(ml.stats.traversal.size(), 2u);
    EXPECT_GE(ml.stats.traversal.back().radius_px, 12.0);
    EXPECT_LT(ml.stats.traversal[ml.stats.traversal.size() - 2].radius_px, 12.0);
    EXPECT_EQ(ml.stats.mip_levels, 1u);
}

TEST(Multilayer, TransparentPaneTintsWhatIsBehindIt) {
    // A BLEND pane (α = 0.5) in focus in front of an in-focus wall: over-blended, unblurred.
    const raster::View view = testView();
    raster::Scene scene = checkerWall(kFocus);
    const int32_t glass =
        addMaterial(scene, flatMaterial({0.0f, 0.0f, 1.0f, 0.5f}, raster::AlphaMode::Blend));
    addQuad(scene, -100.0f * 0.99f, -100.0f * 0.99f, 100.0f * 0.99f, 100.0f * 0.99f, kFocus * 0.99f,
            glass);
    const raster::Frame wall = render(checkerWall(kFocus), view);
    dof::MultilayerSettings settings;
    settings.color_format = raster::ColorFormat::Float32;
    settings.epsilon = 0.001f;
    const MlRun ml = runMultilayer(scene, view, dof::makeThinLens(view, 1.0f, kFocus), settings);
    for (uint32_t y = 4; y < kH; y += 9)
        for (uint32_t x = 4; x < kW; x += 9) {
            const glm::vec4 w = pixel(wall, x, y);
            EXPECT_NEAR(channel(ml.image, x, y, 0), 0.5f * w.r, 2e-3f);
            EXPECT_NEAR(channel(ml.image, x, y, 2), 0.5f + 0.5f * w.b, 2e-3f);
        }
}

TEST(Multilayer, DeterministicAcrossThreadCounts) {
    raster::Result<raster::Scene> scene = scenes::makeBuiltinScene("railing");
    ASSERT_TRUE(scene.ok());
    const raster::View view = raster::viewFromCamera(scene->cameras[0], 192, 108);
    const dof::ThinLens lens =
        dof::makeThinLens(view, scene->lens->aperture_radius, scene->lens->focus_distance);
    // Configurations mip/stack, box (b) or aperture levels (a: disc, t: triangle, whose near
    // and far levels differ).
    for (const char* config : {"1/auto a", "1/auto t", "2/auto b", "0/3 b", "4/0 b", "4/0 a"}) {
        dof::MultilayerSettings settings;
        settings.mip_levels = uint32_t(config[0] - '0');
        settings.stack_levels = config[2] == 'a' ? -1 : int32_t(config[2] - '0');
        const char kind = config[std::strlen(config) - 1];
        settings.filter = kind == 'b' ? dof::LevelFilter::Box : dof::LevelFilter::Aperture;
        if (kind == 't') {
            settings.aperture.kind = dof::ApertureKind::Polygon;
            settings.aperture.blades = 3;
        }
        const uint64_t h0 = hashImage(runMultilayer(*scene, view, lens, settings, 0).image);
        for (uint32_t threads : {1u, 2u, 3u, 8u})
            EXPECT_EQ(hashImage(runMultilayer(*scene, view, lens, settings, threads).image), h0)
                << config << " threads " << threads;
    }
}

TEST(Multilayer, UnreadCellsLeftEmptyGiveTheSameBytes) {
    // Aperture cells that cannot hold a fragment the traversal reads are not merged
    // (dof::LevelReads); the image is the same bytes as with every cell merged, and cells are
    // skipped. railing: a near railing, a sign in focus and a far wall; demo: a floor through
    // every depth. Disc and triangle (near and far levels apart), mean and nearest depth,
    // truncation off.
    for (const char* name : {"railing", "demo"}) {
        raster::Result<raster::Scene> scene = scenes::makeBuiltinScene(name);
        ASSERT_TRUE(scene.ok());
        const raster::View view = raster::viewFromCamera(scene->cameras[0], 160, 120);
        const dof::ThinLens lens =
            dof::makeThinLens(view, scene->lens->aperture_radius, scene->lens->focus_distance);
        for (const char* config : {"default", "triangle", "nearest", "truncate off"}) {
            dof::MultilayerSettings on;
            if (std::strcmp(config, "triangle") == 0) {
                on.aperture.kind = dof::ApertureKind::Polygon;
                on.aperture.blades = 3;
            }
            on.mean_depth = std::strcmp(config, "nearest") != 0;
            on.truncate = std::strcmp(config, "truncate off") != 0;
            dof::MultilayerSettings off = on;
            off.skip_unread_cells = false;
            const MlRun a = runMultilayer(*scene, view, lens, on, 2);
            const MlRun b = runMultilayer(*scene, view, lens, off, 2);
            EXPECT_EQ(hashImage(a.image), hashImage(b.image)) << name << " " << config;
            uint64_t skipped_on = 0, skipped_off = 0, cells = 0;
            for (const dof::MultilayerLevelStats& l : a.stats.apertures) {
                skipped_on += l.cells_skipped;
                cells += uint64_t(l.width) * l.height;
            }
            for (const dof::MultilayerLevelStats& l : b.stats.apertures)
                skipped_off += l.cells_skipped;
            EXPECT_GT(skipped_on, cells / 10) << name << " " << config;
            EXPECT_EQ(skipped_off, 0u) << name << " " << config;
        }
    }
}

TEST(Multilayer, BadSettingsNameTheSetting) {
    dof::MultilayerSettings s;
    s.epsilon = -1.0f;
    raster::Status st = dof::validate(s);
    EXPECT_FALSE(st.ok());
    EXPECT_NE(st.message().find("multilayer settings: epsilon"), std::string::npos);
    s = {};
    s.mip_levels = 10;
    s.stack_levels = 10;
    st = dof::validate(s);
    EXPECT_NE(st.message().find("multilayer settings: mip_levels"), std::string::npos);
    s = {};
    s.fragments_per_pixel = 5000;
    EXPECT_NE(dof::validate(s).message().find("multilayer settings: fragments_per_pixel"),
              std::string::npos);
    s = {};
    s.epsilon = NAN;
    EXPECT_FALSE(dof::validate(s).ok());
    s = {};
    s.aperture_grids = {4, 9};
    EXPECT_NE(dof::validate(s).message().find("multilayer settings: aperture_grids"),
              std::string::npos);
    s.aperture_grids = {4, 8}; // not below twice the first
    EXPECT_FALSE(dof::validate(s).ok());
    s.aperture_grids = {5, 4};
    EXPECT_FALSE(dof::validate(s).ok());
    s = {};
    s.additive_gap = NAN;
    EXPECT_NE(dof::validate(s).message().find("multilayer settings: additive_gap"),
              std::string::npos);
}

} // namespace
} // namespace focal::test
