// glTF 2.0 import (.gltf and .glb) into focal's Scene. The only place tinygltf is used.
// Validates everything it reads; any problem is a Status naming the file and the item.
#pragma once

#include <raster/scene.h>
#include <raster/status.h>

#include <string>

namespace raster {

// Loads the default scene (or scene 0) of a glTF file. Unsupported optional extensions become
// Scene::warnings; an unsupported required extension is an error.
Result<Scene> importGltf(const std::string& path);

} // namespace raster
