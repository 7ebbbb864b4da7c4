// Multiview's frame driver (dof/multiview.h): validation, the pinhole and layered renders, the
// Tracer's lens constants, the setup stages, the tiles traced in parallel (multiview_tracer.h),
// the stats and the memory estimate. Consumes the caller's view, lens,
// samples, settings and render callbacks; produces the caller's RGBA image and MultiviewStats;
// scratch is the caller's MultiviewScratch or a local one.
#include "multiview_tracer.h"

#include <dof/multiview.h>
#include <raster/surface_shading.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>

namespace dof {

using raster::Status;
using namespace multiview_detail;

namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// Most cells walked in advance (PathCell; 20 bytes each).
constexpr double kMaxPathCells = double(1u << 22);
// Largest image offset a ray may reach (pixels): beyond it the lens is rejected as absurd for the
// view (offsets are then still exact in float and fit RayPath's int32 boxes).
constexpr float kMaxReachPx = float(1u << 24);

// The path of ray direction w through [s0, s1]: its cells appended to `cells`.
RayPath walkPath(const Tracer& tr, glm::vec2 w, float s0, float s1, std::vector<PathCell>& cells) {
    RayPath p;
    const glm::vec2 o0 = tr.offsetOf(w, s0), o1 = tr.offsetOf(w, s1);
    const CellBox box = cellBox(o0, o1); // |offsets| < kMaxReachPx: int32 holds them
    p.box_x0 = int32_t(box.x0), p.box_x1 = int32_t(box.x1);
    p.box_y0 = int32_t(box.y0), p.box_y1 = int32_t(box.y1);
    p.first = uint32_t(cells.size());
    walkCells(o0, o1, s0, s1, [&](int64_t dx, int64_t dy, float t_in, float t_out) {
        cells.push_back(
            {int32_t(dx), int32_t(dy), int32_t(dy * int64_t(tr.width) + dx), t_in, t_out});
        return false;
    });
    p.count = uint32_t(cells.size()) - p.first;
    return p;
}

} // namespace

Status validate(const MultiviewSettings& s, uint32_t sample_count) {
    if (sample_count == 0)
        return Status::error("--samples must be at least 1");
    if (s.layers == 0 && (!std::isfinite(s.layer_spacing_px) || !(s.layer_spacing_px > 0.0f)))
        return Status::error("--layer-spacing must be a positive number of pixels");
    if (s.layers > raster::kMaxLayers)
        return Status::error("--layers must be at most " + std::to_string(raster::kMaxLayers));
    if (!std::isfinite(s.overlap) || s.overlap < 0.0f || s.overlap > 1.0f)
        return Status::error("--overlap must be in [0, 1]");
    if (std::isnan(s.thickness_px) || !(s.thickness_px > 0.0f))
        return Status::error("--thickness must be a positive number of pixels or inf");
    if (s.iterations > 64)
        return Status::error("--iterations must be at most 64");
    if (s.refine_steps > 32)
        return Status::error("--refine-steps must be at most 32");
    if (s.tile_size == 0 || s.tile_size > 1024)
        return Status::error("multiview: tile size must be in [1, 1024]");
    if (s.jitter == JitterMode::Halton) {
        if (!s.sequence_2n || s.sequence_2n->size() == 0)
            return Status::error("--jitter halton needs a 2N-sample sequence");
        if (s.sequence_2n->size() < sample_count)
            return Status::error("--jitter halton: the sequence must hold at least --samples");
    }
    if (s.env_map) {
        const EnvironmentMap& e = *s.env_map;
        if (e.width == 0 || e.height == 0 || e.rgb.size() != size_t(e.width) * e.height * 3)
            return Status::error("--env-map: the image is empty or its size does not match");
        if (!std::isfinite(e.intensity) || e.intensity < 0.0f)
            return Status::error("--env-intensity must be a non-negative number");
    }
    return {};
}

raster::Result<raster::LayeredTargetDesc> multiviewLayerDesc(const ThinLens& lens,
                                                             const DepthRange& range,
                                                             const MultiviewSettings& settings,
                                                             LayerSpacing* spacing_out) {
    raster::Result<LayerSpacing> sp =
        settings.layers > 0
            ? layerSpacingFromCount(lens, range, settings.layers)
            : layerSpacingFromDelta(lens, range, settings.layer_spacing_px, raster::kMaxLayers);
    if (!sp.ok())
        return sp.status();
    raster::LayeredTargetDesc desc;
    desc.bounds = sp->bounds;
    desc.overlap = settings.overlap;
    desc.routing = settings.routing;
    desc.color_format = settings.color_format;
    desc.depth_format = settings.depth_format;
    desc.gbuffer = settings.view_dependent || settings.env_map != nullptr;
    if (spacing_out)
        *spacing_out = std::move(*sp);
    return desc;
}

raster::Result<MultiviewStats>
synthesizeMultiview(const raster::View& view, const ThinLens& lens, const LensSampleSet& samples,
                    const raster::Frame& pinhole, const raster::LayeredTarget& layers,
                    const LayerSpacing& spacing, const MultiviewSettings& settings,
                    const ShadingInputs& shading, glm::vec3 background, raster::TaskPool& pool,
                    MultiviewScratch& scratch, std::vector<float>& rgba) {
    if (Status st = validate(settings, samples.size()); !st.ok())
        return st;
    if (Status st = validate(lens, view); !st.ok())
        return st;
    const uint32_t width = view.width, height = view.height;
    if (pinhole.width != width || pinhole.height != height || layers.width != width ||
        layers.height != height)
        return Status::error("multiview: the pinhole frame and layers must match the view size");
    if (layers.layer_count == 0 || layers.layer_count > raster::kMaxLayers)
        return Status::error("multiview: the layered target has no layers");
    const bool shade = settings.view_dependent || settings.env_map;
    const size_t layer_texels = layers.pixelCount() * layers.layer_count;
    if (shade &&
        (layers.gbuffer.size() != layer_texels || !shading.scene ||
         (layers.hasTransparency() && (layers.transparent_gbuffer.size() != layer_texels ||
                                       layers.transparent_top_alpha.size() != layer_texels))))
        return Status::error("--view-dependent needs layers rendered with a G-buffer");

    MultiviewStats stats;
    const uint32_t m = layers.layer_count;
    stats.layers = m;
    stats.delta_px = spacing.delta_px;
    stats.budget_limited = spacing.budget_limited;
    stats.layered_bytes = layers.bytes();

    Tracer tr;
    tr.view = &view;
    tr.lens = &lens;
    tr.samples = &samples;
    tr.layers = &layers;
    tr.settings = &settings;
    tr.shading = &shading;
    tr.scratch = &scratch;
    tr.pinhole = &pinhole;
    tr.width = width;
    tr.height = height;
    tr.background = background;
    std::optional<raster::SurfaceShader> shader;
    if (shade) {
        shader.emplace(*shading.scene, view, shading.simd);
        tr.shader = &*shader;
    }
    // C as an affine function of stored depth D: 1/d = 1/f - D (1/n - 1/f) (camera.h), so
    // C = E f_px (1/d_f - 1/f) + E f_px (1/n - 1/f) D (Eq. 3).
    {
        const double ef = double(lens.aperture_radius) * double(lens.focal_length_px);
        const double inv_n = 1.0 / double(view.znear);
        const double inv_f = view.zfar > 0.0f ? 1.0 / double(view.zfar) : 0.0;
        tr.coc_a = float(ef * (1.0 / double(lens.focus_distance) - inv_f));
        tr.coc_b = float(ef * (inv_n - inv_f));
    }
    if (std::isfinite(settings.thickness_px) && tr.coc_b != 0.0f)
        tr.thickness_d = settings.thickness_px / std::fabs(tr.coc_b);
    tr.lambda = meanNeighbourDistance(samples);
    stats.lambda = tr.lambda;
    float r_max = 0.0f;
    for (const LensSample& ls : samples.samples())
        r_max = std::max(r_max, glm::length(ls.position));
    if (settings.cone && settings.cone_centre == ConeCentre::Cell &&
        settings.jitter == JitterMode::None) {
        const std::vector<glm::vec2> cells = lensCellOffsets(samples);
        for (uint32_t k = 0; k < cells.size(); ++k) {
            tr.cone_offsets.push_back(lensRayImageOffset(1.0f, cells[k]));
            // The culling windows (and N-buffer levels) bound every cone centre as every ray.
            r_max = std::max(r_max, glm::length(samples.sample(k).position + cells[k]));
        }
    }
    stats.cones_on_cells = !tr.cone_offsets.empty();
    if (settings.jitter == JitterMode::Halton)
        for (const LensSample& ls : settings.sequence_2n->samples())
            r_max = std::max(r_max, glm::length(ls.position));
    if (settings.jitter == JitterMode::Rotate)
        r_max = std::max(r_max, std::sqrt(2.0f)); // any aperture lies in [-1,1]^2
    tr.r_max = std::max(r_max, 1e-6f);

    // Per-layer float depths (empty -> kEmptyDepth), content extents, N-buffers and coverage
    // mipmaps; one task per layer, each writing only its own slots.
    auto t0 = Clock::now();
    const size_t pixels = size_t(width) * height;
    const bool transparency = layers.hasTransparency();
    scratch.depth.resize(m);
    scratch.transparent_depth.resize(transparency ? m : 0);
    // Buffers kept from the caller's previous frame are resized in place, not reallocated: every
    // slot read below is rewritten, and a layer that builds nothing is cleared.
    scratch.nbuffers.resize(m);
    std::vector<float> content_min(m, INFINITY), content_max(m, -INFINITY);
    std::vector<uint8_t> transparent_content(m, 0);
    pool.parallelFor(m, [&](uint32_t l, uint32_t) {
        float lo = INFINITY, hi = -INFINITY;
        // Returns whether any texel is covered.
        auto copy = [&](const raster::ColorBuffer& color, const raster::DepthBuffer& depth,
                        std::vector<float>& d) {
            d.resize(pixels);
            bool any = false;
            for (size_t i = 0; i < pixels; ++i) {
                const size_t li = layers.index(l, i);
                const bool covered = color.load(li).a > 0.0f;
                const float v = covered ? depth.load(li) : kEmptyDepth;
                d[i] = v;
                if (covered) {
                    lo = std::min(lo, v);
                    hi = std::max(hi, v);
                    any = true;
                }
            }
            return any;
        };
        copy(layers.color, layers.depth, scratch.depth[l]);
        if (transparency)
            transparent_content[l] = copy(layers.transparent_color, layers.transparent_depth,
                                          scratch.transparent_depth[l]);
        content_min[l] = lo;
        content_max[l] = hi;
    });
    // Segments: the overlapped interval of each layer in D (§4.2); the first and last layers
    // also reach their content (depths outside the bounds are routed there).
    tr.segs.resize(m);
    float reach_max = 0.0f;
    for (uint32_t l = 0; l < m; ++l) {
        LayerSeg& seg = tr.segs[l];
        const raster::LayerInterval iv = raster::overlappedInterval(layers.desc, l);
        const float near_d = l == 0 ? layers.desc.bounds[0] : iv.near_d;
        const float far_d = l + 1 == m ? layers.desc.bounds[m] : iv.far_d;
        seg.t0 = raster::depthFromDistance(view, near_d);
        seg.t1 = raster::depthFromDistance(view, far_d);
        if (content_max[l] >= content_min[l]) {
            seg.empty = false;
            if (l == 0)
                seg.t0 = std::min(seg.t0, content_min[l]);
            if (l + 1 == m)
                seg.t1 = std::max(seg.t1, content_max[l]);
        }
        seg.t0 = std::clamp(seg.t0, raster::kNearDepth, raster::kFarDepth);
        seg.t1 = std::clamp(seg.t1, seg.t0, raster::kFarDepth);
        seg.own0 = l == 0 ? seg.t0 : raster::depthFromDistance(view, layers.desc.bounds[l]);
        seg.own1 = l + 1 == m ? seg.t1 : raster::depthFromDistance(view, layers.desc.bounds[l + 1]);
        seg.transparent = transparent_content[l] != 0;
        // Every ray of a pixel stays within r_max * max |C| of it over the segment (C is
        // monotonic in D, so the extreme is at an end).
        const float coc_max = std::max(std::fabs(tr.cocOf(seg.t0)), std::fabs(tr.cocOf(seg.t1)));
        seg.reach_px = tr.r_max * coc_max;
        if (!(seg.reach_px < kMaxReachPx && coc_max < kMaxReachPx))
            return Status::error("multiview: the lens blurs by more than 2^24 pixels over the "
                                 "visible depths (aperture radius " +
                                 std::to_string(lens.aperture_radius) + ")");
        const float widest = tr.lambda * coc_max;
        if (settings.cone && settings.cone_misses && widest > 1.0f) {
            // A missed cone is first looked up in the middle of the layer's own interval,
            // then somewhere in the segment (missCone). A trilinear lookup at diameter Dc reads
            // level floor(log2 Dc) + 1 at most (and none above the top), 1.5 of its texels
            // either side.
            seg.t_cone = 0.5f * (seg.own0 + seg.own1);
            const int top = int(kMaxMipLevels) - 1;
            seg.cone_px = 1.5f * std::ldexp(1.0f, std::min(std::ilogb(widest) + 1, top)) + 1.0f;
        }
        if (!seg.empty)
            reach_max = std::max(reach_max, seg.reach_px);
        else
            ++stats.layers_empty;
    }
    stats.ms_decomposition = msSince(t0); // the copy belongs to the decomposition's cost

    t0 = Clock::now();
    if (!settings.culling)
        scratch.nbuffers.assign(m, NBuffer{});
    if (settings.culling) {
        pool.parallelFor(m, [&](uint32_t l, uint32_t) {
            if (tr.segs[l].empty) {
                scratch.nbuffers[l] = NBuffer{};
                return;
            }
            // Window side 2 * reach + 2 texels for a pixel; the tile query uses more (it falls
            // back to a conservative tiling when the levels run out).
            const float side = 2.0f * (tr.segs[l].reach_px + tr.segs[l].cone_px) + 2.0f +
                               float(settings.tile_size);
            uint32_t level = 0;
            while (level < 16 && float(2u << level) <= side)
                ++level;
            if (!transparency) {
                buildNBuffer(scratch.depth[l].data(), width, height, level, scratch.nbuffers[l]);
                return;
            }
            // One N-buffer for both planes: the nearer of the two depths, so culling stays
            // lossless for each.
            std::vector<float> nearest(pixels);
            for (size_t i = 0; i < pixels; ++i)
                nearest[i] = std::min(scratch.depth[l][i], scratch.transparent_depth[l][i]);
            buildNBuffer(nearest.data(), width, height, level, scratch.nbuffers[l]);
        });
        for (uint32_t l = 0; l < m; ++l)
            stats.nbuffer_levels = std::max(stats.nbuffer_levels, scratch.nbuffers[l].levelCount());
    }
    stats.ms_nbuffer = msSince(t0);

    t0 = Clock::now();
    // Per layer, the levels built below (cleared for the layers that build none).
    auto keepLayers = [&](std::vector<std::vector<std::vector<float>>>& mips, bool used) {
        mips.resize(used ? m : 0);
        for (uint32_t l = 0; l < mips.size(); ++l)
            if (!settings.cone || tr.segs[l].empty)
                mips[l].clear();
    };
    keepLayers(scratch.mips, true);
    keepLayers(scratch.transparent_mips, transparency);
    keepLayers(scratch.owned_mips, settings.cone && settings.cone_misses);
    scratch.mip_width.clear();
    scratch.mip_height.clear();
    if (settings.cone) {
        // §4.4: mipmaps of the layer colour with coverage alpha (premultiplied: empty texels
        // are (0,0,0,0)), up to the level the widest cone needs.
        // reach_max = r_max * the largest |C| of any non-empty segment.
        const float widest = tr.lambda * reach_max / tr.r_max;
        uint32_t levels = 1;
        while (levels < kMaxMipLevels && float(1u << (levels - 1)) < widest)
            ++levels;
        scratch.mip_width.push_back(width);
        scratch.mip_height.push_back(height);
        for (uint32_t lv = 1; lv < levels; ++lv) {
            scratch.mip_width.push_back(std::max(1u, (scratch.mip_width.back() + 1) / 2));
            scratch.mip_height.push_back(std::max(1u, (scratch.mip_height.back() + 1) / 2));
        }
        stats.mip_levels = levels;
        // Level 0 from `level0` (C channels per texel), then 2x2 box reductions.
        auto build = [&]<uint32_t C>(std::vector<std::vector<float>>& mip, auto&& level0) {
            mip.resize(levels);
            mip[0].resize(pixels * C);
            for (size_t i = 0; i < pixels; ++i) {
                const auto c = level0(i);
                for (uint32_t k = 0; k < C; ++k)
                    mip[0][i * C + k] = c[k];
            }
            for (uint32_t lv = 1; lv < levels; ++lv) {
                const uint32_t pw = scratch.mip_width[lv - 1], ph = scratch.mip_height[lv - 1];
                const uint32_t cw = scratch.mip_width[lv], ch = scratch.mip_height[lv];
                const std::vector<float>& src = mip[lv - 1];
                std::vector<float>& dst = mip[lv];
                dst.resize(size_t(cw) * ch * C);
                for (uint32_t y = 0; y < ch; ++y) {
                    const float* r0 = src.data() + size_t(std::min(2 * y, ph - 1)) * pw * C;
                    const float* r1 = src.data() + size_t(std::min(2 * y + 1, ph - 1)) * pw * C;
                    float* o = dst.data() + size_t(y) * cw * C;
                    auto texel = [&](uint32_t x, uint32_t x0, uint32_t x1) {
                        for (uint32_t c = 0; c < C; ++c)
                            o[x * C + c] = 0.25f * (r0[x0 * C + c] + r0[x1 * C + c] +
                                                    r1[x0 * C + c] + r1[x1 * C + c]);
                    };
                    // Only an odd level's last column clamps its right neighbour.
                    for (uint32_t x = 0; x < pw / 2; ++x)
                        texel(x, 2 * x, 2 * x + 1);
                    for (uint32_t x = pw / 2; x < cw; ++x)
                        texel(x, std::min(2 * x, pw - 1), std::min(2 * x + 1, pw - 1));
                }
            }
        };
        pool.parallelFor(m, [&](uint32_t l, uint32_t) {
            if (tr.segs[l].empty)
                return;
            build.template operator()<4>(scratch.mips[l], [&](size_t i) {
                // coverage alpha: 1 where covered
                const glm::vec4 c = layers.color.load(layers.index(l, i));
                const float a = c.a > 0.0f ? 1.0f : 0.0f;
                return glm::vec4(glm::vec3(c) * a, a);
            });
            if (settings.cone_misses) { // the texels the layer owns (missCone)
                const float lo = tr.segs[l].own0, hi = tr.segs[l].own1;
                const bool last = l + 1 == m;
                build.template operator()<kOwnedChannels>(scratch.owned_mips[l], [&](size_t i) {
                    const float d = scratch.depth[l][i];
                    const bool owned = d >= lo && (d < hi || (last && d <= hi));
                    const glm::vec4 c = layers.color.load(layers.index(l, i));
                    return owned ? std::array<float, kOwnedChannels>{d, 1.0f, c.r, c.g, c.b}
                                 : std::array<float, kOwnedChannels>{};
                });
            }
            if (transparency) // already premultiplied, alpha = opacity
                build.template operator()<4>(scratch.transparent_mips[l], [&](size_t i) {
                    return layers.transparent_color.load(layers.index(l, i));
                });
        });
    }
    auto views = [&](const std::vector<std::vector<std::vector<float>>>& layer_mips) {
        std::vector<MipChain> chains(layer_mips.size());
        for (size_t l = 0; l < layer_mips.size(); ++l)
            for (size_t lv = 0; lv < layer_mips[l].size(); ++lv) {
                const int64_t w = scratch.mip_width[lv], h = scratch.mip_height[lv];
                chains[l][lv] = {layer_mips[l][lv].data(), w, h, float(w - 1), float(h - 1)};
            }
        return chains;
    };
    tr.mips = views(scratch.mips);
    tr.owned_mips = views(scratch.owned_mips);
    tr.transparent_mips = views(scratch.transparent_mips);
    for (LayerSeg& seg : tr.segs)
        if (seg.cone_px > 0.0f) {
            seg.cone_level = mipLevelFor(tr, tr.lambda * std::fabs(tr.cocOf(seg.t_cone)));
            seg.first_cone_px = tr.r_max * std::fabs(tr.cocOf(seg.t_cone)) +
                                1.5f * std::ldexp(1.0f, int(seg.cone_level.l1)) + 1.0f;
        }
    stats.ms_mipmaps = msSince(t0);
    for (uint32_t l = 0; l < m; ++l) {
        for (const std::vector<float>& lv : scratch.nbuffers[l].levels)
            stats.scratch_bytes += lv.size() * sizeof(float);
        for (const std::vector<float>& lv : scratch.mips[l])
            stats.scratch_bytes += lv.size() * sizeof(float);
        if (!scratch.owned_mips.empty())
            for (const std::vector<float>& lv : scratch.owned_mips[l])
                stats.scratch_bytes += lv.size() * sizeof(float);
        stats.scratch_bytes += scratch.depth[l].size() * sizeof(float);
        if (transparency) {
            for (const std::vector<float>& lv : scratch.transparent_mips[l])
                stats.scratch_bytes += lv.size() * sizeof(float);
            stats.scratch_bytes += scratch.transparent_depth[l].size() * sizeof(float);
        }
    }

    // §4.3: trace every pixel's lens rays, one task per output tile.
    t0 = Clock::now();
    if (settings.precompute_paths && settings.jitter == JitterMode::None &&
        settings.traversal == Traversal::Scan) {
        // A path crosses about |dx| + |dy| + 1 cells (estimated as 2 per pixel of offset, plus
        // 2); walk them in advance unless the lens makes that very many (the per-pixel walk is
        // then the cheaper one).
        double cells_bound = 0.0;
        for (const LayerSeg& seg : tr.segs)
            cells_bound += 2.0 * double(tr.r_max) *
                               std::fabs(double(tr.cocOf(seg.t1)) - double(tr.cocOf(seg.t0))) +
                           2.0;
        if (cells_bound * samples.size() <= double(kMaxPathCells)) {
            tr.paths.reserve(size_t(samples.size()) * m);
            for (uint32_t k = 0; k < samples.size(); ++k) {
                const glm::vec2 p = samples.sample(k).position;
                for (uint32_t l = 0; l < m; ++l)
                    tr.paths.push_back(tr.segs[l].empty // never traced
                                           ? RayPath{}
                                           : walkPath(tr, glm::vec2(-p.x, p.y), tr.segs[l].t0,
                                                      tr.segs[l].t1, tr.cells));
            }
            stats.path_cells = tr.cells.size();
            for (uint32_t l = 0; l < m; ++l) {
                LayerSeg& seg = tr.segs[l];
                if (seg.empty)
                    continue;
                seg.focus_t1 = seg.t1;
                for (uint32_t k = 0; k < samples.size(); ++k) {
                    const RayPath& path = tr.paths[size_t(k) * m + l];
                    const PathCell* cells = tr.cells.data() + path.first;
                    uint32_t i = 0;
                    while (i < path.count && (cells[i].dx != 0 || cells[i].dy != 0)) {
                        auto& box = seg.focus_box;
                        const bool first = box.x0 > box.x1;
                        box.x0 = first ? cells[i].dx : std::min(box.x0, cells[i].dx);
                        box.x1 = first ? cells[i].dx : std::max(box.x1, cells[i].dx);
                        box.y0 = first ? cells[i].dy : std::min(box.y0, cells[i].dy);
                        box.y1 = first ? cells[i].dy : std::max(box.y1, cells[i].dy);
                        ++i;
                    }
                    if (i == path.count) { // this ray never crosses its own texel here
                        seg.focus_t0 = 1.0f, seg.focus_t1 = -1.0f;
                        break;
                    }
                    seg.focus_t0 = k == 0 ? cells[i].t_in : std::max(seg.focus_t0, cells[i].t_in);
                    seg.focus_t1 = std::min(seg.focus_t1, cells[i].t_out);
                }
            }
            // inFocusPixel repeats what traceLayer and endPixel do for a ray that hits its own
            // texel: lens-centre shading and no ray dropped at the image border.
            tr.in_focus = !shade && settings.offscreen == OffscreenPolicy::Clamp;
        }
    }
    rgba.assign(pixels * 4, 0.0f);
    const uint32_t ts = settings.tile_size;
    const uint32_t tiles_x = (width + ts - 1) / ts, tiles_y = (height + ts - 1) / ts;
    std::vector<TileCounters> counters(size_t(tiles_x) * tiles_y);
    // Per worker: the states of one tile's rays and pixels.
    std::vector<RayState> ray_states(size_t(pool.workerCount()) * ts * ts * samples.size());
    std::vector<PixelLayers> pixel_layers(size_t(pool.workerCount()) * ts * ts);
    const TraceTileFn trace_tile = traceTileFor(shading.simd);
    pool.parallelFor(tiles_x * tiles_y, [&](uint32_t tile, uint32_t worker) {
        // Counted on the stack, stored once: neighbouring tiles' counters share cache lines,
        // and the two workers usually trace neighbouring tiles.
        TileCounters cnt;
        const uint32_t x0 = (tile % tiles_x) * ts, y0 = (tile / tiles_x) * ts;
        const uint32_t x1 = std::min(x0 + ts, width), y1 = std::min(y0 + ts, height);
        // Skip empty layers, and layers with nothing in reach of the whole tile (one query).
        std::array<uint32_t, raster::kMaxLayers> tile_layers{};
        uint32_t count = 0;
        for (uint32_t l = 0; l < m; ++l) {
            if (tr.segs[l].empty)
                continue;
            if (settings.culling && culled(tr, l, x0, x1 - 1, y0, y1 - 1, tr.segs[l].cone_px)) {
                ++cnt.culled_tile;
                continue;
            }
            tile_layers[count++] = l;
        }
        trace_tile(tr, x0, x1, y0, y1, tile_layers.data(), count,
                   ray_states.data() + size_t(worker) * ts * ts * samples.size(),
                   pixel_layers.data() + size_t(worker) * ts * ts, rgba.data(), cnt);
        counters[tile] = cnt;
    });
    for (const TileCounters& c : counters) {
        stats.rays += c.rays;
        stats.rays_discarded += c.discarded;
        stats.rays_background += c.background;
        stats.layer_tests += c.layer_tests;
        stats.layer_culled_pixel += c.culled_pixel;
        stats.layer_culled_tile += c.culled_tile;
        stats.layer_culled_ray += c.culled_ray;
        stats.cone_partial += c.cone_partial;
        stats.cone_missed += c.cone_missed;
        stats.texel_fetches += c.fetches;
        stats.layer_steps += c.layer_steps;
        stats.transparent_hits += c.transparent_hits;
        stats.pixels_in_focus += c.pixels_in_focus;
    }
    stats.ms_tracing = msSince(t0);
    return stats;
}

raster::Result<MultiviewStats>
renderMultiview(const raster::View& view, const ThinLens& lens, const LensSampleSet& samples,
                const MultiviewSettings& settings, const ShadingInputs& shading,
                glm::vec3 background, const PinholeFn& render_pinhole,
                const LayersFn& render_layers, raster::TaskPool& pool, std::vector<float>& rgba,
                raster::Frame* pinhole_out, raster::LayeredTarget* layers_out,
                MultiviewScratch* scratch_io) {
    if (Status st = validate(settings, samples.size()); !st.ok())
        return st;
    if (Status st = validate(lens, view); !st.ok())
        return st;
    raster::Frame local_pinhole;
    raster::Frame& pinhole = pinhole_out ? *pinhole_out : local_pinhole;
    // §4.1: the pinhole through the lens centre gives the visible depth range.
    auto t0 = Clock::now();
    if (Status st = render_pinhole(view, pinhole); !st.ok())
        return st;
    const double ms_pinhole = msSince(t0);
    const DepthRange range = visibleDepthRange(pinhole, view);
    // Nothing to blur: the pinhole render is the result (the same rule as accum's, so both
    // methods return the pinhole image for the same lenses). Rays offset by less than half a
    // pixel would read every pixel's own texel anyway.
    std::string skip_reason;
    if (!range.covered) {
        skip_reason = "nothing visible: the image is the background";
    } else if (settings.skip_unblurred && !settings.env_map) {
        const CocRange coc = visibleCocRange(lens, pinhole, view);
        if (lens.aperture_radius == 0.0f) {
            skip_reason = "aperture radius is 0 (pinhole)";
        } else if (coc.max_abs_px < 0.5f) {
            char buf[96];
            std::snprintf(buf, sizeof buf, "every visible depth has |C(d)| < 0.5 px (max %.3f px)",
                          double(coc.max_abs_px));
            skip_reason = buf;
        }
    }
    if (!skip_reason.empty()) {
        rgba = pinhole.color;
        if (layers_out)
            *layers_out = raster::LayeredTarget{}; // no decomposition was made
        MultiviewStats stats;
        stats.skipped = true;
        stats.skip_reason = std::move(skip_reason);
        stats.ms_pinhole = ms_pinhole;
        if (range.covered)
            stats.d_near = range.near_d, stats.d_far = range.far_d;
        return stats;
    }
    LayerSpacing spacing;
    raster::Result<raster::LayeredTargetDesc> desc =
        multiviewLayerDesc(lens, range, settings, &spacing);
    if (!desc.ok())
        return desc.status();
    raster::LayeredTarget local_layers;
    raster::LayeredTarget& layers = layers_out ? *layers_out : local_layers;
    t0 = Clock::now();
    if (Status st = render_layers(view, *desc, layers); !st.ok())
        return st;
    const double ms_layers = msSince(t0);
    MultiviewScratch local_scratch;
    MultiviewScratch& scratch = scratch_io ? *scratch_io : local_scratch;
    raster::Result<MultiviewStats> r =
        synthesizeMultiview(view, lens, samples, pinhole, layers, spacing, settings, shading,
                            background, pool, scratch, rgba);
    if (!r.ok())
        return r;
    r->ms_pinhole = ms_pinhole;
    r->ms_decomposition += ms_layers;
    r->d_near = range.near_d;
    r->d_far = range.far_d;
    return r;
}

uint64_t multiviewMinimumBytes(const MultiviewSettings& settings, uint32_t width, uint32_t height,
                               uint32_t sample_count, uint32_t workers) {
    using raster::addBytes, raster::mulBytes;
    const uint64_t pixels = uint64_t{width} * height;
    const uint32_t layers = std::max(settings.layers, 1u);
    raster::LayeredTargetDesc desc;
    desc.color_format = settings.color_format;
    desc.depth_format = settings.depth_format;
    desc.gbuffer = settings.view_dependent || settings.env_map != nullptr;
    uint64_t bytes = raster::frameBytes(width, height, raster::DepthFormat::Float32, false);
    bytes = addBytes(bytes, mulBytes(pixels, 4 * sizeof(float))); // rgba
    bytes = addBytes(bytes, raster::layeredTargetBytes(width, height, layers, desc, false));
    bytes = addBytes(bytes, mulBytes(mulBytes(pixels, layers), sizeof(float))); // scratch.depth
    const uint64_t tile_texels = uint64_t{settings.tile_size} * settings.tile_size;
    const uint64_t per_texel =
        addBytes(mulBytes(sample_count, sizeof(RayState)), sizeof(PixelLayers));
    return addBytes(bytes, mulBytes(mulBytes(workers, tile_texels), per_texel));
}

} // namespace dof
