// Multiview's cones (§4.4): trilinear lookups of the layer mipmaps at a hit's cone, and the cones
// of rays that miss a layer. Consumes the Tracer and the mipmaps (MultiviewScratch, viewed as
// MipChain); produces coverage and mean colour; owns nothing. Included only by
// multiview_tracer.cpp, so both traceTile copies inline it.
#pragma once

#include "multiview_shading.inl"
#include "multiview_tracer.h"

#include <dof/float4.h>

namespace dof::multiview_detail {
namespace {

// Trilinear lookup of the first C channels of a layer mipmap `mip` with Stride channels per
// texel (§4.4) at image position (px, py) on the levels `lv`. Channels 0-3 are weighted as one
// vector (C = 2 reads four and keeps two: a texel has Stride >= 4 channels); a fifth is scalar.
template <int C, int Stride = C>
std::array<float, C> sampleMip(const MipChain& mip, float px, float py, MipLevel lv) {
    static_assert(C <= 5 && Stride >= 4 && Stride >= C);
    struct Taps {
        Float4 v;
        float e; // channel 4 when C == 5
    };
    auto bilinear = [&](uint32_t level) {
        const MipView& m = mip[level];
        const int64_t w = m.width, h = m.height;
        const float scale = kMipScale[level];
        const float u = px * scale - 0.5f, v = py * scale - 0.5f;
        const float fu = std::floor(u), fv = std::floor(v);
        const float au = u - fu, av = v - fv;
        const float* r0;
        const float* r1;
        int64_t x0, x1;
        if (fu >= 0.0f && fv >= m.first_v && fu < m.last_u && fv < m.stored_v) {
            // Inside the level's stored rows: the four texels need no clamping (the usual case).
            x0 = int64_t(fu) * Stride;
            x1 = x0 + Stride;
            r0 = m.data + size_t((int64_t(fv) - m.row0) * w) * Stride;
            r1 = r0 + size_t(w) * Stride;
        } else {
            // Clamped to the level (the position may lie far outside it when a clamped ray
            // read a border texel); a row the level does not store is 0.
            const int64_t iu = int64_t(std::clamp(fu, -1.0f, float(w)));
            const int64_t iv = int64_t(std::clamp(fv, -1.0f, float(h)));
            x0 = std::clamp<int64_t>(iu, 0, w - 1) * Stride;
            x1 = std::clamp<int64_t>(iu + 1, 0, w - 1) * Stride;
            const auto row = [&](int64_t y) {
                y = std::clamp<int64_t>(y, 0, h - 1);
                return y >= m.row0 && y < m.row1 ? m.data + size_t((y - m.row0) * w) * Stride
                                                 : m.zero;
            };
            r0 = row(iv);
            r1 = row(iv + 1);
        }
        const float bu = 1.0f - au, bv = 1.0f - av;
        Taps out;
        const Float4 top_row = loadFloat4(r0 + x0) * bu + loadFloat4(r0 + x1) * au;
        const Float4 bottom = loadFloat4(r1 + x0) * bu + loadFloat4(r1 + x1) * au;
        out.v = top_row * bv + bottom * av;
        out.e = 0.0f;
        if constexpr (C == 5) {
            const float top4 = r0[x0 + 4] * bu + r0[x1 + 4] * au;
            const float bottom4 = r1[x0 + 4] * bu + r1[x1 + 4] * au;
            out.e = top4 * bv + bottom4 * av;
        }
        return out;
    };
    Taps c0 = bilinear(lv.l0);
    if (lv.l1 != lv.l0 && lv.f != 0.0f) {
        const Taps c1 = bilinear(lv.l1);
        const float g = 1.0f - lv.f;
        c0.v = c0.v * g + c1.v * lv.f;
        c0.e = c0.e * g + c1.e * lv.f;
    }
    std::array<float, C> out;
    for (int c = 0; c < C; ++c)
        out[c] = c < 4 ? c0.v[c] : c0.e;
    return out;
}

// Whether sampleMip on `mip` (Stride channels per texel, a non-negative coverage in one channel)
// at (px, py) on levels whose finer one is l0 returns exactly 0 in that channel because every
// texel it reads is empty there: when both levels' taps lie inside their levels, the taps of l0
// lie in the 2x2 blocks the coarser level's four taps average (u0 = 2 u1 + 1/2), so the block
// of the last level read (`last`, lastConeLevel) decides it: `empty_blocks` says which blocks
// have four zero coverages (MultiviewScratch::owned_empty_blocks). False when unsure.
// kInside: the caller knows that the taps of both levels lie inside them (missCone's
// LayerSeg::first_cone_px margin), so only the last level's block is looked up.
template <bool kInside = false>
bool mipEmptyAt(const MipChain& mip, const uint8_t* empty_blocks, float px, float py, uint32_t l0,
                uint32_t last) {
    // The 2x2 block at level L under (px, py), false when the taps there are not all inside.
    int64_t block = 0;
    const auto inside = [&](uint32_t level) {
        const MipView& m = mip[level];
        const float scale = kMipScale[level];
        const float fu = std::floor(px * scale - 0.5f), fv = std::floor(py * scale - 0.5f);
        block = int64_t(fv) * m.width + int64_t(fu);
        return kInside || (fu >= 0.0f && fv >= 0.0f && fu < m.last_u && fv < m.last_v);
    };
    if (kInside)
        inside(last);
    else if (!inside(l0) || (last != l0 && !inside(last)))
        return false;
    return empty_blocks[block] != 0;
}

// The same for a window of `diameter` pixels.
template <int C, int Stride = C>
std::array<float, C> sampleMip(const Tracer& tr, const MipChain& mip, float px, float py,
                               float diameter) {
    return sampleMip<C, Stride>(mip, px, py, mipLevelFor(tr, diameter));
}

// A layer's premultiplied coverage mipmap (RGBA, alpha = coverage) at a cone (§4.4).
glm::vec4 sampleCone(const Tracer& tr, const MipChain& mip, float px, float py, float diameter) {
    const std::array<float, 4> m = sampleMip<4>(tr, mip, px, py, diameter);
    return {m[0], m[1], m[2], m[3]};
}

// A missed ray's cone (MultiviewSettings::cone_misses): coverage v1 and mean colour c1 of the
// layer texels around the ray where it passes them, at stored depth t.
struct MissCone {
    float v1 = 0.0f;
    glm::vec3 c1{0.0f};
    float t = 0.0f;
};

// The paper (§4.4) evaluates a cone only "given an impact point", so rays passing beside a small
// or thin object between the lens samples never see it. Here a ray that crossed layer l's
// segment without a hit is thickened too. The cone is placed where the ray passes the layer's
// content: first at the middle of the layer (t_cone), then at the mean depth of the covered
// texels found there (where a ray passes a small object depends on the object's depth, through
// C). Coverage and colour count only the texels the layer owns ([own0, own1], owned_mips), so a
// surface in the overlap of two layers is coned once (per-ray shading, §5, shades the covered
// texels among the footprint's taps, as for a hit). Off the image the cone is looked up at the
// image border under OffscreenPolicy::Clamp (the border texels stand in for the unseen content,
// as for a clamped hit) and not at all under Discard; the culling windows, clamped to the
// image, then still hold every texel read. None when the cone sees nothing. w: the cone centre's
// image offset per unit C (the ray's, or its cell's with ConeCentre::Cell); seg: tr.segs[l].
// first_inside: the pixel centre (cx, cy) is at least seg.first_cone_px inside the image, so the
// first lookup's position is inside the image and its taps inside their levels.
std::optional<MissCone> missCone(const Tracer& tr, uint32_t l, const LayerSeg& seg, float cx,
                                 float cy, glm::vec2 w, bool first_inside, bool shade,
                                 glm::vec3 eye, TileCounters& cnt) {
    // Where the ray is where its image offset is c (at stored depth t, c = C(t)): off the image,
    // clamped to its border (as a clamped ray reads the border texels, OffscreenPolicy::Clamp)
    // or none (Discard). `inside`: known to lie in the image.
    auto at = [&](float c, float& px, float& py, bool inside = false) {
        px = cx + c * w.x, py = cy + c * w.y;
        if (inside || tr.inImage(px, py))
            return true;
        if (tr.settings->offscreen != OffscreenPolicy::Clamp)
            return false;
        px = std::clamp(px, 0.0f, std::nextafter(float(tr.width), 0.0f));
        py = std::clamp(py, 0.0f, std::nextafter(float(tr.height), 0.0f));
        return true;
    };
    float px = 0.0f, py = 0.0f;
    const MipChain& owned = tr.owned_mips[l];
    if (!at(seg.coc_cone, px, py, first_inside))
        return std::nullopt;
    // Most rays pass where the layer owns nothing near them: no coverage, no lookup.
    const uint32_t l0 = seg.cone_level.l0, last = seg.cone_last_level;
    if (first_inside ? mipEmptyAt<true>(owned, seg.cone_empty_blocks, px, py, l0, last)
                     : mipEmptyAt<false>(owned, seg.cone_empty_blocks, px, py, l0, last))
        return std::nullopt;
    const std::array<float, 2> d = sampleMip<2, kOwnedChannels>(owned, px, py, seg.cone_level);
    if (!(d[1] > 0.0f))
        return std::nullopt;
    MissCone cone;
    cone.t = std::clamp(d[0] / d[1], seg.t0, seg.t1);
    const float diameter = tr.lambda * std::fabs(tr.cocOf(cone.t));
    if (!at(tr.cocOf(cone.t), px, py) || !(diameter > 1.0f))
        return std::nullopt;
    const std::array<float, kOwnedChannels> m =
        sampleMip<kOwnedChannels>(tr, owned, px, py, diameter);
    if (!(m[1] > 0.0f))
        return std::nullopt;
    ++cnt.cone_missed;
    cone.v1 = std::min(m[1], 1.0f);
    cone.c1 = glm::vec3(m[2], m[3], m[4]) / m[1];
    if (shade && tr.settings->cone_shading == ConeShading::Footprint)
        cone.c1 = shadeTaps(tr, l, px, py, 0.5f * diameter, eye).value_or(cone.c1);
    return cone;
}

} // namespace
} // namespace dof::multiview_detail
