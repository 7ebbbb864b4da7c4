// Layered target: the GPU's layered rendering (an array texture with one depth buffer per
// slice), as Lee, Eisemann & Seidel 2009 §4.1-4.2 use it to decompose a scene into depth layers.
// Produced by Renderer::renderLayers; consumed by the multiview method and the layer dumps.
// Owns its buffers; layer-major storage (layer l's pixel i is element l * width * height + i).
#pragma once

#include <raster/storage.h>

#include <glm/vec3.hpp>

#include <cstdint>
#include <vector>

namespace raster {

enum class LayerRouting : uint8_t {
    // Lee et al. §4.2: each triangle goes to the layer of its maximum vertex depth (their
    // geometry-shader pass); a fragment-copy pass then moves pixels that belong to other
    // (overlapped) layers there with a manual depth test. Approximate at layer bounds.
    MaxVertexDepth,
    // Every fragment goes to every layer whose overlapped interval holds its depth: identical to
    // separate renders with clipping planes at each layer's bounds (the paper's definition).
    PerFragment,
};

struct LayeredTargetDesc {
    // M+1 increasing distances along the view axis; layer l holds [bounds[l], bounds[l+1]).
    // Depths before bounds[0] go to layer 0 and beyond bounds[M] to layer M-1.
    std::vector<float> bounds;
    // Each interval is widened by overlap/2 of its width on both sides, measured in 1/d (the
    // space in which the circle of confusion is affine), so neighbours share `overlap` of a layer.
    float overlap = 0.1f;
    LayerRouting routing = LayerRouting::MaxVertexDepth;
    ColorFormat color_format = ColorFormat::Float32;
    DepthFormat depth_format = DepthFormat::Float32;
    bool gbuffer = false; // also store normals and material parameters (Lee et al. §5)
};

// One G-buffer texel: the surface a layer pixel shows, for shading it from another direction.
struct GSample {
    glm::vec3 normal{0.0f}; // world space, unit, facing the centre view
    float metallic = 0.0f;
    glm::vec3 base_color{0.0f}; // linear albedo (texture x factor x vertex colour)
    float roughness = 1.0f;
    glm::vec3 emissive{0.0f};
    float unlit = 0.0f; // 1: the colour does not depend on the view
};

struct LayeredTarget {
    uint32_t width = 0;
    uint32_t height = 0;
    uint32_t layer_count = 0;
    LayeredTargetDesc desc;
    // Linear RGBA; alpha is coverage (0 where the layer is empty). Cleared to (0,0,0,0).
    ColorBuffer color;
    // Stored depth D per layer (1 where empty), layer-major like colour.
    DepthBuffer depth;
    // G-buffer (when desc.gbuffer), layer-major: what re-shading a hit needs (Lee et al. §5).
    std::vector<GSample> gbuffer;
    // The transparent plane of each layer (allocated only when the scene has BLEND materials;
    // not in the paper, whose layers hold opaque surfaces only): the BLEND fragments whose depth
    // lies in the layer's own (not overlapped) interval, routed per fragment, that pass its
    // opaque depth test as drawn (BLEND triangles come after the opaque ones), composited with
    // the over operator in primitive order into premultiplied RGBA (alpha = opacity, 0 = none),
    // and the depth of the nearest of them. Each BLEND fragment is in exactly one plane.
    ColorBuffer transparent_color;
    DepthBuffer transparent_depth;
    // With desc.gbuffer and a transparent plane: the G-buffer sample of each plane texel's top
    // pane (the last one composited) and its opacity (0: no pane). The composite is linear in
    // the top pane's colour, so the pane can be re-shaded from another eye exactly
    // (Lee et al. §5). 52 bytes per texel and layer.
    std::vector<GSample> transparent_gbuffer;
    std::vector<float> transparent_top_alpha;

    size_t pixelCount() const { return size_t(width) * height; }
    size_t index(uint32_t layer, size_t pixel) const { return layer * pixelCount() + pixel; }
    bool hasTransparency() const { return transparent_depth.bytes() > 0; }
    size_t bytes() const {
        return color.bytes() + depth.bytes() + gbuffer.size() * sizeof(GSample) +
               transparent_color.bytes() + transparent_depth.bytes() +
               transparent_gbuffer.size() * sizeof(GSample) +
               transparent_top_alpha.size() * sizeof(float);
    }
};

// Bytes of the buffers a width x height LayeredTarget with `layers` layers holds (with BLEND
// materials, also the transparent planes): what Renderer::renderLayers checks against the budget.
uint64_t layeredTargetBytes(uint32_t width, uint32_t height, uint32_t layers,
                            const LayeredTargetDesc& desc, bool transparency);

// The overlapped interval of layer l in distances [near, far).
struct LayerInterval {
    float near_d;
    float far_d;
};
LayerInterval overlappedInterval(const LayeredTargetDesc& desc, uint32_t layer);
// The layer whose (non-overlapped) interval holds distance d, clamped to [0, M-1].
uint32_t layerOf(const LayeredTargetDesc& desc, float d);

} // namespace raster
