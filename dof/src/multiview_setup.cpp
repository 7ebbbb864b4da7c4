// Multiview's setup stages (multiview_setup.h): the scratch copy of the layer depths, the
// segments, the N-buffers, the mipmaps and the paths walked in advance, once per frame. Consume
// the layered target and the Tracer; produce the caller's MultiviewScratch buffers (resized in
// place, so a kept scratch is reused) and the Tracer's per-frame vectors.
#include "multiview_setup.h"

#include <raster/camera.h>
#include <raster/layered_target.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <bit>

namespace dof::multiview_detail {

using raster::Status;

namespace {

// Most cells walked in advance (PathCell; 20 bytes each).
constexpr double kMaxPathCells = double(1u << 22);
// Largest image offset a ray may reach (pixels): beyond it the lens is rejected as absurd for the
// view (offsets are then still exact in float and fit RayPath's int32 boxes).
constexpr float kMaxReachPx = float(1u << 24);

// Row y of a mipmap level that stores its rows [row0, row1), `row_floats` floats each, or
// `zero` (a row of zeros at least as long) for a row it does not store.
const float* storedRow(const std::vector<float>& level, size_t row0, size_t row1, size_t row_floats,
                       size_t y, const float* zero) {
    return y >= row0 && y < row1 ? level.data() + (y - row0) * row_floats : zero;
}

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

// A texel's coverage (alpha > 0) and whether any channel holds other bits than the clear
// value +0, from the stored bits of a colour buffer of float (Bits = uint32_t) or half
// (uint16_t) values: a half widens to a float of the same sign, zero-ness and NaN-ness, so
// these are the answers of loading the texel as floats, without converting four values.
// A value is > 0 iff its bits lie in [1, bits of +inf] (NaNs lie above).
struct TexelBits {
    bool covered, drawn;
};
template <class Bits> TexelBits texelBits(Bits r, Bits g, Bits b, Bits a) {
    static_assert(sizeof(Bits) == 2 || sizeof(Bits) == 4);
    constexpr Bits kInf = sizeof(Bits) == 2 ? Bits(0x7c00u) : Bits(0x7f800000u);
    return {Bits(a - 1) < kInf, (r | g | b | a) != 0};
}

} // namespace

void copyLayerDepths(const raster::LayeredTarget& layers, raster::TaskPool& pool,
                     MultiviewScratch& scratch, LayerContent& content) {
    const uint32_t m = layers.layer_count;
    const size_t pixels = size_t(layers.width) * layers.height;
    const bool transparency = layers.hasTransparency();
    scratch.depth.resize(m);
    scratch.transparent_depth.resize(transparency ? m : 0);
    // Buffers kept from the caller's previous frame are resized in place, not reallocated: every
    // slot read below is rewritten, and a layer that builds nothing is cleared.
    scratch.nbuffers.resize(m);
    content.min.assign(m, INFINITY);
    content.max.assign(m, -INFINITY);
    content.transparent.assign(m, 0);
    content.row0.assign(m, 0);
    content.row1.assign(m, 0);
    content.transparent_row0.assign(m, 0);
    content.transparent_row1.assign(m, 0);
    const uint32_t width = layers.width, height = layers.height;
    pool.parallelFor(m, [&](uint32_t l, uint32_t) {
        float lo = INFINITY, hi = -INFINITY;
        // Returns whether any texel is covered; [row0, row1): the rows with a texel not +0.
        // bits(k): the bits of the colour buffer's value k.
        auto copyAs = [&](auto bits, const raster::DepthBuffer& depth, std::vector<float>& d,
                          uint32_t& row0, uint32_t& row1) {
            d.resize(pixels);
            bool any = false;
            for (uint32_t y = 0; y < height; ++y) {
                bool drawn = false;
                for (size_t i = size_t(y) * width, end = i + width; i < end; ++i) {
                    const size_t li = layers.index(l, i);
                    const TexelBits t = texelBits(bits(4 * li), bits(4 * li + 1), bits(4 * li + 2),
                                                  bits(4 * li + 3));
                    const float v = t.covered ? depth.load(li) : kEmptyDepth;
                    d[i] = v;
                    // Not the clear value +0: the mipmaps' level 0 may differ from +0 here.
                    drawn |= t.drawn;
                    if (t.covered) {
                        lo = std::min(lo, v);
                        hi = std::max(hi, v);
                        any = true;
                    }
                }
                if (drawn) {
                    row0 = row1 == 0 ? y : row0;
                    row1 = y + 1;
                }
            }
            return any;
        };
        auto copy = [&](const raster::ColorBuffer& color, const raster::DepthBuffer& depth,
                        std::vector<float>& d, uint32_t& row0, uint32_t& row1) {
            if (color.format == raster::ColorFormat::Half)
                return copyAs([&](size_t k) { return color.half[k].bits(); }, depth, d, row0, row1);
            return copyAs([&](size_t k) { return std::bit_cast<uint32_t>(color.float32[k]); },
                          depth, d, row0, row1);
        };
        copy(layers.color, layers.depth, scratch.depth[l], content.row0[l], content.row1[l]);
        if (transparency)
            content.transparent[l] = copy(layers.transparent_color, layers.transparent_depth,
                                          scratch.transparent_depth[l], content.transparent_row0[l],
                                          content.transparent_row1[l]);
        content.min[l] = lo;
        content.max[l] = hi;
    });
}

Status buildSegments(Tracer& tr, const LayerContent& content, MultiviewStats& stats,
                     float& reach_max) {
    const raster::View& view = *tr.view;
    const ThinLens& lens = *tr.lens;
    const raster::LayeredTarget& layers = *tr.layers;
    const MultiviewSettings& settings = *tr.settings;
    const uint32_t m = layers.layer_count;
    // Segments: the overlapped interval of each layer in D (§4.2); the first and last layers
    // also reach their content (depths outside the bounds are routed there).
    tr.segs.resize(m);
    reach_max = 0.0f;
    for (uint32_t l = 0; l < m; ++l) {
        LayerSeg& seg = tr.segs[l];
        const raster::LayerInterval iv = raster::overlappedInterval(layers.desc, l);
        const float near_d = l == 0 ? layers.desc.bounds[0] : iv.near_d;
        const float far_d = l + 1 == m ? layers.desc.bounds[m] : iv.far_d;
        seg.t0 = raster::depthFromDistance(view, near_d);
        seg.t1 = raster::depthFromDistance(view, far_d);
        if (content.max[l] >= content.min[l]) {
            seg.empty = false;
            if (l == 0)
                seg.t0 = std::min(seg.t0, content.min[l]);
            if (l + 1 == m)
                seg.t1 = std::max(seg.t1, content.max[l]);
        }
        seg.t0 = std::clamp(seg.t0, raster::kNearDepth, raster::kFarDepth);
        seg.t1 = std::clamp(seg.t1, seg.t0, raster::kFarDepth);
        seg.own0 = l == 0 ? seg.t0 : raster::depthFromDistance(view, layers.desc.bounds[l]);
        seg.own1 = l + 1 == m ? seg.t1 : raster::depthFromDistance(view, layers.desc.bounds[l + 1]);
        seg.transparent = content.transparent[l] != 0;
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
            seg.coc_cone = tr.cocOf(seg.t_cone);
            const int top = int(kMaxMipLevels) - 1;
            seg.cone_px = 1.5f * std::ldexp(1.0f, std::min(std::ilogb(widest) + 1, top)) + 1.0f;
        }
        if (!seg.empty)
            reach_max = std::max(reach_max, seg.reach_px);
        else
            ++stats.layers_empty;
    }
    return {};
}

void buildNBuffers(const Tracer& tr, raster::TaskPool& pool, MultiviewScratch& scratch,
                   std::vector<std::vector<float>>& nearest, MultiviewStats& stats) {
    const MultiviewSettings& settings = *tr.settings;
    const uint32_t width = tr.width, height = tr.height;
    const uint32_t m = uint32_t(tr.segs.size());
    const size_t pixels = size_t(width) * height;
    const bool transparency = tr.layers->hasTransparency();
    if (!settings.culling)
        scratch.nbuffers.assign(m, NBuffer{});
    if (settings.culling) {
        nearest.resize(transparency ? m : 0);
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
            std::vector<float>& source = nearest[l];
            source.resize(pixels);
            for (size_t i = 0; i < pixels; ++i)
                source[i] = std::min(scratch.depth[l][i], scratch.transparent_depth[l][i]);
            buildNBuffer(source.data(), width, height, level, scratch.nbuffers[l]);
        });
        for (uint32_t l = 0; l < m; ++l)
            stats.nbuffer_levels = std::max(stats.nbuffer_levels, scratch.nbuffers[l].levelCount());
    }
}

void buildMipmaps(Tracer& tr, const LayerContent& content, float reach_max, raster::TaskPool& pool,
                  MultiviewScratch& scratch, MultiviewStats& stats) {
    const raster::LayeredTarget& layers = *tr.layers;
    const MultiviewSettings& settings = *tr.settings;
    const uint32_t width = tr.width, height = tr.height;
    const uint32_t m = uint32_t(tr.segs.size());
    const bool transparency = layers.hasTransparency();
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
    scratch.mip_row0.resize(m);
    scratch.transparent_mip_row0.resize(transparency ? m : 0);
    scratch.owned_empty_blocks.resize(scratch.owned_mips.size());
    for (std::vector<uint8_t>& blocks : scratch.owned_empty_blocks)
        blocks.clear(); // rebuilt below for the layers with missed cones
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
        tr.zero_row.resize(size_t(width) * kOwnedChannels);
        for (LayerSeg& seg : tr.segs)
            if (seg.cone_px > 0.0f) {
                seg.cone_level = mipLevelFor(tr, tr.lambda * std::fabs(tr.cocOf(seg.t_cone)));
                seg.cone_last_level = lastConeLevel(seg.cone_level);
                seg.first_cone_px = tr.r_max * std::fabs(tr.cocOf(seg.t_cone)) +
                                    1.5f * std::ldexp(1.0f, int(seg.cone_level.l1)) + 1.0f;
            }
        // The rows [first, end) each level stores: level 0 the layer's rows [row0, row1) whose
        // texels are not +0 (every other texel of level 0 is +0), then the rows a 2x2 reduction
        // of those can reach; a level's other rows average four +0 texels, +0 too.
        using LevelRows = std::array<uint32_t, kMaxMipLevels>;
        auto planRows = [&](std::vector<uint32_t>& first, LevelRows& end, uint32_t row0,
                            uint32_t row1) {
            first.resize(levels);
            for (uint32_t lv = 0; lv < levels; ++lv) {
                if (lv > 0 && row1 > row0) {
                    row0 /= 2;
                    row1 = std::min((row1 - 1) / 2 + 1, scratch.mip_height[lv]);
                }
                if (row1 <= row0)
                    row0 = row1 = 0;
                first[lv] = row0;
                end[lv] = row1;
            }
        };
        // Level 0 from `level0` (C channels per texel) on its stored rows, then 2x2 box
        // reductions; a source row a level does not store is read as zeros.
        auto build = [&]<uint32_t C>(std::vector<std::vector<float>>& mip,
                                     const std::vector<uint32_t>& first, const LevelRows& end,
                                     auto&& level0) {
            mip.resize(levels);
            mip[0].resize(size_t(end[0] - first[0]) * width * C);
            for (size_t i = size_t(first[0]) * width, o = 0; i < size_t(end[0]) * width; ++i, ++o) {
                const auto c = level0(i);
                for (uint32_t k = 0; k < C; ++k)
                    mip[0][o * C + k] = c[k];
            }
            for (uint32_t lv = 1; lv < levels; ++lv) {
                const uint32_t pw = scratch.mip_width[lv - 1], ph = scratch.mip_height[lv - 1];
                const uint32_t cw = scratch.mip_width[lv];
                std::vector<float>& dst = mip[lv];
                dst.resize(size_t(end[lv] - first[lv]) * cw * C);
                auto srcRow = [&](uint32_t y) {
                    return storedRow(mip[lv - 1], first[lv - 1], end[lv - 1], size_t(pw) * C,
                                     std::min(y, ph - 1), tr.zero_row.data());
                };
                for (uint32_t y = first[lv]; y < end[lv]; ++y) {
                    const float* r0 = srcRow(2 * y);
                    const float* r1 = srcRow(2 * y + 1);
                    float* o = dst.data() + size_t(y - first[lv]) * cw * C;
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
            LevelRows end;
            planRows(scratch.mip_row0[l], end, content.row0[l], content.row1[l]);
            const std::vector<uint32_t>& first = scratch.mip_row0[l];
            build.template operator()<4>(scratch.mips[l], first, end, [&](size_t i) {
                // coverage alpha: 1 where covered
                const glm::vec4 c = layers.color.load(layers.index(l, i));
                const float a = c.a > 0.0f ? 1.0f : 0.0f;
                return glm::vec4(glm::vec3(c) * a, a);
            });
            if (settings.cone_misses) { // the texels the layer owns (missCone)
                const float lo = tr.segs[l].own0, hi = tr.segs[l].own1;
                const bool last = l + 1 == m;
                build.template operator()<kOwnedChannels>(
                    scratch.owned_mips[l], first, end, [&](size_t i) {
                        const float d = scratch.depth[l][i];
                        const bool owned = d >= lo && (d < hi || (last && d <= hi));
                        const glm::vec4 c = layers.color.load(layers.index(l, i));
                        return owned ? std::array<float, kOwnedChannels>{d, 1.0f, c.r, c.g, c.b}
                                     : std::array<float, kOwnedChannels>{};
                    });
                std::vector<uint8_t>& blocks = scratch.owned_empty_blocks[l];
                if (tr.segs[l].cone_px > 0.0f) {
                    // mipEmptyAt's four coverage taps, tested once per block here instead of
                    // once per missed ray: one byte read, from a map that stays in the cache.
                    // Rows the level does not store have no coverage.
                    const uint32_t lv = tr.segs[l].cone_last_level;
                    const size_t w = scratch.mip_width[lv], h = scratch.mip_height[lv];
                    auto coverage = [&](size_t v) {
                        return storedRow(scratch.owned_mips[l][lv], first[lv], end[lv],
                                         w * kOwnedChannels, v, tr.zero_row.data()) +
                               1;
                    };
                    blocks.assign(w * h, 0);
                    for (size_t v = 0; v + 1 < h; ++v) {
                        const float* c0 = coverage(v);
                        const float* c1 = coverage(v + 1);
                        for (size_t u = 0; u + 1 < w; ++u) {
                            const size_t k = u * kOwnedChannels;
                            blocks[v * w + u] = c0[k] == 0.0f && c0[k + kOwnedChannels] == 0.0f &&
                                                c1[k] == 0.0f && c1[k + kOwnedChannels] == 0.0f;
                        }
                    }
                }
            }
            if (transparency) { // already premultiplied, alpha = opacity
                LevelRows transparent_end;
                planRows(scratch.transparent_mip_row0[l], transparent_end,
                         content.transparent_row0[l], content.transparent_row1[l]);
                build.template operator()<4>(
                    scratch.transparent_mips[l], scratch.transparent_mip_row0[l], transparent_end,
                    [&](size_t i) { return layers.transparent_color.load(layers.index(l, i)); });
            }
        });
    }
    auto views = [&](const std::vector<std::vector<std::vector<float>>>& layer_mips,
                     const std::vector<std::vector<uint32_t>>& row0, uint32_t channels,
                     std::vector<MipChain>& chains) {
        chains.assign(layer_mips.size(), MipChain{});
        for (size_t l = 0; l < layer_mips.size(); ++l)
            for (size_t lv = 0; lv < layer_mips[l].size(); ++lv) {
                const int64_t w = scratch.mip_width[lv], h = scratch.mip_height[lv];
                const int64_t r0 = row0[l][lv];
                const int64_t r1 = r0 + int64_t(layer_mips[l][lv].size() / (size_t(w) * channels));
                chains[l][lv] = {layer_mips[l][lv].data(),
                                 tr.zero_row.data(),
                                 w,
                                 h,
                                 r0,
                                 r1,
                                 float(w - 1),
                                 float(h - 1),
                                 float(r0),
                                 float(r1 - 1)};
            }
    };
    views(scratch.mips, scratch.mip_row0, 4, tr.mips);
    views(scratch.owned_mips, scratch.mip_row0, kOwnedChannels, tr.owned_mips);
    views(scratch.transparent_mips, scratch.transparent_mip_row0, 4, tr.transparent_mips);
    for (uint32_t l = 0; l < scratch.owned_empty_blocks.size(); ++l)
        tr.segs[l].cone_empty_blocks =
            scratch.owned_empty_blocks[l].empty() ? nullptr : scratch.owned_empty_blocks[l].data();
}

void buildFirstRays(Tracer& tr) {
    if (tr.settings->jitter != JitterMode::None)
        return;
    const uint32_t n = tr.samples->size();
    tr.first_rays.resize(n);
    for (uint32_t k = 0; k < n; ++k) {
        RayState& ray = tr.first_rays[k];
        ray = RayState{};
        ray.lens = tr.samples->sample(k);
        ray.w = glm::vec2(-ray.lens.position.x, ray.lens.position.y);
        ray.wc = tr.cone_offsets.empty() ? ray.w : ray.w + tr.cone_offsets[k];
        ray.t_end = tr.segs.back().t1;
    }
}

bool walkPaths(Tracer& tr, MultiviewStats& stats) {
    const LensSampleSet& samples = *tr.samples;
    const uint32_t m = uint32_t(tr.segs.size());
    // A path crosses about |dx| + |dy| + 1 cells (estimated as 2 per pixel of offset, plus
    // 2); walk them in advance unless the lens makes that very many (the per-pixel walk is
    // then the cheaper one).
    double cells_bound = 0.0;
    for (const LayerSeg& seg : tr.segs)
        cells_bound += 2.0 * double(tr.r_max) *
                           std::fabs(double(tr.cocOf(seg.t1)) - double(tr.cocOf(seg.t0))) +
                       2.0;
    if (!(cells_bound * samples.size() <= double(kMaxPathCells)))
        return false;
    tr.paths.reserve(size_t(samples.size()) * m);
    for (uint32_t k = 0; k < samples.size(); ++k) {
        const glm::vec2 p = samples.sample(k).position;
        for (uint32_t l = 0; l < m; ++l)
            tr.paths.push_back(
                tr.segs[l].empty // never traced
                    ? RayPath{}
                    : walkPath(tr, glm::vec2(-p.x, p.y), tr.segs[l].t0, tr.segs[l].t1, tr.cells));
    }
    stats.path_cells = tr.cells.size();
    for (uint32_t l = 0; l < m; ++l) {
        LayerSeg& seg = tr.segs[l];
        if (seg.empty)
            continue;
        for (uint32_t k = 0; k < samples.size(); ++k) {
            const RayPath& path = tr.paths[size_t(k) * m + l];
            auto& box = seg.paths_box;
            const bool first = k == 0;
            box.x0 = first ? path.box_x0 : std::min(box.x0, path.box_x0);
            box.x1 = first ? path.box_x1 : std::max(box.x1, path.box_x1);
            box.y0 = first ? path.box_y0 : std::min(box.y0, path.box_y0);
            box.y1 = first ? path.box_y1 : std::max(box.y1, path.box_y1);
            seg.long_paths = seg.long_paths || path.count > kRayCullMinCells;
        }
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
    return true;
}

} // namespace dof::multiview_detail
