// The scenes `focal bench` runs: which ones (built-ins and glTF files found in a folder) and, per
// scene, the camera and lens every render of it gets. Consumes scene specs; produces BenchScene
// values owned by the caller. Loads each scene once (without decoding images) to read its view
// and lens hint.
#pragma once

#include <raster/camera.h>
#include <raster/status.h>

#include <cstdint>
#include <string>
#include <vector>

namespace focal {

// A scene to benchmark: its spec and the camera/lens options every render of it gets.
struct BenchScene {
    std::string spec;
    std::string name;              // file-safe
    std::vector<std::string> lens; // e.g. --aperture-radius for glTF files without a lens hint
    std::string identity;          // file size + mtime for glTF files (reference cache key)
    raster::View view;             // the default camera at the bench resolution
    float aperture_radius = 0.0f;
    float focus_distance = 1.0f;
};

raster::Result<BenchScene> prepareScene(const std::string& spec, uint32_t width, uint32_t height);

// The glTF scenes under `dir` in the Khronos sample layout, DIR/**/glTF/*.gl{tf,b}, sorted; none
// when the folder does not exist.
std::vector<std::string> findSceneFiles(const std::string& dir);

} // namespace focal
