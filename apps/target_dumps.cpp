#include "apps/target_dumps.h"

#include "apps/false_colour.h"
#include "apps/image_io.h"
#include "apps/text_file.h"

#include <raster/texture.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

namespace focal {

using raster::Status;

std::vector<float> uniformInverseDepthBounds(float d_near, float d_far, uint32_t layers) {
    std::vector<float> bounds(layers + 1);
    const float inv_near = 1.0f / d_near, inv_far = 1.0f / d_far;
    for (uint32_t i = 0; i <= layers; ++i)
        bounds[i] = 1.0f / (inv_near + (inv_far - inv_near) * float(i) / float(layers));
    bounds[layers] = d_far;
    return bounds;
}

namespace {

std::string numbered(const std::string& dir, const char* stem, uint32_t i, const char* suffix) {
    char name[64];
    std::snprintf(name, sizeof(name), "%s_%02u%s", stem, i, suffix);
    return (std::filesystem::path(dir) / name).string();
}

// Creates the dump folder (and its parents) when missing.
Status checkDir(const std::string& dir) {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (!std::filesystem::is_directory(dir, ec))
        return Status::error(dir + ": cannot create the dump folder");
    return {};
}

} // namespace

Status dumpLayers(const raster::LayeredTarget& layers, const raster::View& view,
                  const std::string& dir) {
    if (Status s = checkDir(dir); !s.ok())
        return s;
    const size_t pixels = layers.pixelCount();
    nlohmann::json index;
    index["width"] = layers.width;
    index["height"] = layers.height;
    index["bounds"] = layers.desc.bounds;
    index["overlap"] = layers.desc.overlap;
    index["routing"] = layers.desc.routing == raster::LayerRouting::MaxVertexDepth
                           ? "max-vertex-depth"
                           : "per-fragment";
    // One plane (colour + depth) of layer l as PREFIX_color.png and PREFIX_depth.exr; returns
    // the covered pixel count.
    auto dumpPlane = [&](uint32_t l, const raster::ColorBuffer& colors,
                         const raster::DepthBuffer& depths,
                         const std::string& suffix) -> raster::Result<size_t> {
        ImageData color{layers.width, layers.height, 4, std::vector<float>(pixels * 4)};
        ImageData depth{layers.width, layers.height, 1, std::vector<float>(pixels)};
        size_t covered = 0;
        for (size_t p = 0; p < pixels; ++p) {
            const glm::vec4 c = colors.load(layers.index(l, p));
            for (int k = 0; k < 4; ++k)
                color.pixels[p * 4 + size_t(k)] = c[k];
            const float d = depths.load(layers.index(l, p));
            depth.pixels[p] = d < raster::kFarDepth ? raster::distanceFromDepth(view, d) : 0.0f;
            covered += c.a > 0.0f;
        }
        if (Status s =
                writeImage(numbered(dir, "layer", l, (suffix + "_color.png").c_str()), color);
            !s.ok())
            return s;
        if (Status s =
                writeImage(numbered(dir, "layer", l, (suffix + "_depth.exr").c_str()), depth);
            !s.ok())
            return s;
        return covered;
    };
    for (uint32_t l = 0; l < layers.layer_count; ++l) {
        raster::Result<size_t> covered = dumpPlane(l, layers.color, layers.depth, "");
        if (!covered.ok())
            return covered.status();
        size_t transparent = 0;
        if (layers.hasTransparency()) { // BLEND surfaces: premultiplied colour, alpha = opacity
            raster::Result<size_t> t =
                dumpPlane(l, layers.transparent_color, layers.transparent_depth, "_transparent");
            if (!t.ok())
                return t.status();
            transparent = *t;
        }
        const raster::LayerInterval iv = raster::overlappedInterval(layers.desc, l);
        index["layers"].push_back({{"near", layers.desc.bounds[l]},
                                   {"far", layers.desc.bounds[l + 1]},
                                   {"overlapped_near", iv.near_d},
                                   {"overlapped_far", std::isfinite(iv.far_d) ? iv.far_d : -1.0f},
                                   {"covered_pixels", *covered},
                                   {"transparent_pixels", transparent}});
    }
    return writeTextFile((std::filesystem::path(dir) / "layers.json").string(),
                         index.dump(2) + "\n");
}

Status dumpFragments(const raster::FragmentLists& lists, const raster::View& view,
                     const std::string& dir, uint32_t first_k) {
    if (Status s = checkDir(dir); !s.ok())
        return s;
    const size_t pixels = size_t(lists.width) * lists.height;
    ImageData heat_map{lists.width, lists.height, 3, std::vector<float>(pixels * 3)};
    ImageData counts{lists.width, lists.height, 1, std::vector<float>(pixels)};
    const float max_len = float(std::max(lists.max_list_length, 1u));
    for (size_t p = 0; p < pixels; ++p) {
        const float n = float(lists.list_length[p]);
        counts.pixels[p] = n;
        // Heat maps are for looking at: the colours are sRGB values, stored linear here so
        // the PNG writer's encoding returns them unchanged.
        const glm::vec3 c = heat(n / max_len);
        for (int k = 0; k < 3; ++k)
            heat_map.pixels[p * 3 + size_t(k)] = raster::srgbToLinear(c[k]);
    }
    const std::filesystem::path base(dir);
    if (Status s = writeImage((base / "fragment_count.png").string(), heat_map); !s.ok())
        return s;
    if (Status s = writeImage((base / "fragment_count.exr").string(), counts); !s.ok())
        return s;
    for (uint32_t k = 0; k < first_k; ++k) {
        ImageData color{lists.width, lists.height, 4, std::vector<float>(pixels * 4, 0.0f)};
        ImageData depth{lists.width, lists.height, 1, std::vector<float>(pixels, 0.0f)};
        for (size_t p = 0; p < pixels; ++p) {
            if (k >= lists.count(p))
                continue;
            const uint32_t i = lists.offsets[p] + k;
            const glm::vec4 c = lists.color.load(i);
            for (int ch = 0; ch < 4; ++ch)
                color.pixels[p * 4 + size_t(ch)] = c[ch];
            depth.pixels[p] = raster::distanceFromDepth(view, lists.depth.load(i));
        }
        if (Status s = writeImage(numbered(dir, "fragment", k, "_color.png"), color); !s.ok())
            return s;
        if (Status s = writeImage(numbered(dir, "fragment", k, "_depth.exr"), depth); !s.ok())
            return s;
    }
    nlohmann::json index = {{"width", lists.width},
                            {"height", lists.height},
                            {"fragments_collected", lists.fragments_collected},
                            {"fragments_kept", lists.fragments_kept},
                            {"max_list_length", lists.max_list_length},
                            {"max_per_pixel", lists.desc.max_per_pixel},
                            {"heat_map_max", lists.max_list_length}};
    return writeTextFile((base / "fragments.json").string(), index.dump(2) + "\n");
}

} // namespace focal
