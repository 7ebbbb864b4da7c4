#include "apps/bench_reference.h"

#include "apps/bench_render.h"
#include "apps/fnv1a.h"
#include "apps/text_file.h"

#include <cstdio>
#include <filesystem>
#include <fstream>

namespace focal {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

namespace {

// The key hashes every option that affects the image plus the scene file's identity.
std::string referenceKeyText(const BenchScene& scene, const std::vector<std::string>& common,
                             uint32_t samples) {
    std::string text = "focal-bench-ref-v1|" + scene.spec + "|" + scene.identity;
    for (const std::string& a : common)
        text += "|" + a;
    return text + "|method=accum|samples=" + std::to_string(samples) +
           "|seed=0|pixel-jitter=off|lens-pattern=hammersley|depth-format=float32|"
           "shading=material|texture-filter=sampler";
}

std::string hexHash(const std::string& text) {
    Fnv1a64 h;
    h.mix(text.data(), text.size());
    char buf[17];
    std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h.value));
    return buf;
}

} // namespace

dof::ImageRef imageRefOf(const ImageData& img) {
    return {img.pixels.data(), img.width, img.height, img.channels};
}

raster::Result<Reference> reference(const BenchScene& scene, const std::vector<std::string>& common,
                                    uint32_t samples, uint32_t threads,
                                    const std::string& cache_dir, const LoadedScene* loaded) {
    Reference ref;
    const std::string keytext = referenceKeyText(scene, common, samples);
    ref.key = hexHash(keytext);
    const std::string base = (fs::path(cache_dir) / ref.key).string();
    const std::string color_path = base + ".exr", depth_path = base + "_depth.exr";
    std::error_code ec;
    if (fs::exists(color_path, ec) && fs::exists(depth_path, ec) && fs::exists(base + ".json")) {
        ref.cached = true;
        std::ifstream f(base + ".json");
        Json j = Json::parse(f, nullptr, false);
        if (!j.is_discarded() && j.contains("time_ms"))
            ref.ms = j["time_ms"].value("total", 0.0);
    } else {
        std::vector<std::string> args = common;
        args.insert(args.end(), {"--method", "accum", "--samples", std::to_string(samples),
                                 "--depth-out", depth_path, "--threads", std::to_string(threads)});
        RenderRun r = renderInMemory(args, loaded);
        if (r.exit_code != 0)
            return raster::Status::error("the reference render of " + scene.spec + " failed");
        r.stats["bench_key"] = keytext;
        // The cache: the images, then the record that says they are complete.
        if (raster::Status s = writeImage(color_path, r.image); !s.ok())
            return s;
        if (raster::Status s = writeImage(depth_path, r.depth); !s.ok())
            return s;
        if (raster::Status s = writeTextFile(base + ".json", r.stats.dump(2) + "\n"); !s.ok())
            return s;
        ref.ms = r.stats["time_ms"].value("total", 0.0);
    }
    raster::Result<ImageData> color = readImage(color_path);
    if (!color.ok())
        return color.status();
    raster::Result<ImageData> depth = readImage(depth_path);
    if (!depth.ok())
        return depth.status();
    ref.color = std::move(*color);
    ref.depth = std::move(*depth);
    ref.band = dof::discontinuityBand(imageRefOf(ref.depth), kBandThreshold, kBandRadius);
    for (uint8_t m : ref.band)
        ref.band_pixels += m;
    return ref;
}

} // namespace focal
