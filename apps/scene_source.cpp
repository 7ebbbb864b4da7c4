#include "apps/scene_source.h"

#include <raster/gltf_import.h>
#include <scenes/builtin.h>

#include <algorithm>
#include <filesystem>

namespace focal {

raster::Result<raster::Scene> loadScene(const std::string& spec) {
    constexpr std::string_view kBuiltin = "builtin:";
    if (spec.rfind(kBuiltin, 0) == 0)
        return scenes::makeBuiltinScene(std::string_view(spec).substr(kBuiltin.size()));
    std::string ext = std::filesystem::path(spec).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    if (ext != ".gltf" && ext != ".glb")
        return raster::Status::error(spec + ": not a scene (expected a .gltf or .glb file, or "
                                            "builtin:NAME)");
    return raster::importGltf(spec);
}

} // namespace focal
