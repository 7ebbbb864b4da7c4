#include <raster/layered_target.h>
#include <raster/memory_budget.h>

#include <algorithm>
#include <cmath>

namespace raster {

LayerInterval overlappedInterval(const LayeredTargetDesc& desc, uint32_t layer) {
    // Widen in inverse distance, where the circle of confusion is affine (Lee et al. Eq. 3-4).
    const float inv_near = 1.0f / desc.bounds[layer];
    const float inv_far = 1.0f / desc.bounds[layer + 1];
    const float pad = 0.5f * desc.overlap * (inv_near - inv_far);
    const float near_inv = inv_near + pad;
    const float far_inv = inv_far - pad;
    LayerInterval iv;
    iv.near_d = 1.0f / near_inv;
    iv.far_d = far_inv > 0.0f ? 1.0f / far_inv : INFINITY;
    const uint32_t last = uint32_t(desc.bounds.size()) - 2;
    // Depths outside the bounds belong to the first and last layer.
    if (layer == 0)
        iv.near_d = 0.0f;
    if (layer == last)
        iv.far_d = INFINITY;
    return iv;
}

uint32_t layerOf(const LayeredTargetDesc& desc, float d) {
    const auto it = std::upper_bound(desc.bounds.begin(), desc.bounds.end(), d);
    const int64_t l = int64_t(it - desc.bounds.begin()) - 1;
    return uint32_t(std::clamp<int64_t>(l, 0, int64_t(desc.bounds.size()) - 2));
}

uint64_t layeredTargetBytes(uint32_t width, uint32_t height, uint32_t layers,
                            const LayeredTargetDesc& desc, bool transparency) {
    const uint64_t texel = bytesPerColor(desc.color_format) + bytesPerDepth(desc.depth_format);
    uint64_t per_texel = texel + (desc.gbuffer ? sizeof(GSample) : 0);
    if (transparency)
        per_texel += texel + (desc.gbuffer ? sizeof(GSample) + sizeof(float) : 0);
    return mulBytes(mulBytes(uint64_t{width} * height, layers), per_texel);
}

} // namespace raster
