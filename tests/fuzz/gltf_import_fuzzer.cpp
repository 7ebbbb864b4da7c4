// libFuzzer target: the glTF/GLB importer (raster/gltf_import.h) on arbitrary bytes. Any crash,
// sanitizer report, leak or unbounded allocation is a bug: hostile files must give a Status.
// Seeds: tests/fuzz/corpus/gltf_import (and every fixture in tests/data/gltf); see docs/testing.md.
#include <raster/gltf_import.h>

#include <cstddef>
#include <cstdint>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    raster::ImportOptions options;
    // Well under libFuzzer's -rss_limit_mb (2 GiB): a file asking for more must be refused.
    options.memory_budget.bytes = uint64_t{512} << 20;
    // Relative uris resolve in a folder that does not exist; absolute ones may read real files,
    // which the importer must survive too (directories, devices, large files).
    (void)raster::importGltfFromMemory(data, size, "fuzz.gltf", "/nonexistent-focal-fuzz", options);
    return 0;
}
