#include "apps/scene_source.h"

#include <scenes/builtin.h>

#include <algorithm>
#include <chrono>
#include <filesystem>

namespace focal {

raster::Result<raster::Scene> loadScene(const std::string& spec,
                                        const raster::ImportOptions& options,
                                        raster::ImportStats* stats) {
    constexpr std::string_view kBuiltin = "builtin:";
    if (spec.rfind(kBuiltin, 0) == 0) {
        const auto t0 = std::chrono::steady_clock::now();
        raster::Result<raster::Scene> scene =
            scenes::makeBuiltinScene(std::string_view(spec).substr(kBuiltin.size()));
        if (stats) {
            *stats = raster::ImportStats{};
            stats->ms_total =
                std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                    .count();
        }
        return scene;
    }
    std::string ext = std::filesystem::path(spec).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    if (ext != ".gltf" && ext != ".glb")
        return raster::Status::error(spec + ": not a scene (expected a .gltf or .glb file, or "
                                            "builtin:NAME)");
    return raster::importGltf(spec, options, stats);
}

} // namespace focal
