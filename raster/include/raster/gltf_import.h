// glTF 2.0 import (.gltf and .glb) into focal's Scene. The only place tinygltf is used.
// Validates everything it reads; any problem is a Status naming the file and the item.
// Decodes (and mipmaps) only the images a caller-chosen set of texture roles samples, in
// parallel on the caller's TaskPool; the Scene is identical for any thread count.
#pragma once

#include <raster/memory_budget.h>
#include <raster/scene.h>
#include <raster/status.h>
#include <raster/task_pool.h>

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

namespace raster {

struct ImportOptions {
    // When set, only images some material uses in one of these roles are decoded and
    // mipmapped; the others keep their name and roles but no pixels (Image::decoded = false)
    // and are not checked beyond what needs no decoding. Pass sampledTextureRoles(mode)
    // (renderer.h) to load what a render in that mode reads. Unset: every image is decoded,
    // whatever uses it, as a viewer or a file checker wants.
    std::optional<TextureRoles> roles;
    // Decodes images in parallel when set (one image per task); nullptr decodes inline.
    TaskPool* pool = nullptr;
    // Bounds the file, its buffer and image files, and the zeros of accessors without a
    // bufferView (which cost nothing in the file); unlimited by default.
    MemoryBudget memory_budget;
};

// Where import time went. Times are wall-clock milliseconds and not deterministic, except that
// decode and mipmaps are summed over images (CPU time on all workers, so with several threads
// they can exceed `images`). Counts are deterministic.
struct ImportStats {
    double ms_total = 0.0;
    double ms_parse = 0.0;   // read the file, parse the JSON, read buffers and image files
    double ms_images = 0.0;  // decode and mipmap the needed images (wall time)
    double ms_decode = 0.0;  // sum over images: PNG/JPEG decode, 16-bit to 8-bit
    double ms_mipmaps = 0.0; // sum over images: buildMipChain
    double ms_scene = 0.0;   // materials, meshes (vertex import) and nodes
    uint32_t images_decoded = 0;
    uint32_t images_skipped = 0; // no material uses them in a role asked for
};

// Loads the default scene (or scene 0) of a glTF file. Unsupported optional extensions become
// Scene::warnings; an unsupported required extension is an error. A needed image that cannot be
// decoded is an error when it is base colour or emissive (colour), else a warning and a white
// texel; an image that is not needed is not decoded, so only problems found without decoding
// it (a missing file, no bytes, an absurd size in its header) are reported, as warnings.
Result<Scene> importGltf(const std::string& path, const ImportOptions& options = {},
                         ImportStats* stats = nullptr);

// The same for a .gltf or .glb already in memory (the fuzzer, embedded use). `name` stands for
// the file in messages; relative uris of buffers and images resolve against `base_dir`.
Result<Scene> importGltfFromMemory(const unsigned char* data, size_t size, const std::string& name,
                                   const std::string& base_dir, const ImportOptions& options = {},
                                   ImportStats* stats = nullptr);

} // namespace raster
