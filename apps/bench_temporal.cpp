#include "apps/bench_temporal.h"

#include "apps/bench_reference.h"
#include "apps/bench_render.h"
#include "apps/bench_sweep.h"
#include "apps/report_text.h"

#include <cmath>
#include <cstdio>
#include <filesystem>

namespace focal {

namespace fs = std::filesystem;

namespace {

constexpr float kPi = 3.14159265358979f;

// The render options of frame k of K: the camera as --eye/--target, the lens explicit.
std::vector<std::string> frameArgs(const BenchArgs& args, const BenchScene& scene, uint32_t k) {
    const raster::View& v = scene.view;
    const float t = float(k) / float(args.temporal_frames - 1);
    const float df = scene.focus_distance * (0.85f + 0.3f * t);
    const glm::vec3 eye = v.eye + v.right * (0.02f * scene.focus_distance * t);
    const glm::vec3 target = eye + v.forward * scene.focus_distance;
    auto vec = [](glm::vec3 p) {
        return exactText(p.x) + "," + exactText(p.y) + "," + exactText(p.z);
    };
    return {scene.spec,
            "--width",
            std::to_string(args.width),
            "--height",
            std::to_string(args.height),
            "--eye",
            vec(eye),
            "--target",
            vec(target),
            "--up",
            vec(v.up),
            "--yfov",
            exactText(v.yfov * 180.0f / kPi),
            "--aperture-radius",
            exactText(scene.aperture_radius),
            "--focus-distance",
            exactText(df)};
}

// Mean over pixels and RGB of |a - b|.
double meanAbs(const ImageData& a, const ImageData& b) {
    double sum = 0.0;
    const size_t n = size_t(a.width) * a.height;
    for (size_t i = 0; i < n; ++i)
        for (uint32_t c = 0; c < 3; ++c)
            sum += std::fabs(double(a.pixels[i * a.channels + c]) -
                             double(b.pixels[i * b.channels + c]));
    return sum / double(3 * n);
}

// Mean over pixels and RGB of |(a1 - a0) - (r1 - r0)|: change the reference does not have.
double excess(const ImageData& a0, const ImageData& a1, const ImageData& r0, const ImageData& r1) {
    double sum = 0.0;
    const size_t n = size_t(a0.width) * a0.height;
    for (size_t i = 0; i < n; ++i)
        for (uint32_t c = 0; c < 3; ++c) {
            const size_t j = i * a0.channels + c, q = i * r0.channels + c;
            sum += std::fabs((double(a1.pixels[j]) - double(a0.pixels[j])) -
                             (double(r1.pixels[q]) - double(r0.pixels[q])));
        }
    return sum / double(3 * n);
}

// The method's K frames, and the sum of their sRGB PSNRs against the references.
raster::Result<std::vector<ImageData>> methodFrames(const BenchArgs& args, const BenchScene& scene,
                                                    const std::string& method,
                                                    const Setting& setting,
                                                    const std::vector<ImageData>& refs,
                                                    const LoadedScene& loaded, double& psnr_sum) {
    std::vector<ImageData> frames;
    for (uint32_t k = 0; k < args.temporal_frames; ++k) {
        std::vector<std::string> a = frameArgs(args, scene, k);
        if (method == "pinhole")
            a.resize(a.size() - 4); // no lens: drop --aperture-radius, --focus-distance
        a.insert(a.end(), {"--threads", std::to_string(args.threads), "--method", method});
        a.insert(a.end(), setting.args.begin(), setting.args.end());
        RenderRun r = renderInMemory(a, &loaded);
        if (r.exit_code != 0)
            return raster::Status::error(scene.spec + ": temporal frame of " + method + " failed");
        raster::Result<dof::ErrorMetrics> m =
            dof::compareImages(imageRefOf(r.image), imageRefOf(refs[k]));
        psnr_sum += m.ok() && std::isfinite(m->psnr_srgb_db) ? m->psnr_srgb_db : 100.0;
        frames.push_back(std::move(r.image));
    }
    return frames;
}

} // namespace

raster::Result<Json> temporalStudy(const BenchArgs& args, const BenchScene& scene,
                                   const std::string& cache_dir) {
    const uint32_t k_frames = args.temporal_frames;
    // The scene, loaded once for every frame (they differ in camera and lens only).
    raster::Result<LoadedScene> loaded = loadBenchScene(frameArgs(args, scene, 0));
    if (!loaded.ok())
        return loaded.status();
    std::vector<ImageData> refs;
    for (uint32_t k = 0; k < k_frames; ++k) {
        std::fprintf(stderr, "focal: bench: temporal reference frame %u/%u\n", k + 1, k_frames);
        raster::Result<Reference> r =
            reference(scene, frameArgs(args, scene, k), args.temporal_ref_samples, args.threads,
                      cache_dir, &*loaded);
        if (!r.ok())
            return r.status();
        refs.push_back(std::move(r->color));
    }
    double ref_flicker = 0.0;
    for (uint32_t k = 1; k < k_frames; ++k)
        ref_flicker += meanAbs(refs[k], refs[k - 1]);
    ref_flicker /= double(k_frames - 1);

    Json temporal = Json::array();
    for (const std::string& method : args.methods) {
        // The most accurate setting, except accum's N = 16 (its best would be the temporal
        // reference itself).
        const Setting setting = studySetting(method, args.quick, &Setting::temporal);
        double psnr_sum = 0.0;
        raster::Result<std::vector<ImageData>> frames =
            methodFrames(args, scene, method, setting, refs, *loaded, psnr_sum);
        if (!frames.ok())
            return frames.status();
        double flicker = 0.0, extra = 0.0;
        for (uint32_t k = 1; k < k_frames; ++k) {
            flicker += meanAbs((*frames)[k], (*frames)[k - 1]);
            extra += excess((*frames)[k - 1], (*frames)[k], refs[k - 1], refs[k]);
        }
        flicker /= double(k_frames - 1);
        extra /= double(k_frames - 1);
        temporal.push_back({{"scene", scene.spec},
                            {"method", method},
                            {"setting", setting.label},
                            {"frames", k_frames},
                            {"reference_samples", args.temporal_ref_samples},
                            {"flicker", flicker},
                            {"reference_flicker", ref_flicker},
                            {"flicker_ratio", ref_flicker > 0 ? flicker / ref_flicker : 0.0},
                            {"excess_flicker", extra},
                            {"mean_psnr_srgb_db", psnr_sum / double(k_frames)}});
        std::fprintf(stderr, "focal: bench: temporal %s: flicker %.5f (reference %.5f)\n",
                     method.c_str(), flicker, ref_flicker);
    }
    return temporal;
}

} // namespace focal
