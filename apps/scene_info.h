// `focal info SCENE`: a human-readable description of a loaded Scene. Consumes a raster::Scene;
// produces a multi-line report (owned by the caller); touches nothing else.
#pragma once

#include <raster/gltf_import.h>
#include <raster/scene.h>

#include <string>

namespace focal {

// Triangle count, meshes, primitives, materials (alpha modes), images (sizes), samplers,
// cameras (yfov in degrees, near/far), lights, world bounds, extensions and import warnings.
// Every line ends with '\n'.
std::string describeScene(const raster::Scene& scene);

// One line: where loading time went (parse, images, scene) and how many images were decoded.
std::string describeLoad(const raster::ImportStats& stats);

} // namespace focal
