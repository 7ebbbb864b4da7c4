// Fragment lists: every fragment of every primitive, per pixel, as GPU per-pixel linked lists
// build them (Yang et al. 2010; Selgrad et al. 2015 §4) but deterministic. Produced by
// Renderer::renderFragmentLists; consumed by the multi-layer method and the fragment dumps.
//
// Collection appends fragments in primitive order to per-pixel lists (a head index per pixel and
// a next index per node in a node pool of explicit capacity). The resolve sorts each list by
// depth (ties by primitive id), keeps the closest N (optionally skipping hidden fragments) and
// compacts all lists into consecutive arrays with a prefix sum over the counts. Owns its arrays.
#pragma once

#include <raster/storage.h>

#include <cstdint>
#include <vector>

namespace raster {

enum class OverflowPolicy : uint8_t {
    Grow, // re-render once with a node pool exactly as large as needed (reported in stats)
    Fail, // return an error naming the capacity and the count needed
};

struct FragmentListDesc {
    uint32_t node_capacity = 1u << 22;            // nodes in the pool (fragments before the N cap)
    uint32_t max_per_pixel = 4;                   // closest N kept by the resolve; 0 keeps all
    ColorFormat color_format = ColorFormat::Half; // Selgrad et al.: half colour and opacity
    DepthFormat depth_format = DepthFormat::Float32; // and single-precision depth
    OverflowPolicy on_overflow = OverflowPolicy::Grow;
    // With a cap of at most kMaxEarlyRejectCap, reject (before shading) fragments that already
    // have N nearer ones in their pixel: the same lists, fewer fragments shaded and sorted. Off:
    // every fragment is collected, as on the GPU (to inspect the uncapped list lengths).
    bool early_reject = true;
    // > 0: a fragment behind an opaque fragment of its own pixel by at most this factor of the
    // view distance (d <= d_o (1 + ε), d_o kept) is hidden, and the resolve skips it when it
    // picks the closest N, so the N slots go to fragments that can be seen. The multi-layer
    // merge (Selgrad et al. §5.1) gives such a fragment no weight whenever it shares the opaque
    // one's ε window (the skipped range is a superset of that: a window can start between d_o
    // and the fragment); dof::Multilayer passes its ε. 0: the closest N of all fragments.
    float hidden_epsilon = 0.0f;
};
constexpr uint32_t kMaxEarlyRejectCap = 16;

struct FragmentLists {
    uint32_t width = 0;
    uint32_t height = 0;
    FragmentListDesc desc;
    // Compacted, sorted lists: pixel i owns fragments [offsets[i], offsets[i+1]).
    std::vector<uint32_t> offsets;
    ColorBuffer color;               // linear RGB + opacity (alpha), one per fragment
    DepthBuffer depth;               // stored depth D, one per fragment (width = count, height = 1)
    std::vector<uint32_t> primitive; // submission index of the fragment's triangle
    std::vector<uint32_t> list_length; // per pixel: fragments appended (after early
                                       // rejection, before the cap)

    // Counts from the collection pass.
    uint64_t fragments_collected = 0; // nodes appended (every fragment without early rejection)
    uint64_t fragments_rejected = 0;  // rejected early (desc.early_reject), never shaded
    uint64_t fragments_hidden = 0;    // skipped as hidden (desc.hidden_epsilon) by the resolve
    uint64_t fragments_kept = 0;      // after the closest-N cap
    uint32_t max_list_length = 0; // longest list appended (after early rejection, before the cap)
    uint32_t node_capacity_used = 0; // capacity of the pool that succeeded
    bool grew = false;               // the pool overflowed once and was grown

    uint32_t count(size_t pixel) const { return offsets[pixel + 1] - offsets[pixel]; }
    size_t bytes() const {
        return (offsets.size() + primitive.size() + list_length.size()) * 4 + color.bytes() +
               depth.bytes();
    }
};

} // namespace raster
