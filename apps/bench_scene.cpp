#include "apps/bench_scene.h"

#include "apps/report_text.h"
#include "apps/scene_source.h"

#include <raster/scene.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <filesystem>

namespace focal {

namespace fs = std::filesystem;

raster::Result<BenchScene> prepareScene(const std::string& spec, uint32_t width, uint32_t height) {
    // Only the view and lens are taken from the scene here (the renders run through focal
    // render), so no image is decoded.
    raster::ImportOptions no_images;
    no_images.roles = raster::TextureRoles{};
    raster::Result<raster::Scene> scene = loadScene(spec, no_images);
    if (!scene.ok())
        return scene.status();
    BenchScene s;
    s.spec = spec;
    s.name = safeName(spec.rfind("builtin:", 0) == 0
                          ? spec.substr(8)
                          : fs::path(spec).parent_path().parent_path().filename().string() + "_" +
                                fs::path(spec).stem().string());
    const raster::Bounds bounds = raster::worldBounds(*scene);
    s.view = scene->cameras.empty() ? raster::viewFramingBounds(bounds, width, height)
                                    : raster::viewFromCamera(scene->cameras[0], width, height);
    if (scene->lens) {
        s.aperture_radius = scene->lens->aperture_radius;
        s.focus_distance = scene->lens->focus_distance;
    } else {
        // No lens hint: an aperture of 1% of the scene's diagonal, focus on the centre pixel
        // (focal render's autofocus).
        s.aperture_radius = bounds.empty ? 0.01f : 0.01f * glm::length(bounds.max - bounds.min);
        s.lens = {"--aperture-radius", exactText(s.aperture_radius)};
        s.focus_distance = s.view.focus_distance;
    }
    std::error_code ec;
    if (spec.rfind("builtin:", 0) != 0) {
        const auto size = fs::file_size(spec, ec);
        const auto time = fs::last_write_time(spec, ec).time_since_epoch().count();
        s.identity = std::to_string(size) + "@" + std::to_string(time);
    }
    return s;
}

std::vector<std::string> findSceneFiles(const std::string& dir) {
    std::vector<std::string> files;
    std::error_code ec;
    if (!fs::is_directory(dir, ec))
        return files;
    for (auto it = fs::recursive_directory_iterator(dir, ec);
         !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
        const std::string ext = it->path().extension().string();
        if (it->is_regular_file() && (ext == ".gltf" || ext == ".glb") &&
            it->path().parent_path().filename() == "glTF")
            files.push_back(it->path().string());
    }
    std::sort(files.begin(), files.end());
    return files;
}

} // namespace focal
