// Layered target and fragment lists (issue 5).
#include "support/test_util.h"

#include <raster/task_pool.h>
#include <scenes/builtin.h>

#include <gtest/gtest.h>

#include <cmath>

namespace focal::test {
namespace {

using raster::AlphaMode;
using raster::LayerRouting;

// Quads at several depths that overlap on screen, none crossing the layer bounds below, plus one
// long slanted quad from d = 2 to d = 14 that crosses them.
raster::Scene stackScene(bool with_crossing) {
    raster::Scene s;
    s.background = glm::vec3(0.0f);
    // 2.95, 6.1 and 11.5 lie in the 10% overlap of two layers (bounds 3, 6, 12 below).
    const float depths[] = {2.0f, 2.95f, 4.0f, 6.1f, 8.0f, 11.5f, 16.0f, 30.0f};
    for (int i = 0; i < 8; ++i) {
        const float d = depths[i], h = 0.25f * d;
        const float cx = 0.12f * d * float(i % 3 - 1), cy = 0.1f * d * float(i % 2) - 0.05f * d;
        const int32_t m = addMaterial(
            s, flatMaterial({0.1f + 0.1f * float(i), 0.9f - 0.1f * float(i), 0.5f, 1.0f}));
        addMesh(s,
                {{cx - h, cy - h, -d},
                 {cx + h, cy - h, -d},
                 {cx + h, cy + h, -d},
                 {cx - h, cy + h, -d}},
                {0, 1, 2, 0, 2, 3}, m);
    }
    if (with_crossing) {
        const int32_t m = addMaterial(s, flatMaterial({1.0f, 1.0f, 0.0f, 1.0f}));
        addMesh(s,
                {{-0.3f, -0.2f, -2.2f},
                 {0.3f, -0.2f, -2.2f},
                 {0.3f, 0.6f, -14.0f},
                 {-0.3f, 0.6f, -14.0f}},
                {0, 1, 2, 0, 2, 3}, m);
    }
    return s;
}

raster::View stackView() {
    raster::View v = pixelView(96, 72, 80.0f);
    v.znear = 1.0f;
    v.zfar = 100.0f;
    return v;
}

raster::LayeredTarget layers(const raster::Scene& s, const raster::View& v,
                             raster::LayeredTargetDesc desc, uint32_t threads = 0,
                             uint32_t tile = 64) {
    raster::TaskPool pool(threads);
    raster::Renderer r(pool);
    raster::LayeredTarget out;
    raster::RenderOptions o;
    o.tile_size = tile;
    EXPECT_TRUE(r.renderLayers(s, v, o, desc, out).ok());
    return out;
}

raster::FragmentLists lists(const raster::Scene& s, const raster::View& v,
                            raster::FragmentListDesc desc, uint32_t threads = 0,
                            uint32_t tile = 64) {
    raster::TaskPool pool(threads);
    raster::Renderer r(pool);
    raster::FragmentLists out;
    raster::RenderOptions o;
    o.tile_size = tile;
    EXPECT_TRUE(r.renderFragmentLists(s, v, o, desc, out).ok());
    return out;
}

raster::LayeredTargetDesc stackDesc(LayerRouting routing, float overlap) {
    raster::LayeredTargetDesc d;
    d.bounds = {1.0f, 3.0f, 6.0f, 12.0f, 100.0f};
    d.routing = routing;
    d.overlap = overlap;
    return d;
}

uint64_t hashLayers(const raster::LayeredTarget& t) {
    raster::Frame f;
    f.color = t.color.float32;
    for (const Imath::half h : t.color.half)
        f.color.push_back(float(h));
    f.depth = t.depth;
    return hashFrame(f);
}

TEST(LayeredTarget, ExactRoutingEqualsRendersClippedToEachLayer) {
    const raster::Scene s = stackScene(true);
    const raster::View v = stackView();
    const raster::LayeredTargetDesc desc = stackDesc(LayerRouting::PerFragment, 0.1f);
    const raster::LayeredTarget t = layers(s, v, desc);
    for (uint32_t l = 0; l < t.layer_count; ++l) {
        // The paper's definition: a render with clipping planes at the layer's bounds.
        const raster::LayerInterval iv = raster::overlappedInterval(desc, l);
        raster::View clipped = v;
        clipped.znear = std::max(iv.near_d, v.znear);
        clipped.zfar = std::min(iv.far_d, v.zfar);
        const raster::Frame ref = render(s, clipped);
        size_t mismatched = 0, covered = 0;
        for (size_t p = 0; p < t.pixelCount(); ++p) {
            const bool in_ref = ref.depth.load(p) < raster::kFarDepth;
            const glm::vec4 c = t.color.load(t.index(l, p));
            covered += in_ref;
            if (in_ref != (c.a > 0.0f)) {
                ++mismatched; // only where a clipped triangle's new edge is snapped differently
                continue;
            }
            if (in_ref) {
                EXPECT_EQ(glm::vec3(c),
                          glm::vec3(pixel(ref, uint32_t(p % v.width), uint32_t(p / v.width))))
                    << "layer " << l << " pixel " << p;
            }
        }
        EXPECT_GT(covered, 0u) << "layer " << l;
        EXPECT_LE(mismatched, t.width) << "layer " << l; // at most a row's worth along the cut
    }
}

TEST(LayeredTarget, PaperRoutingDiffersOnlyWhereTrianglesCrossBounds) {
    const raster::View v = stackView();
    // Without crossing triangles and without overlap the two policies agree bit for bit.
    const raster::Scene plain = stackScene(false);
    EXPECT_EQ(hashLayers(layers(plain, v, stackDesc(LayerRouting::MaxVertexDepth, 0.0f))),
              hashLayers(layers(plain, v, stackDesc(LayerRouting::PerFragment, 0.0f))));
    // With the slanted quad, differences stay inside its screen footprint.
    const raster::Scene crossing = stackScene(true);
    const raster::LayeredTarget paper =
        layers(crossing, v, stackDesc(LayerRouting::MaxVertexDepth, 0.0f));
    const raster::LayeredTarget exact =
        layers(crossing, v, stackDesc(LayerRouting::PerFragment, 0.0f));
    raster::Scene only_crossing = crossing;
    only_crossing.instances.erase(only_crossing.instances.begin(),
                                  only_crossing.instances.end() - 1);
    const raster::Frame footprint = render(only_crossing, v);
    size_t differing = 0;
    for (uint32_t l = 0; l < paper.layer_count; ++l)
        for (size_t p = 0; p < paper.pixelCount(); ++p) {
            const size_t i = paper.index(l, p);
            if (paper.color.load(i) == exact.color.load(i) &&
                paper.depth.load(i) == exact.depth.load(i))
                continue;
            ++differing;
            EXPECT_LT(footprint.depth.load(p), raster::kFarDepth)
                << "layer " << l << " pixel " << p;
        }
    EXPECT_GT(differing, 0u); // the crossing quad does land in other layers
}

TEST(LayeredTarget, BlendSurfacesGoToTheTransparentPlane) {
    // A 40% red pane (d = 4) and a 50% blue pane (d = 5) in front of an opaque wall (d = 8), all
    // in one layer: the opaque plane keeps the wall untouched, the transparent plane holds the
    // panes composited in primitive order (premultiplied) at the nearer pane's depth.
    raster::Scene s;
    addMesh(s, {{-50, -50, -8}, {50, -50, -8}, {50, 50, -8}, {-50, 50, -8}}, {0, 1, 2, 0, 2, 3},
            addMaterial(s, flatMaterial({0.0f, 1.0f, 0.0f, 1.0f})));
    addMesh(s, {{-50, -50, -5}, {50, -50, -5}, {50, 50, -5}, {-50, 50, -5}}, {0, 1, 2, 0, 2, 3},
            addMaterial(s, flatMaterial({0.0f, 0.0f, 1.0f, 0.5f}, AlphaMode::Blend)));
    addMesh(s, {{-50, -50, -4}, {50, -50, -4}, {50, 50, -4}, {-50, 50, -4}}, {0, 1, 2, 0, 2, 3},
            addMaterial(s, flatMaterial({1.0f, 0.0f, 0.0f, 0.4f}, AlphaMode::Blend)));
    const raster::View v = stackView();
    raster::LayeredTargetDesc desc;
    desc.bounds = {1.0f, 100.0f};
    for (LayerRouting routing : {LayerRouting::MaxVertexDepth, LayerRouting::PerFragment}) {
        desc.routing = routing;
        const raster::LayeredTarget t = layers(s, v, desc);
        ASSERT_TRUE(t.hasTransparency());
        const size_t p = t.index(0, size_t(36) * 96 + 48);
        const glm::vec4 opaque = t.color.load(p);
        EXPECT_EQ(opaque, glm::vec4(0.0f, 1.0f, 0.0f, 1.0f));
        EXPECT_NEAR(raster::distanceFromDepth(v, t.depth.load(p)), 8.0f, 1e-3f);
        // red over (blue over nothing): rgb = 0.4 red + 0.6 * 0.5 blue, alpha = 1 - 0.6 * 0.5.
        const glm::vec4 tc = t.transparent_color.load(p);
        EXPECT_NEAR(tc.r, 0.4f, 1e-6f);
        EXPECT_NEAR(tc.b, 0.3f, 1e-6f);
        EXPECT_NEAR(tc.a, 0.7f, 1e-6f);
        EXPECT_NEAR(raster::distanceFromDepth(v, t.transparent_depth.load(p)), 4.0f, 1e-3f);
        EXPECT_TRUE(t.transparent_top_alpha.empty()); // no G-buffer asked for
    }
    // With a G-buffer the plane keeps its top pane's surface and opacity (the last composited
    // in primitive order: the red one) for re-shading.
    desc.gbuffer = true;
    const raster::LayeredTarget g = layers(s, v, desc);
    const size_t p = g.index(0, size_t(36) * 96 + 48);
    ASSERT_EQ(g.transparent_top_alpha.size(), g.pixelCount());
    EXPECT_EQ(g.transparent_top_alpha[p], 0.4f);
    EXPECT_EQ(g.transparent_gbuffer[p].base_color, glm::vec3(1.0f, 0.0f, 0.0f));
    EXPECT_EQ(g.transparent_top_alpha[g.index(0, 0)], 0.4f); // the panes cover the image
    // Scenes without BLEND materials get no transparent planes (no memory).
    EXPECT_FALSE(
        layers(stackScene(false), v, stackDesc(LayerRouting::PerFragment, 0.1f)).hasTransparency());
}

TEST(LayeredTarget, BitIdenticalAcrossThreadsAndTiles) {
    const raster::Scene s = stackScene(true);
    const raster::View v = stackView();
    for (LayerRouting routing : {LayerRouting::MaxVertexDepth, LayerRouting::PerFragment}) {
        const uint64_t ref = hashLayers(layers(s, v, stackDesc(routing, 0.1f), 0, 64));
        for (uint32_t threads : {1u, 2u, 3u, 8u})
            for (uint32_t tile : {16u, 32u, 128u})
                EXPECT_EQ(hashLayers(layers(s, v, stackDesc(routing, 0.1f), threads, tile)), ref);
    }
}

TEST(LayeredTarget, LightQueueGivesTheBytesOfFragmentsShadedOneByOne) {
    // Lit fragments routed to one layer (MaxVertexDepth) wait in the tile raster's light queue,
    // their depth stored at once and their colour when a batch of 16 is shaded (LayerSink::
    // queuesLight); with a G-buffer, which the queue does not carry, each quad pair is shaded
    // and written whole. Both must leave the same colour and depth in every layer, overlapped
    // copies included, on demo (textured, lit and emissive materials).
    raster::Result<raster::Scene> s = scenes::makeBuiltinScene("demo");
    ASSERT_TRUE(s.ok());
    const raster::View v = raster::viewFromCamera(s->cameras[0], 160, 120);
    raster::LayeredTargetDesc queued;
    queued.bounds = {0.5f, 2.0f, 4.0f, 6.0f, 10.0f, 100.0f};
    queued.routing = LayerRouting::MaxVertexDepth;
    queued.overlap = 0.1f;
    raster::LayeredTargetDesc whole = queued;
    whole.gbuffer = true;
    for (uint32_t threads : {0u, 2u}) {
        const raster::LayeredTarget a = layers(*s, v, queued, threads, 16);
        const raster::LayeredTarget b = layers(*s, v, whole, threads, 16);
        ASSERT_FALSE(a.color.float32.empty());
        EXPECT_EQ(a.color.float32, b.color.float32) << threads;
        EXPECT_EQ(a.depth.float32, b.depth.float32) << threads;
        EXPECT_EQ(a.transparent_color.float32, b.transparent_color.float32) << threads;
    }
}

TEST(LayeredTarget, HalfAndUnorm16StorageStayWithinTheirPrecision) {
    const raster::Scene s = stackScene(true);
    const raster::View v = stackView();
    raster::LayeredTargetDesc d = stackDesc(LayerRouting::PerFragment, 0.1f);
    const raster::LayeredTarget full = layers(s, v, d);
    d.color_format = raster::ColorFormat::Half;
    d.depth_format = raster::DepthFormat::Unorm16;
    const raster::LayeredTarget small = layers(s, v, d);
    EXPECT_LT(small.bytes(), full.bytes());
    for (size_t i = 0; i < full.pixelCount() * full.layer_count; ++i) {
        const float zf = full.depth.load(i), zs = small.depth.load(i);
        if (zf < 1.0f && std::abs(zf - zs) <= 0.5f / 65535.0f + 1e-7f) {
            const glm::vec4 cf = full.color.load(i), cs = small.color.load(i);
            for (int k = 0; k < 4; ++k) // half: 11 significant bits
                EXPECT_LE(std::abs(cf[k] - cs[k]), std::abs(cf[k]) * 0x1p-11f + 1e-7f);
        }
    }
}

// Renderer::promiseSceneUnchanged: the layers after a pinhole of the same scene and eye reuse its
// geometry and bins, with the bytes of a fresh render; a different eye, or a promise spent on a
// failed call, makes them again.
TEST(LayeredTarget, GeometryIsKeptOnlyWhenPromisedForTheSameSceneAndView) {
    raster::Scene s = stackScene(true);
    const raster::View v = stackView();
    const raster::LayeredTargetDesc desc = stackDesc(LayerRouting::MaxVertexDepth, 0.1f);
    raster::TaskPool pool(0);
    raster::Renderer r(pool);
    raster::Frame pinhole;
    raster::LayeredTarget out;
    raster::FrameStats stats;

    ASSERT_TRUE(r.render(s, v, {}, pinhole).ok());
    r.promiseSceneUnchanged();
    ASSERT_TRUE(r.renderLayers(s, v, {}, desc, out, &stats).ok());
    EXPECT_EQ(hashLayers(out), hashLayers(layers(s, v, desc)));
    EXPECT_EQ(stats.ms_geometry, 0.0); // kept, not made
    EXPECT_GT(stats.triangles_setup, 0u);

    raster::View moved = v;
    moved.eye.x += 0.3f;
    ASSERT_TRUE(r.render(s, v, {}, pinhole).ok());
    r.promiseSceneUnchanged();
    ASSERT_TRUE(r.renderLayers(s, moved, {}, desc, out).ok());
    EXPECT_EQ(hashLayers(out), hashLayers(layers(s, moved, desc)));
    EXPECT_NE(hashLayers(out), hashLayers(layers(s, v, desc)));

    // A promise is for the next call only, even when that call fails.
    ASSERT_TRUE(r.render(s, v, {}, pinhole).ok());
    r.promiseSceneUnchanged();
    raster::LayeredTargetDesc bad = desc;
    bad.overlap = 2.0f;
    ASSERT_FALSE(r.renderLayers(s, v, {}, bad, out).ok());
    s.instances[0].world[3].x += 0.5f; // the caller changes the scene afterwards
    ASSERT_TRUE(r.renderLayers(s, v, {}, desc, out).ok());
    EXPECT_EQ(hashLayers(out), hashLayers(layers(s, v, desc)));
}

// A promise for another view of the same scene (accum's views) keeps the world-space vertices
// and makes the rest again: the bytes of a fresh render of that view, at 0 and 2 threads, for
// moved eyes, sheared lens views, and an instance whose transform is not affine (its world w is
// not 1: a clip position made from (world, 1) would differ).
TEST(Renderer, PromisedSceneKeepsItsWorldVerticesForAnotherView) {
    for (const char* name : {"demo", "foliage"}) {
        raster::Result<raster::Scene> scene = scenes::makeBuiltinScene(name);
        ASSERT_TRUE(scene.ok()) << name;
        scene->instances[0].world[0][3] = 0.01f; // projective: w = 1 + 0.01 x
        const raster::View v = raster::viewFromCamera(scene->cameras[0], 96, 64);
        raster::View moved = v;
        moved.eye.x += 0.2f;
        raster::View sheared = v;
        sheared.lens_offset = {0.05f, -0.03f};
        for (uint32_t threads : {0u, 2u}) {
            raster::TaskPool pool(threads);
            raster::Renderer r(pool);
            raster::Frame f;
            ASSERT_TRUE(r.render(*scene, v, {}, f).ok());
            for (const raster::View& next : {moved, sheared, v}) {
                r.promiseSceneUnchanged();
                ASSERT_TRUE(r.render(*scene, next, {}, f).ok());
                EXPECT_EQ(hashFrame(f), hashFrame(render(*scene, next, {}, threads)))
                    << name << ", " << threads << " threads";
            }
        }
    }
}

TEST(LayeredTarget, InvalidBoundsAreErrors) {
    raster::TaskPool pool(0);
    raster::Renderer r(pool);
    raster::LayeredTarget out;
    raster::LayeredTargetDesc d;
    for (std::vector<float> bounds : std::vector<std::vector<float>>{
             {}, {1.0f}, {2.0f, 1.0f}, {0.0f, 1.0f}, {1.0f, NAN}, {1.0f, 1.0f}}) {
        d.bounds = bounds;
        EXPECT_FALSE(r.renderLayers(stackScene(false), stackView(), {}, d, out).ok());
    }
    d.bounds = {1.0f, 2.0f};
    d.overlap = 1.5f;
    EXPECT_FALSE(r.renderLayers(stackScene(false), stackView(), {}, d, out).ok());
}

// RenderOptions::depth_only: the depth buffers of a shaded render, bit for bit, with opaque
// surfaces unshaded (the background where they are), on scenes with OPAQUE, MASK (foliage's
// leaves) and BLEND (glass) surfaces, at 0 and 2 threads.
TEST(Renderer, DepthOnlyGivesTheShadedRendersDepths) {
    for (const char* name : {"demo", "foliage", "glass"}) {
        raster::Result<raster::Scene> scene = scenes::makeBuiltinScene(name);
        ASSERT_TRUE(scene.ok()) << name;
        const raster::View view = raster::viewFromCamera(scene->cameras[0], 96, 64);
        for (uint32_t threads : {0u, 2u}) {
            raster::TaskPool pool(threads);
            raster::Renderer renderer(pool);
            raster::RenderOptions options;
            raster::Frame shaded, depth;
            ASSERT_TRUE(renderer.render(*scene, view, options, shaded).ok());
            options.depth_only = true;
            ASSERT_TRUE(renderer.render(*scene, view, options, depth).ok());
            EXPECT_EQ(depth.depth.float32, shaded.depth.float32) << name;
            EXPECT_EQ(depth.transparent_depth.float32, shaded.transparent_depth.float32) << name;
            size_t unshaded = 0; // covered pixels left at the background
            for (size_t i = 0; i < size_t(view.width) * view.height; ++i)
                unshaded += depth.depth.load(i) < raster::kFarDepth &&
                            depth.color[i * 4] == scene->background.r &&
                            shaded.color[i * 4] != scene->background.r;
            EXPECT_GT(unshaded, 100u) << name;
        }
    }
}

TEST(FragmentLists, EqualDepthPeeling) {
    const raster::Scene s = stackScene(true);
    const raster::View v = stackView();
    raster::FragmentListDesc desc;
    desc.max_per_pixel = 0; // keep all
    desc.color_format = raster::ColorFormat::Float32;
    const raster::FragmentLists fl = lists(s, v, desc);
    EXPECT_GT(fl.max_list_length, 3u);
    // Peel front to back with the ordinary frame target; peel k is the k-th list entry.
    raster::Frame peeled = render(s, v);
    for (uint32_t k = 0; k < fl.max_list_length; ++k) {
        for (size_t p = 0; p < size_t(v.width) * v.height; ++p) {
            if (k < fl.count(p)) {
                const uint32_t i = fl.offsets[p] + k;
                ASSERT_EQ(fl.depth.load(i), peeled.depth.load(p)) << "peel " << k << " px " << p;
                EXPECT_EQ(fl.color.load(i),
                          pixel(peeled, uint32_t(p % v.width), uint32_t(p / v.width)));
            } else {
                EXPECT_EQ(peeled.depth.load(p), raster::kFarDepth) << "peel " << k << " px " << p;
            }
        }
        raster::RenderOptions o;
        o.peel_depth = &peeled.depth;
        raster::Frame next = render(s, v, o);
        peeled = std::move(next);
    }
}

TEST(FragmentLists, CapKeepsTheClosestN) {
    const raster::Scene s = stackScene(true);
    const raster::View v = stackView();
    raster::FragmentListDesc all;
    all.max_per_pixel = 0;
    raster::FragmentListDesc two = all;
    two.max_per_pixel = 2;
    const raster::FragmentLists a = lists(s, v, all), b = lists(s, v, two);
    // Early rejection skips fragments with two nearer ones already in their pixel (no MASK
    // here, so every rejected fragment would have been collected).
    EXPECT_GT(b.fragments_rejected, 0u);
    EXPECT_EQ(a.fragments_rejected, 0u);
    EXPECT_EQ(a.fragments_collected, b.fragments_collected + b.fragments_rejected);
    EXPECT_LT(b.fragments_kept, a.fragments_kept);
    for (size_t p = 0; p < size_t(v.width) * v.height; ++p) {
        ASSERT_EQ(b.count(p), std::min(a.count(p), 2u));
        for (uint32_t k = 0; k < b.count(p); ++k) {
            EXPECT_EQ(b.depth.load(b.offsets[p] + k), a.depth.load(a.offsets[p] + k));
            EXPECT_EQ(b.primitive[b.offsets[p] + k], a.primitive[a.offsets[p] + k]);
        }
        for (uint32_t k = 1; k < a.count(p); ++k) // sorted front to back
            EXPECT_LE(a.depth.load(a.offsets[p] + k - 1), a.depth.load(a.offsets[p] + k));
    }
}

TEST(FragmentLists, EarlyRejectionKeepsTheSameListsOnFoliage) {
    // Alpha-masked leaves many deep: rejecting before shading the fragments that already have N
    // nearer ones changes no kept fragment (colour, depth, primitive) for any cap.
    raster::Result<raster::Scene> s = scenes::makeBuiltinScene("foliage");
    ASSERT_TRUE(s.ok());
    const raster::View v = raster::viewFromCamera(s->cameras[0], 160, 120);
    for (uint32_t cap : {1u, 4u, 16u}) {
        raster::FragmentListDesc early;
        early.max_per_pixel = cap;
        raster::FragmentListDesc full = early;
        full.early_reject = false;
        const raster::FragmentLists e = lists(*s, v, early), f = lists(*s, v, full);
        EXPECT_GT(e.fragments_rejected, 0u) << cap;
        EXPECT_LT(e.fragments_collected, f.fragments_collected) << cap;
        ASSERT_EQ(e.offsets, f.offsets) << cap;
        EXPECT_EQ(e.primitive, f.primitive) << cap;
        EXPECT_EQ(e.color.half, f.color.half) << cap;
        EXPECT_EQ(e.depth.float32, f.depth.float32) << cap;
    }
}

TEST(FragmentLists, HiddenFragmentsGiveTheirSlotsToVisibleOnes) {
    // Full-view quads, near to far: a BLEND pane at 1.5 (hides nothing), an opaque 1.6, an
    // opaque 1.7 (within 20 % behind 1.6: hidden), opaque 2.5, 2.9 (hidden by 2.5), 4.0, 5.0
    // and 6.0. Submitted near to far, so that early rejection meets every fragment with its
    // nearer ones collected: 4.0 has four nearer ones but must be kept; 6.0 has 1.5, 2.5, 4.0
    // and 5.0 spaced by more than 1.2 in front of it and is rejected.
    raster::Scene s;
    s.background = glm::vec3(0.0f);
    const float depths[] = {1.5f, 1.6f, 1.7f, 2.5f, 2.9f, 4.0f, 5.0f, 6.0f};
    for (float d : depths) {
        const bool pane = d == 1.5f;
        const int32_t m = addMaterial(
            s, flatMaterial({0.5f, 0.5f, 0.5f, pane ? 0.5f : 1.0f},
                            pane ? raster::AlphaMode::Blend : raster::AlphaMode::Opaque));
        addMesh(s, {{-d, -d, -d}, {d, -d, -d}, {d, d, -d}, {-d, d, -d}}, {0, 1, 2, 0, 2, 3}, m);
    }
    const raster::View v = stackView();
    auto centre = [&](const raster::FragmentLists& fl) {
        const size_t p = size_t(v.height / 2) * v.width + v.width / 2;
        std::vector<float> d;
        for (uint32_t i = fl.offsets[p]; i < fl.offsets[p + 1]; ++i)
            d.push_back(raster::distanceFromDepth(v, fl.depth.load(i)));
        return d;
    };
    auto near = [](const std::vector<float>& got, const std::vector<float>& want) {
        if (got.size() != want.size())
            return false;
        for (size_t i = 0; i < got.size(); ++i)
            if (std::abs(got[i] - want[i]) > 1e-3f * want[i])
                return false;
        return true;
    };
    raster::FragmentListDesc closest;
    closest.max_per_pixel = 4;
    raster::FragmentListDesc visible = closest;
    visible.hidden_epsilon = 0.2f;
    raster::FragmentListDesc visible_full = visible;
    visible_full.early_reject = false;
    const raster::FragmentLists a = lists(s, v, closest), b = lists(s, v, visible),
                                c = lists(s, v, visible_full);
    EXPECT_TRUE(near(centre(a), {1.5f, 1.6f, 1.7f, 2.5f}));
    EXPECT_TRUE(near(centre(b), {1.5f, 1.6f, 2.5f, 4.0f}));
    EXPECT_EQ(a.fragments_hidden, 0u);
    EXPECT_EQ(b.fragments_hidden, 2u * v.width * v.height);   // 1.7 and 2.9 everywhere
    EXPECT_EQ(b.fragments_rejected, 1u * v.width * v.height); // 6.0 everywhere
    EXPECT_EQ(c.fragments_hidden, b.fragments_hidden);
    EXPECT_EQ(b.offsets, c.offsets);
    EXPECT_EQ(b.depth.float32, c.depth.float32);
    EXPECT_EQ(b.primitive, c.primitive);
    raster::FragmentListDesc bad = visible;
    bad.hidden_epsilon = -1.0f;
    raster::TaskPool pool(0);
    raster::Renderer r(pool);
    raster::FragmentLists out;
    EXPECT_FALSE(r.renderFragmentLists(s, v, {}, bad, out).ok());
}

TEST(FragmentLists, EarlyRejectionKeepsTheSameListsWithHiddenFragments) {
    // With hidden fragments skipped, early rejection only rejects a fragment with N nearer ones
    // spaced by more than 1 + ε (see ListSink): on foliage the lists equal those of a full
    // collection for every cap and ε.
    raster::Result<raster::Scene> s = scenes::makeBuiltinScene("foliage");
    ASSERT_TRUE(s.ok());
    const raster::View v = raster::viewFromCamera(s->cameras[0], 160, 120);
    for (float eps : {0.05f, 0.2f, 1.0f})
        for (uint32_t cap : {1u, 4u, 16u}) {
            raster::FragmentListDesc early;
            early.max_per_pixel = cap;
            early.hidden_epsilon = eps;
            raster::FragmentListDesc full = early;
            full.early_reject = false;
            const raster::FragmentLists e = lists(*s, v, early), f = lists(*s, v, full);
            // Rejection needs N nearer fragments spaced by 1 + ε: rare for long or wide spacing.
            if (cap == 1 || (cap == 4 && eps <= 0.2f)) {
                EXPECT_GT(e.fragments_rejected, 0u) << cap << " " << eps;
            }
            if (cap > 1) { // with one slot, the nearest fragment is the whole list
                EXPECT_GT(f.fragments_hidden, 0u) << cap << " " << eps;
            }
            ASSERT_EQ(e.offsets, f.offsets) << cap << " " << eps;
            EXPECT_EQ(e.fragments_hidden, f.fragments_hidden) << cap << " " << eps;
            EXPECT_EQ(e.primitive, f.primitive) << cap << " " << eps;
            EXPECT_EQ(e.color.half, f.color.half) << cap << " " << eps;
            EXPECT_EQ(e.depth.float32, f.depth.float32) << cap << " " << eps;
        }
}

TEST(FragmentLists, OverflowFailsOrGrowsWithoutLoss) {
    const raster::Scene s = stackScene(true);
    const raster::View v = stackView();
    raster::FragmentListDesc desc;
    const raster::FragmentLists big = lists(s, v, desc);
    ASSERT_GT(big.fragments_collected, 100u);
    desc.node_capacity = 100;
    desc.on_overflow = raster::OverflowPolicy::Fail;
    raster::TaskPool pool(2);
    raster::Renderer r(pool);
    raster::FragmentLists out;
    const raster::Status st = r.renderFragmentLists(s, v, {}, desc, out);
    ASSERT_FALSE(st.ok());
    EXPECT_NE(st.message().find(std::to_string(big.fragments_collected)), std::string::npos)
        << st.message();
    EXPECT_NE(st.message().find("100"), std::string::npos);
    desc.on_overflow = raster::OverflowPolicy::Grow;
    ASSERT_TRUE(r.renderFragmentLists(s, v, {}, desc, out).ok());
    EXPECT_TRUE(out.grew);
    EXPECT_EQ(out.node_capacity_used, big.fragments_collected);
    EXPECT_EQ(out.offsets, big.offsets);
    EXPECT_EQ(out.primitive, big.primitive);
}

TEST(FragmentLists, BitIdenticalAcrossThreadsAndTilesOnFoliage) {
    raster::Result<raster::Scene> s = scenes::makeBuiltinScene("foliage");
    ASSERT_TRUE(s.ok());
    const raster::View v = raster::viewFromCamera(s->cameras[0], 120, 90);
    for (float eps : {0.0f, 0.2f}) { // the closest N; with hidden fragments skipped
        raster::FragmentListDesc desc;
        desc.hidden_epsilon = eps;
        const raster::FragmentLists ref = lists(*s, v, desc, 0, 64);
        EXPECT_GT(ref.max_list_length, 4u);
        EXPECT_EQ(ref.fragments_hidden > 0, eps > 0.0f);
        for (uint32_t threads : {1u, 3u, 8u})
            for (uint32_t tile : {16u, 32u, 128u}) {
                const raster::FragmentLists other = lists(*s, v, desc, threads, tile);
                EXPECT_EQ(other.offsets, ref.offsets);
                EXPECT_EQ(other.primitive, ref.primitive);
                EXPECT_EQ(other.depth.float32, ref.depth.float32);
                ASSERT_EQ(other.color.half.size(), ref.color.half.size());
                for (size_t i = 0; i < ref.color.half.size(); ++i)
                    ASSERT_EQ(other.color.half[i].bits(), ref.color.half[i].bits());
            }
    }
}

} // namespace
} // namespace focal::test
