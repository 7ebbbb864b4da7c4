#include "apps/render_command.h"

#include "apps/image_io.h"
#include "apps/scene_source.h"
#include "apps/text_file.h"

#include <raster/camera.h>
#include <raster/renderer.h>
#include <raster/task_pool.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <thread>

#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

namespace focal {

using raster::Result;
using raster::Status;

namespace {

constexpr float kPi = 3.14159265358979f;

Result<glm::vec3> parseVec3(const std::string& option, const std::string& text) {
    glm::vec3 v(0.0f);
    std::istringstream in(text);
    char comma1 = 0, comma2 = 0;
    in >> v.x >> comma1 >> v.y >> comma2 >> v.z;
    if (!in || comma1 != ',' || comma2 != ',' || !(in >> std::ws).eof() ||
        !std::isfinite(v.x + v.y + v.z))
        return Status::error(option + " expects three finite numbers X,Y,Z, got '" + text + "'");
    return v;
}

// The camera: explicit --eye/--target, a glTF camera, or one framing the scene's bounds.
Result<raster::View> resolveView(const raster::Scene& scene, const RenderArgs& args) {
    raster::View view;
    const raster::Bounds bounds = raster::worldBounds(scene);
    if (args.eye || args.target) {
        if (!args.eye || !args.target)
            return Status::error("--eye and --target go together");
        if (args.camera)
            return Status::error("--camera cannot be combined with --eye/--target");
        auto eye = parseVec3("--eye", *args.eye);
        auto target = parseVec3("--target", *args.target);
        auto up = parseVec3("--up", args.up.value_or("0,1,0"));
        for (const Status* s : {&eye.status(), &target.status(), &up.status()})
            if (!s->ok())
                return *s;
        if (glm::length(*target - *eye) <= 0.0f)
            return Status::error("--eye and --target must be different points");
        // Default clip planes enclose the scene's bounds as seen from the eye.
        float far_dist = 1.0f;
        if (!bounds.empty)
            for (int i = 0; i < 8; ++i) {
                const glm::vec3 corner((i & 1) ? bounds.max.x : bounds.min.x,
                                       (i & 2) ? bounds.max.y : bounds.min.y,
                                       (i & 4) ? bounds.max.z : bounds.min.z);
                far_dist = std::max(far_dist, 1.01f * glm::length(corner - *eye));
            }
        view = raster::viewLookAt(*eye, *target, *up, args.yfov_deg.value_or(45.0f) * kPi / 180.0f,
                                  args.width, args.height, args.znear.value_or(1e-3f * far_dist),
                                  args.zfar.value_or(far_dist));
        return view;
    }
    if (!scene.cameras.empty() || args.camera) {
        const int index = args.camera.value_or(0);
        if (index < 0 || size_t(index) >= scene.cameras.size())
            return Status::error(scene.source + ": has no camera " + std::to_string(index) +
                                 " (it has " + std::to_string(scene.cameras.size()) + ")");
        view = raster::viewFromCamera(scene.cameras[size_t(index)], args.width, args.height);
    } else {
        view = raster::viewFramingBounds(bounds, args.width, args.height);
    }
    if (args.yfov_deg)
        view.yfov = *args.yfov_deg * kPi / 180.0f;
    if (args.znear)
        view.znear = *args.znear;
    if (args.zfar)
        view.zfar = *args.zfar;
    if (scene.lens)
        view.focus_distance = scene.lens->focus_distance;
    return view;
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

int fail(const std::string& message) {
    std::fprintf(stderr, "focal: error: %s\n", message.c_str());
    return 1;
}

}  // namespace

CLI::App* addRenderCommand(CLI::App& app, RenderArgs& args) {
    CLI::App* cmd = app.add_subcommand("render", "Render a scene to an image");
    args.threads = std::max(1u, std::thread::hardware_concurrency());
    cmd->add_option("scene", args.scene, "glTF file (.gltf/.glb) or builtin:NAME")->required();
    cmd->add_option("-o,--output", args.output, "output image: .exr (linear float RGBA) or .png "
                                                "(8-bit sRGB)")
        ->required();
    cmd->add_option("--width", args.width, "image width in pixels")
        ->capture_default_str()
        ->check(CLI::Range(1, 16384));
    cmd->add_option("--height", args.height, "image height in pixels")
        ->capture_default_str()
        ->check(CLI::Range(1, 16384));
    cmd->add_option("--camera", args.camera, "index of the glTF camera to use [default: 0]");
    cmd->add_option("--eye", args.eye, "camera position X,Y,Z (world units)");
    cmd->add_option("--target", args.target, "point looked at X,Y,Z (world units)");
    cmd->add_option("--up", args.up, "up direction X,Y,Z [default: 0,1,0]");
    cmd->add_option("--yfov", args.yfov_deg, "vertical field of view in degrees [default: the "
                                             "camera's, or 45]")
        ->check(CLI::Range(0.01f, 177.0f));
    cmd->add_option("--near", args.znear, "near clip distance (world units)");
    cmd->add_option("--far", args.zfar, "far clip distance (world units; 0 = infinite)");
    cmd->add_option("--threads", args.threads, "worker threads (0 = run inline on the caller)")
        ->capture_default_str()
        ->check(CLI::Range(0, 256));
    cmd->add_option("--tile", args.tile, "tile size in pixels (multiple of 8, 8 to 256)")
        ->capture_default_str()
        ->check(CLI::Range(8, 256));
    cmd->add_option("--method", args.method, "depth-of-field method")
        ->capture_default_str()
        ->check(CLI::IsMember({"pinhole"}));
    cmd->add_option("--stats", args.stats_path, "write every parameter, stage times (ms) and "
                                                "counts to this JSON file");
    cmd->add_option("--repeat", args.repeat, "render K times; stats keep every run and the median")
        ->capture_default_str()
        ->check(CLI::Range(1, 100000));
    cmd->add_option("--depth-out", args.depth_out, "also write linear depth (distance along the "
                                                   "view axis, world units) to this EXR");
    cmd->add_option("--depth-format", args.depth_format, "depth buffer storage")
        ->capture_default_str()
        ->check(CLI::IsMember({"float32", "unorm16"}));
    cmd->add_option("--shading", args.shading, "material: as the material says; unlit; lit")
        ->capture_default_str()
        ->check(CLI::IsMember({"material", "unlit", "lit"}));
    cmd->add_option("--texture-filter", args.texture_filter, "sampler: as the glTF sampler says")
        ->capture_default_str()
        ->check(CLI::IsMember({"sampler", "nearest", "bilinear", "trilinear"}));
    return cmd;
}

int runRender(const RenderArgs& args) {
    if (args.tile % 8 != 0)
        return fail("--tile " + std::to_string(args.tile) + " must be a multiple of 8");
    if (!args.depth_out.empty() && !isLinearFormat(args.depth_out))
        return fail(args.depth_out + ": --depth-out must be an .exr file");
    Result<raster::Scene> scene = loadScene(args.scene);
    if (!scene.ok())
        return fail(scene.status().message());
    for (const std::string& w : scene->warnings)
        std::fprintf(stderr, "focal: warning: %s\n", w.c_str());
    Result<raster::View> view = resolveView(*scene, args);
    if (!view.ok())
        return fail(view.status().message());

    raster::RenderOptions options;
    options.tile_size = args.tile;
    options.depth_format =
        args.depth_format == "unorm16" ? raster::DepthFormat::Unorm16 : raster::DepthFormat::Float32;
    options.shading = args.shading == "unlit" ? raster::ShadingMode::Unlit
                      : args.shading == "lit" ? raster::ShadingMode::Lit
                                              : raster::ShadingMode::Material;
    options.texture_filter = args.texture_filter == "nearest" ? raster::FilterOverride::Nearest
                             : args.texture_filter == "bilinear"
                                 ? raster::FilterOverride::Bilinear
                             : args.texture_filter == "trilinear"
                                 ? raster::FilterOverride::Trilinear
                                 : raster::FilterOverride::Sampler;

    raster::TaskPool pool(args.threads);
    raster::Renderer renderer(pool);
    raster::Frame frame;
    raster::FrameStats stats;
    nlohmann::json runs = nlohmann::json::array();
    std::vector<double> totals, geometry, binning, raster_ms;
    for (uint32_t run = 0; run < args.repeat; ++run) {
        const auto start = std::chrono::steady_clock::now();
        if (Status s = renderer.render(*scene, *view, options, frame, &stats); !s.ok())
            return fail(s.message());
        const double total =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count();
        totals.push_back(total);
        geometry.push_back(stats.ms_geometry);
        binning.push_back(stats.ms_binning);
        raster_ms.push_back(stats.ms_raster);
        runs.push_back({{"total", total},
                        {"geometry", stats.ms_geometry},
                        {"binning", stats.ms_binning},
                        {"raster", stats.ms_raster}});
    }

    ImageData color{frame.width, frame.height, 4, frame.color};
    if (Status s = writeImage(args.output, color); !s.ok())
        return fail(s.message());
    if (!args.depth_out.empty()) {
        ImageData depth{frame.width, frame.height, 1, {}};
        depth.pixels.resize(size_t(frame.width) * frame.height);
        for (size_t i = 0; i < depth.pixels.size(); ++i)
            depth.pixels[i] = raster::distanceFromDepth(*view, frame.depth.load(uint32_t(i)));
        if (Status s = writeImage(args.depth_out, depth); !s.ok())
            return fail(s.message());
    }
    if (!args.stats_path.empty()) {
        const raster::View& v = *view;
        nlohmann::json j;
        j["scene"] = args.scene;
        j["output"] = args.output;
        j["method"] = args.method;
        j["width"] = args.width;
        j["height"] = args.height;
        j["threads"] = args.threads;
        j["tile"] = args.tile;
        j["depth_format"] = args.depth_format;
        j["shading"] = args.shading;
        j["texture_filter"] = args.texture_filter;
        j["repeat"] = args.repeat;
        j["camera"] = {{"eye", {v.eye.x, v.eye.y, v.eye.z}},
                       {"forward", {v.forward.x, v.forward.y, v.forward.z}},
                       {"up", {v.up.x, v.up.y, v.up.z}},
                       {"yfov_deg", v.yfov * 180.0f / kPi},
                       {"near", v.znear},
                       {"far", v.zfar},
                       {"focus_distance", v.focus_distance}};
        j["time_ms"] = {{"total", median(totals)},
                        {"geometry", median(geometry)},
                        {"binning", median(binning)},
                        {"raster", median(raster_ms)}};
        j["runs"] = runs;
        j["triangles"] = {{"in", stats.triangles_in},
                          {"culled", stats.triangles_culled},
                          {"clipped", stats.triangles_clipped},
                          {"setup", stats.triangles_setup}};
        j["fragments"] = {{"covered", stats.fragments_covered},
                          {"passed", stats.fragments_passed}};
        if (Status s = writeTextFile(args.stats_path, j.dump(2) + "\n"); !s.ok())
            return fail(s.message());
    }
    std::printf("focal: wrote %s", args.output.c_str());
    if (!args.depth_out.empty())
        std::printf(" and %s", args.depth_out.c_str());
    std::printf(" (%ux%u, %s, %.1f ms)\n", frame.width, frame.height, args.method.c_str(),
                median(totals));
    return 0;
}

}  // namespace focal
