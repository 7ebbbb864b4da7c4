#include "apps/render_command.h"

#include "apps/dof_method.h"
#include "apps/image_io.h"
#include "apps/memory_option.h"
#include "apps/scene_source.h"
#include "apps/target_dumps.h"
#include "apps/text_file.h"

#include <dof/accum.h>
#include <dof/frame_renderer.h>
#include <dof/layer_spacing.h>
#include <dof/lens.h>
#include <dof/lens_samples.h>
#include <raster/camera.h>
#include <raster/depth_precision.h>
#include <raster/renderer.h>
#include <raster/task_pool.h>

#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <thread>
#include <unistd.h>

namespace focal {

using raster::Result;
using raster::Status;

namespace {

constexpr float kPi = 3.14159265358979f;

// The version of the --stats layout (docs/stats-schema.md): bumped on any change that could break
// a reader (a removed or renamed field, a changed meaning or unit), not for new fields.
constexpr int kStatsSchemaVersion = 1;

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

Result<glm::uvec2> parsePixel(const std::string& option, const std::string& text) {
    long long x = -1, y = -1;
    char comma = 0;
    std::istringstream in(text);
    in >> x >> comma >> y;
    if (!in || comma != ',' || !(in >> std::ws).eof() || x < 0 || y < 0 || x > 1000000 ||
        y > 1000000)
        return Status::error(option + " expects a pixel X,Y (integers >= 0), got '" + text + "'");
    return glm::uvec2(uint32_t(x), uint32_t(y));
}

Status checkPositive(const char* option, const std::optional<float>& v, bool allow_zero) {
    if (v && (!std::isfinite(*v) || *v < 0.0f || (!allow_zero && *v == 0.0f)))
        return Status::error(std::string(option) + " must be a finite number " +
                             (allow_zero ? ">= 0" : "> 0") + ", got " + std::to_string(*v));
    return {};
}

// Everything the lens resolution decided, for the stats file.
struct LensChoice {
    dof::ThinLens lens;
    std::string aperture_source = "default"; // cli | fstop | scene | default
    std::string focus_source = "view";       // cli | focus-pixel | target | scene | autofocus
                                             // | bounds | view
    double ms_focus = 0.0;                   // pinhole render(s) needed to choose the focus
};

dof::LensPattern patternOf(const std::string& name) {
    return name == "halton"    ? dof::LensPattern::Halton
           : name == "poisson" ? dof::LensPattern::Poisson
                               : dof::LensPattern::Hammersley;
}

Result<dof::ApertureShape> resolveAperture(const RenderArgs& args) {
    dof::ApertureShape shape;
    std::string kind = args.aperture_shape.value_or(
        !args.aperture_image.empty() ? "image" : (args.aperture_blades ? "polygon" : "circle"));
    if (kind == "polygon") {
        shape.kind = dof::ApertureKind::Polygon;
        shape.blades = args.aperture_blades.value_or(6);
        shape.rotation_deg = args.aperture_rotation_deg;
    } else if (kind == "image") {
        if (args.aperture_image.empty())
            return Status::error("--aperture-shape image needs --aperture-image FILE");
        Result<ImageData> img = readImage(args.aperture_image);
        if (!img.ok())
            return img.status();
        // Transmission: mean of RGB (or grey) in linear light, times alpha when present.
        shape.kind = dof::ApertureKind::Image;
        shape.mask.width = img->width;
        shape.mask.height = img->height;
        const uint32_t ch = img->channels;
        shape.mask.transmission.resize(size_t(img->width) * img->height);
        for (size_t i = 0; i < shape.mask.transmission.size(); ++i) {
            const float* p = &img->pixels[i * ch];
            float t = ch >= 3 ? (p[0] + p[1] + p[2]) / 3.0f : p[0];
            if (ch == 2 || ch == 4)
                t *= p[ch - 1];
            shape.mask.transmission[i] = std::max(t, 0.0f);
        }
    } else if (kind != "circle") {
        return Status::error("unknown --aperture-shape " + kind);
    }
    if (kind != "polygon" && args.aperture_blades)
        return Status::error("--aperture-blades needs --aperture-shape polygon");
    if (kind != "image" && !args.aperture_image.empty())
        return Status::error("--aperture-image needs --aperture-shape image");
    return shape;
}

const char* apertureKindName(dof::ApertureKind k) {
    return k == dof::ApertureKind::Polygon ? "polygon"
           : k == dof::ApertureKind::Image ? "image"
                                           : "circle";
}

// Progress bar on stderr, only when stderr is a terminal.
class ProgressBar {
public:
    explicit ProgressBar(bool enabled) : enabled_(enabled) {}
    void update(uint32_t done, uint32_t total) {
        if (!enabled_ || total == 0)
            return;
        const uint32_t permille = uint32_t(uint64_t(done) * 1000 / total);
        if (permille == last_ && done != total)
            return;
        last_ = permille;
        constexpr int kBar = 40;
        const int filled = int(uint64_t(done) * kBar / total);
        std::fprintf(stderr, "\rfocal: accum [%.*s%.*s] %u/%u views", filled,
                     "########################################", kBar - filled,
                     "........................................", done, total);
        if (done == total)
            std::fputc('\n', stderr);
        std::fflush(stderr);
    }

private:
    bool enabled_;
    uint32_t last_ = ~0u;
};

// No silent wrong image: warns, with the numbers, when a depth format cannot hold the distances
// the scene spans in front of the view (docs/targets.md, "Depth precision"). `targets`: the
// storage of the layered target / fragment lists when the user chose one.
void warnDepthPrecision(const raster::Scene& scene, const raster::View& view,
                        raster::DepthFormat frame_format,
                        std::optional<raster::DepthFormat> targets, bool table_method) {
    const raster::Bounds b = raster::worldBounds(scene);
    if (b.empty)
        return;
    float near_d = INFINITY, far_d = -INFINITY;
    for (int corner = 0; corner < 8; ++corner) {
        const glm::vec3 p((corner & 1) ? b.max.x : b.min.x, (corner & 2) ? b.max.y : b.min.y,
                          (corner & 4) ? b.max.z : b.min.z);
        const float d = glm::dot(p - view.eye, view.forward);
        near_d = std::min(near_d, d);
        far_d = std::max(far_d, d);
    }
    near_d = std::max(near_d, view.znear);
    if (view.zfar > 0.0f)
        far_d = std::min(far_d, view.zfar);
    auto warn = [&](raster::DepthFormat format, const char* target) {
        if (std::optional<std::string> problem =
                raster::depthPrecisionProblem(view, format, near_d, far_d, target))
            std::fprintf(stderr, "focal: warning: %s\n", problem->c_str());
    };
    warn(frame_format, "depth");
    if (table_method && targets && *targets != frame_format)
        warn(*targets, "target depth");
}

// Focus on the centre of the scene's bounds, when it lies in front of the view.
std::optional<float> boundsFocusDistance(const raster::Scene& scene, const raster::View& view) {
    const raster::Bounds b = raster::worldBounds(scene);
    const float along = glm::dot(0.5f * (b.min + b.max) - view.eye, view.forward);
    if (b.empty || !(along > 0.0f))
        return std::nullopt;
    return along;
}

// "--method multiview at 16384x16384 with 65536 samples": the request, in messages.
std::string requestText(const RenderArgs& args, const raster::View& view) {
    std::string text = "--method " + args.method + " at " + std::to_string(view.width) + "x" +
                       std::to_string(view.height);
    if (args.method != "pinhole")
        text += " with " + std::to_string(args.samples) + " samples";
    return text;
}

// The memory a render request needs at least, before anything is rendered: the pinhole frame
// (autofocus and the lens centre), accum's second frame and its double-precision sum, and what a
// table method declares (MethodEntry::minimum_bytes).
uint64_t requestMinimumBytes(const RenderArgs& args, const raster::View& view,
                             const raster::RenderOptions& options, const MethodEntry* table_method,
                             uint32_t workers) {
    const uint32_t w = view.width, h = view.height;
    uint64_t bytes = raster::frameBytes(w, h, options.depth_format, false);
    if (args.method == "accum")
        bytes = raster::addBytes(
            bytes, raster::addBytes(raster::frameBytes(w, h, options.depth_format, false),
                                    raster::mulBytes(uint64_t{w} * h, 4 * sizeof(double))));
    if (table_method && table_method->minimum_bytes)
        bytes = raster::addBytes(bytes, table_method->minimum_bytes(view, args.samples, workers));
    return bytes;
}

} // namespace

CLI::App* addRenderCommand(CLI::App& app, RenderArgs& args) {
    CLI::App* cmd = app.add_subcommand("render", "Render a scene to an image");
    args.threads = std::max(1u, std::thread::hardware_concurrency());
    cmd->add_option("scene", args.scene, "glTF file (.gltf/.glb) or builtin:NAME")->required();
    cmd->add_option("-o,--output", args.outputs,
                    "output image: .exr (linear float RGBA) or .png "
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
    cmd->add_option("--yfov", args.yfov_deg,
                    "vertical field of view in degrees [default: the "
                    "camera's, or 45]")
        ->check(CLI::Range(0.01f, 177.0f));
    cmd->add_option("--near", args.znear, "near clip distance (world units)");
    cmd->add_option("--far", args.zfar, "far clip distance (world units; 0 = infinite)");
    cmd->add_option("--threads", args.threads, "worker threads (0 = run inline on the caller)")
        ->capture_default_str()
        ->check(CLI::Range(0, 256));
    cmd->add_option("--memory-budget", args.memory_budget,
                    "the most memory one render may use: auto (half of physical memory), a "
                    "size (8G, 512MiB) or a percentage of physical memory (25%)")
        ->capture_default_str()
        ->check(CLI::Validator(
            [](const std::string& text) {
                const Result<raster::MemoryBudget> r = parseMemoryBudget(text);
                return r.ok() ? std::string() : r.status().message();
            },
            "SIZE"));
    cmd->add_flag("--dry-run", args.dry_run,
                  "check the options, scene, view, lens and memory budget, print the request "
                  "and stop: nothing is rendered or written (autofocus falls back to the scene "
                  "bounds)");
    cmd->add_option("--tile", args.tile, "tile size in pixels (multiple of 8, 8 to 256)")
        ->capture_default_str()
        ->check(CLI::Range(8, 256))
        ->check(CLI::Validator(
            [](const std::string& text) {
                const int v = std::atoi(text.c_str());
                return v % 8 == 0 ? std::string() : text + " is not a multiple of 8";
            },
            "MULTIPLE OF 8"));
    cmd->add_option("--method", args.method, "depth-of-field method")
        ->capture_default_str()
        ->check(CLI::IsMember(methodNames()));
    cmd->add_option("--stats", args.stats_path,
                    "write every parameter, stage times (ms) and "
                    "counts to this JSON file");
    cmd->add_option("--repeat", args.repeat, "render K times; stats keep every run and the median")
        ->capture_default_str()
        ->check(CLI::Range(1, 100000));
    cmd->add_option("--depth-out", args.depth_out,
                    "also write linear depth (distance along the "
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

    // The lens (docs/dof/lens.md). Value checks (NaN, negative, focus beyond the far plane)
    // happen in runRender so they print a sentence, not a validator message.
    CLI::Option* aperture = cmd->add_option(
        "--aperture-radius", args.aperture_radius,
        "lens radius E in world units (0 = pinhole) [default: the scene's lens, else 0]");
    CLI::Option* fstop = cmd->add_option(
        "--fstop", args.fstop, "f-number N; with --focal-length: E = focal_length/(2 N) in metres");
    CLI::Option* focal = cmd->add_option(
        "--focal-length", args.focal_length_mm,
        "lens focal length in mm; also sets yfov = 2 atan(sensor/2 / focal) (Blender)");
    CLI::Option* sensor = cmd->add_option("--sensor-height", args.sensor_height_mm,
                                          "sensor height in mm, vertical fit [default: 24]");
    CLI::Option* focus_d = cmd->add_option(
        "--focus-distance", args.focus_distance,
        "focus distance d_f along the view axis (world units) [default: see docs/dof/lens.md]");
    CLI::Option* focus_p =
        cmd->add_option("--focus-pixel", args.focus_pixel,
                        "focus on the depth a pinhole render shows at pixel X,Y");
    fstop->needs(focal);
    sensor->needs(focal);
    aperture->excludes(fstop);
    focus_d->excludes(focus_p);
    cmd->get_option("--yfov")->excludes(focal);
    cmd->add_option("--samples", args.samples, "accum: lens samples (views) N")
        ->capture_default_str()
        ->check(CLI::Range(1, 1 << 20));
    cmd->add_flag("--pixel-jitter", args.pixel_jitter,
                  "accum: also jitter the sub-pixel position per view (box-filter anti-aliasing)");
    cmd->add_option("--lens-pattern", args.lens_pattern, "lens sample pattern")
        ->capture_default_str()
        ->check(CLI::IsMember({"halton", "hammersley", "poisson"}));
    cmd->add_option("--aperture-shape", args.aperture_shape,
                    "circle, polygon (--aperture-blades) or image (--aperture-image) "
                    "[default: circle]")
        ->check(CLI::IsMember({"circle", "polygon", "image"}));
    cmd->add_option("--aperture-blades", args.aperture_blades,
                    "polygon aperture: number of blades (3-64) [default: 6]")
        ->check(CLI::Range(3, 64));
    cmd->add_option("--aperture-rotation", args.aperture_rotation_deg,
                    "polygon aperture: rotation in degrees, counter-clockwise (0: a vertex up)")
        ->capture_default_str();
    cmd->add_option("--aperture-image", args.aperture_image,
                    "aperture image (bokeh mask): transmission = mean RGB x alpha, top row = up");
    cmd->add_option("--seed", args.seed,
                    "lens pattern seed (0: the unrotated pattern; otherwise a Cranley-Patterson "
                    "rotation and, for poisson, other candidates)")
        ->capture_default_str();
    cmd->add_flag("--no-progress", args.no_progress, "accum: no progress bar on stderr");
    cmd->add_flag("--no-simd", args.no_simd,
                  "run the scalar reference kernels instead of the SIMD ones (same bits)");
    cmd->add_option("--dump-layers", args.dump_layers,
                    "write a layered decomposition (colour, depth per layer) into this folder");
    cmd->add_option("--dump-layer-count", args.dump_layer_count,
                    "layers for --dump-layers, uniform in 1/d over the visible depths")
        ->capture_default_str()
        ->check(CLI::Range(1, 64));
    cmd->add_option("--dump-fragments", args.dump_fragments,
                    "write per-pixel fragment-list counts and the first K fragment layers into "
                    "this folder");
    cmd->add_option("--dump-fragment-layers", args.dump_fragment_layers, "K for --dump-fragments")
        ->capture_default_str()
        ->check(CLI::Range(0, 64));
    cmd->add_option("--precision", args.precision,
                    "layered targets / fragment lists: 16 (half colour, unorm16 depth) or 32 "
                    "(float) [default: the method's]")
        ->check(CLI::IsMember({16, 32}));
    cmd->add_option("--target-color", args.target_color,
                    "layered targets / fragment lists: colour storage")
        ->check(CLI::IsMember({"half", "float32"}));
    cmd->add_option("--target-depth", args.target_depth,
                    "layered targets / fragment lists: depth storage")
        ->check(CLI::IsMember({"unorm16", "float32"}));
    // Each method in apps/methods.cpp adds its own options.
    for (MethodEntry& m : methodTable())
        if (m.add_options)
            m.add_options(*cmd);
    return cmd;
}

int runRender(const RenderArgs& args) {
    if (args.tile % 8 != 0)
        return fail("--tile " + std::to_string(args.tile) + " must be a multiple of 8");
    if (!args.depth_out.empty() && !isLinearFormat(args.depth_out))
        return fail(args.depth_out + ": --depth-out must be an .exr file");
    // Lens values the parser cannot judge (NaN, negative, zero).
    for (const Status& s : {checkPositive("--aperture-radius", args.aperture_radius, true),
                            checkPositive("--fstop", args.fstop, false),
                            checkPositive("--focal-length", args.focal_length_mm, false),
                            checkPositive("--sensor-height", args.sensor_height_mm, false),
                            checkPositive("--focus-distance", args.focus_distance, false)})
        if (!s.ok())
            return fail(s.message());
    if (!std::isfinite(args.aperture_rotation_deg))
        return fail("--aperture-rotation must be a finite angle in degrees");
    const bool is_accum = args.method == "accum";
    const MethodEntry* table_method = findMethod(args.method);
    const bool uses_lens = args.method != "pinhole";
    const bool lens_options = args.aperture_radius || args.fstop || args.focus_distance ||
                              args.focus_pixel || args.aperture_shape || args.aperture_blades ||
                              !args.aperture_image.empty() || args.pixel_jitter;
    if (!uses_lens && lens_options)
        std::fprintf(stderr, "focal: warning: lens options have no effect with --method %s\n",
                     args.method.c_str());
    Result<glm::uvec2> focus_pixel = glm::uvec2(0);
    if (args.focus_pixel) {
        focus_pixel = parsePixel("--focus-pixel", *args.focus_pixel);
        if (!focus_pixel.ok())
            return fail(focus_pixel.status().message());
    }
    Result<dof::ApertureShape> aperture_shape = resolveAperture(args);
    if (!aperture_shape.ok())
        return fail(aperture_shape.status().message());

    raster::RenderOptions options;
    options.tile_size = args.tile;
    options.depth_format = args.depth_format == "unorm16" ? raster::DepthFormat::Unorm16
                                                          : raster::DepthFormat::Float32;
    options.shading = args.shading == "unlit" ? raster::ShadingMode::Unlit
                      : args.shading == "lit" ? raster::ShadingMode::Lit
                                              : raster::ShadingMode::Material;
    options.texture_filter = args.texture_filter == "nearest"    ? raster::FilterOverride::Nearest
                             : args.texture_filter == "bilinear" ? raster::FilterOverride::Bilinear
                             : args.texture_filter == "trilinear"
                                 ? raster::FilterOverride::Trilinear
                                 : raster::FilterOverride::Sampler;
    options.simd = !args.no_simd;
    options.memory_budget = parseMemoryBudget(args.memory_budget).value(); // checked by CLI11

    raster::TaskPool pool(args.threads);

    // Decode only the textures this shading samples, in parallel on the render's pool.
    raster::ImportOptions import_options;
    import_options.roles = raster::sampledTextureRoles(options.shading);
    import_options.pool = &pool;
    import_options.memory_budget = options.memory_budget;
    raster::ImportStats load_stats;
    Result<raster::Scene> scene = loadScene(args.scene, import_options, &load_stats);
    if (!scene.ok())
        return fail(scene.status().message());
    for (const std::string& w : scene->warnings)
        std::fprintf(stderr, "focal: warning: %s\n", w.c_str());
    Result<raster::View> view = resolveView(*scene, args);
    if (!view.ok())
        return fail(view.status().message());
    // A focal length implies the field of view (Blender, vertical sensor fit).
    const float sensor_mm = args.sensor_height_mm.value_or(24.0f);
    if (args.focal_length_mm)
        view->yfov = dof::yfovFromFocalLength(*args.focal_length_mm, sensor_mm);
    if (Status s = raster::validate(*view); !s.ok())
        return fail(s.message());
    // Target storage for the table's methods.
    std::optional<raster::ColorFormat> target_color;
    std::optional<raster::DepthFormat> target_depth;
    if (args.precision) {
        target_color =
            *args.precision == 16 ? raster::ColorFormat::Half : raster::ColorFormat::Float32;
        target_depth =
            *args.precision == 16 ? raster::DepthFormat::Unorm16 : raster::DepthFormat::Float32;
    }
    if (args.target_color)
        target_color =
            *args.target_color == "half" ? raster::ColorFormat::Half : raster::ColorFormat::Float32;
    if (args.target_depth)
        target_depth = *args.target_depth == "unorm16" ? raster::DepthFormat::Unorm16
                                                       : raster::DepthFormat::Float32;
    warnDepthPrecision(*scene, *view, options.depth_format, target_depth, table_method != nullptr);
    // Absurd requests fail here, in milliseconds, before any rendering.
    const uint64_t request_bytes =
        requestMinimumBytes(args, *view, options, table_method, pool.workerCount());
    if (Status s =
            raster::checkMemory(options.memory_budget, requestText(args, *view), request_bytes);
        !s.ok())
        return fail(s.message());

    // Every frame of this command (autofocus, each --repeat run, the dumps) is rendered by one
    // FrameRenderer: it keeps the renderer, the methods' buffers and the pinhole frame.
    dof::FrameRenderer frames(pool);
    // Counts of the last renderer call (--stats "triangles", "fragments").
    raster::FrameStats stats;

    // Resolve the lens: aperture, then focus distance (docs/dof/lens.md, "Defaults").
    LensChoice choice;
    float aperture_radius = 0.0f;
    if (args.aperture_radius) {
        aperture_radius = *args.aperture_radius;
        choice.aperture_source = "cli";
    } else if (args.fstop) {
        aperture_radius = dof::apertureRadiusFromFStop(*args.focal_length_mm, *args.fstop);
        choice.aperture_source = "fstop";
    } else if (scene->lens) {
        aperture_radius = scene->lens->aperture_radius;
        choice.aperture_source = "scene";
    }
    float focus_distance = view->focus_distance;
    const bool look_at = args.eye.has_value();
    if (args.focus_distance) {
        focus_distance = *args.focus_distance;
        choice.focus_source = "cli";
    } else if (!args.dry_run && (args.focus_pixel || (uses_lens && !look_at && !scene->lens))) {
        // Render the pinhole (independent of the lens) and read its depth; the frame renderer
        // keeps it for the first frame, whose methods read the same pinhole.
        const auto t0 = std::chrono::steady_clock::now();
        Result<const raster::Frame*> pinhole = frames.pinhole(*scene, *view, options, &stats);
        if (!pinhole.ok())
            return fail(pinhole.status().message());
        const raster::Frame& frame = **pinhole;
        choice.ms_focus =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                .count();
        if (args.focus_pixel) {
            Result<float> d =
                dof::focusDistanceAtPixel(frame, *view, focus_pixel->x, focus_pixel->y);
            if (!d.ok())
                return fail(d.status().message());
            focus_distance = *d;
            choice.focus_source = "focus-pixel";
        } else if (Result<float> d =
                       dof::focusDistanceAtPixel(frame, *view, view->width / 2, view->height / 2);
                   d.ok()) {
            focus_distance = *d;
            choice.focus_source = "autofocus";
        } else if (const std::optional<float> bounds_d = boundsFocusDistance(*scene, *view)) {
            focus_distance = *bounds_d;
            choice.focus_source = "bounds";
        }
    } else if (args.dry_run && (args.focus_pixel || (uses_lens && !look_at && !scene->lens))) {
        // Autofocus reads a pinhole render, which a dry run does not make.
        if (const std::optional<float> d = boundsFocusDistance(*scene, *view)) {
            focus_distance = *d;
            choice.focus_source = "bounds";
        }
    } else if (look_at) {
        choice.focus_source = "target";
    } else if (scene->lens) {
        focus_distance = scene->lens->focus_distance;
        choice.focus_source = "scene";
    }
    choice.lens = dof::makeThinLens(*view, aperture_radius, focus_distance);
    if (uses_lens || lens_options)
        if (Status s = dof::validate(choice.lens, *view); !s.ok())
            return fail(s.message());
    view->focus_distance = focus_distance;

    Result<dof::LensSampleSet> lens_samples = dof::LensSampleSet::create(
        *aperture_shape, patternOf(args.lens_pattern), uses_lens ? args.samples : 1, args.seed);
    if (!lens_samples.ok())
        return fail(lens_samples.status().message());
    if (args.dry_run) {
        std::printf("focal: dry run: %s, aperture radius %g, focus distance %g (%s), needs at "
                    "least %s of a %s memory budget\n",
                    requestText(args, *view).c_str(), double(choice.lens.aperture_radius),
                    double(focus_distance), choice.focus_source.c_str(),
                    raster::formatBytes(request_bytes).c_str(),
                    options.memory_budget.limited()
                        ? raster::formatBytes(options.memory_budget.bytes).c_str()
                        : "unlimited");
        return 0;
    }

    const MethodContext method_context{*view, *lens_samples, options, target_color, target_depth};
    MethodOutput method_out;
    std::vector<std::pair<std::string, std::vector<double>>> method_stage_ms;
    // The image every run writes (linear RGBA) and the depth --depth-out asks for.
    const size_t pixels = size_t(view->width) * view->height;
    std::vector<float> color(pixels * 4);
    std::vector<float> depth_image(args.depth_out.empty() ? 0 : pixels);
    dof::FrameImage image;
    image.rgba = color.data();
    image.stride = size_t(view->width) * 4;
    image.depth = depth_image.empty() ? nullptr : depth_image.data();
    image.depth_stride = view->width;

    nlohmann::json runs = nlohmann::json::array();
    std::vector<double> totals, geometry, binning, raster_ms;
    dof::AccumStats accum_stats;
    dof::FrameReport report;
    const bool show_progress =
        is_accum && !args.no_progress && args.samples > 1 && ::isatty(::fileno(stderr)) == 1;
    for (uint32_t run = 0; run < args.repeat; ++run) {
        const auto start = std::chrono::steady_clock::now();
        ProgressBar bar(show_progress);
        dof::MethodSettings method;
        if (is_accum) {
            dof::AccumMethod accum;
            accum.settings.pixel_jitter = args.pixel_jitter;
            accum.samples = &*lens_samples;
            accum.progress = [&bar](uint32_t done, uint32_t total) { bar.update(done, total); };
            method = std::move(accum);
        } else if (table_method) {
            Result<dof::MethodSettings> m = table_method->settings(method_context);
            if (!m.ok())
                return fail(m.status().message());
            method = std::move(*m);
        }
        if (Status s = frames.render(*scene, *view, choice.lens, options, method, image, &report);
            !s.ok())
            return fail(s.message());
        if (table_method) {
            method_out = MethodOutput{};
            if (Status s =
                    table_method->finish(method_context, method, frames, report, color, method_out);
                !s.ok())
                return fail(s.message());
        }
        const double total =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count();
        // Renderer stage times of pinhole and accum (the table methods report their own stages).
        raster::FrameStats run_sum;
        if (!table_method) {
            run_sum = report.render_sum;
            if (report.renders > 0)
                stats = report.last_render;
        }
        if (is_accum)
            accum_stats = std::get<dof::AccumStats>(report.method_stats);
        totals.push_back(total);
        geometry.push_back(run_sum.ms_geometry);
        binning.push_back(run_sum.ms_binning);
        raster_ms.push_back(run_sum.ms_raster);
        nlohmann::json one = {{"total", total},
                              {"geometry", run_sum.ms_geometry},
                              {"binning", run_sum.ms_binning},
                              {"raster", run_sum.ms_raster}};
        for (size_t k = 0; k < report.stage_ms.size(); ++k) {
            const auto& [stage, ms] = report.stage_ms[k];
            one[stage] = ms;
            if (method_stage_ms.size() <= k)
                method_stage_ms.push_back({stage, {}});
            method_stage_ms[k].second.push_back(ms);
        }
        runs.push_back(one);
    }
    if (is_accum && accum_stats.skipped)
        std::fprintf(stderr, "focal: note: accum rendered once: %s\n",
                     accum_stats.skip_reason.c_str());

    ImageData color_out{view->width, view->height, 4, std::move(color)};
    for (const std::string& output : args.outputs)
        if (Status s = writeImage(output, color_out); !s.ok())
            return fail(s.message());
    if (!args.depth_out.empty()) {
        // The method's depth (dof::FrameImage::depth): the pinhole's for pinhole, accum and
        // gather.
        ImageData depth{view->width, view->height, 1, std::move(depth_image)};
        if (Status s = writeImage(args.depth_out, depth); !s.ok())
            return fail(s.message());
    }
    // Look inside the GPU-emulating targets (docs/targets.md): layers over the visible depth
    // range, uniform in 1/d, with the paper's routing; fragment lists with the closest K kept.
    nlohmann::json target_stats;
    if (!args.dump_layers.empty() || !args.dump_fragments.empty()) {
        // The last frame's pinhole when it is this view's, else a new render.
        raster::Frame rendered;
        const raster::Frame* kept = frames.lastPinhole(*scene, *view, options);
        if (!kept) {
            if (Status s = frames.renderer().render(*scene, *view, options, rendered); !s.ok())
                return fail(s.message());
            kept = &rendered;
        }
        const raster::Frame& pinhole = *kept;
        raster::Renderer& renderer = frames.renderer();
        if (!args.dump_layers.empty()) {
            const dof::DepthRange range = dof::visibleDepthRange(pinhole, *view);
            if (!range.covered)
                return fail(args.scene + ": nothing visible to decompose into layers");
            raster::LayeredTargetDesc desc;
            desc.bounds = uniformInverseDepthBounds(
                range.near_d, std::max(range.far_d, range.near_d * 1.001f), args.dump_layer_count);
            desc.color_format = target_color.value_or(raster::ColorFormat::Float32);
            desc.depth_format = target_depth.value_or(raster::DepthFormat::Float32);
            raster::LayeredTarget layers;
            raster::FrameStats ts;
            if (Status s = renderer.renderLayers(*scene, *view, options, desc, layers, &ts);
                !s.ok())
                return fail(s.message());
            if (Status s = dumpLayers(layers, *view, args.dump_layers); !s.ok())
                return fail(s.message());
            target_stats["layers"] = {
                {"count", layers.layer_count},
                {"bounds", desc.bounds},
                {"bytes", ts.target_bytes},
                {"time_ms", {{"raster", ts.ms_raster}, {"copy", ts.ms_resolve}}}};
        }
        if (!args.dump_fragments.empty()) {
            raster::FragmentListDesc desc;
            desc.max_per_pixel = std::max(desc.max_per_pixel, args.dump_fragment_layers);
            desc.early_reject = false; // look inside: every fragment, the full list lengths
            desc.color_format = target_color.value_or(desc.color_format);
            desc.depth_format = target_depth.value_or(desc.depth_format);
            raster::FragmentLists lists;
            raster::FrameStats ts;
            if (Status s = renderer.renderFragmentLists(*scene, *view, options, desc, lists, &ts);
                !s.ok())
                return fail(s.message());
            if (Status s =
                    dumpFragments(lists, *view, args.dump_fragments, args.dump_fragment_layers);
                !s.ok())
                return fail(s.message());
            target_stats["fragment_lists"] = {
                {"collected", lists.fragments_collected},
                {"kept", lists.fragments_kept},
                {"max_list_length", lists.max_list_length},
                {"bytes", ts.target_bytes},
                {"time_ms", {{"collect", ts.ms_raster}, {"resolve", ts.ms_resolve}}}};
        }
    }
    if (!args.stats_path.empty()) {
        const raster::View& v = *view;
        nlohmann::json j;
        j["schema"] = "focal.render-stats";
        j["schema_version"] = kStatsSchemaVersion;
        j["scene"] = args.scene;
        j["output"] = args.outputs.front();
        j["outputs"] = args.outputs;
        j["simd"] = !args.no_simd;
        if (!target_stats.is_null())
            j["targets"] = target_stats;
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
        const dof::ThinLens& lens = choice.lens;
        nlohmann::json lj = {{"aperture_radius", lens.aperture_radius},
                             {"aperture_source", choice.aperture_source},
                             {"focus_distance", lens.focus_distance},
                             {"focus_source", choice.focus_source},
                             {"focal_length_px", lens.focal_length_px},
                             {"coc_at_infinity_px", dof::cocRadiusPx(lens, INFINITY)},
                             {"aperture_shape", apertureKindName(aperture_shape->kind)},
                             {"lens_pattern", args.lens_pattern},
                             {"seed", args.seed}};
        if (args.fstop)
            lj["fstop"] = *args.fstop;
        if (args.focal_length_mm) {
            lj["focal_length_mm"] = *args.focal_length_mm;
            lj["sensor_height_mm"] = sensor_mm;
        }
        if (args.focus_pixel)
            lj["focus_pixel"] = {focus_pixel->x, focus_pixel->y};
        if (aperture_shape->kind == dof::ApertureKind::Polygon) {
            lj["aperture_blades"] = aperture_shape->blades;
            lj["aperture_rotation_deg"] = aperture_shape->rotation_deg;
        }
        if (aperture_shape->kind == dof::ApertureKind::Image)
            lj["aperture_image"] = args.aperture_image;
        j["lens"] = lj;
        j["time_ms"] = {{"total", median(totals)},
                        {"geometry", median(geometry)},
                        {"binning", median(binning)},
                        {"raster", median(raster_ms)}};
        if (choice.ms_focus > 0.0)
            j["time_ms"]["focus"] = choice.ms_focus;
        // Scene loading, once per process (not part of time_ms, which is per render).
        j["load"] = {{"time_ms",
                      {{"total", load_stats.ms_total},
                       {"parse", load_stats.ms_parse},
                       {"images", load_stats.ms_images},
                       {"decode", load_stats.ms_decode},
                       {"mipmaps", load_stats.ms_mipmaps},
                       {"scene", load_stats.ms_scene}}},
                     {"images_decoded", load_stats.images_decoded},
                     {"images_skipped", load_stats.images_skipped}};
        if (is_accum) {
            nlohmann::json aj = {{"samples", args.samples},
                                 {"pixel_jitter", args.pixel_jitter},
                                 {"views", accum_stats.views},
                                 {"renders", accum_stats.renders},
                                 {"skipped", accum_stats.skipped}};
            if (accum_stats.skipped)
                aj["skip_reason"] = accum_stats.skip_reason;
            if (accum_stats.coc.covered)
                aj["visible_coc_px"] = {{"min", accum_stats.coc.min_px},
                                        {"max", accum_stats.coc.max_px},
                                        {"max_abs", accum_stats.coc.max_abs_px}};
            j["accum"] = aj;
        }
        for (const auto& [stage, ms] : method_stage_ms)
            j["time_ms"][stage] = median(ms);
        if (table_method) {
            j["params"] = method_out.params;
            j["counts"] = method_out.counts;
            // Tracing cost per lens ray and per (ray, layer) step, from the median time.
            const nlohmann::json& c = method_out.counts;
            const std::pair<const char*, const char*> units[] = {{"rays", "per_ray"},
                                                                 {"layer_steps", "per_layer_step"}};
            if (j["time_ms"].contains("tracing"))
                for (const auto& [count, name] : units)
                    if (c.contains(count) && c[count].get<uint64_t>() > 0)
                        j["tracing_ns"][name] = j["time_ms"]["tracing"].get<double>() * 1e6 /
                                                double(c[count].get<uint64_t>());
            j["lens"]["samples"] = args.samples;
            if (target_color)
                j["target_color"] = *target_color == raster::ColorFormat::Half ? "half" : "float32";
            if (target_depth)
                j["target_depth"] =
                    *target_depth == raster::DepthFormat::Unorm16 ? "unorm16" : "float32";
        }
        j["runs"] = runs;
        j["triangles"] = {{"in", stats.triangles_in},
                          {"culled", stats.triangles_culled},
                          {"clipped", stats.triangles_clipped},
                          {"setup", stats.triangles_setup}};
        j["fragments"] = {{"covered", stats.fragments_covered}, {"passed", stats.fragments_passed}};
        if (Status s = writeTextFile(args.stats_path, j.dump(2) + "\n"); !s.ok())
            return fail(s.message());
    }
    std::printf("focal: wrote %s", args.outputs.front().c_str());
    for (size_t i = 1; i < args.outputs.size(); ++i)
        std::printf(", %s", args.outputs[i].c_str());
    if (!args.depth_out.empty())
        std::printf(" and %s", args.depth_out.c_str());
    if (is_accum)
        std::printf(" (%ux%u, accum %u views, %.1f ms)\n", view->width, view->height,
                    accum_stats.views, median(totals));
    else
        std::printf(" (%ux%u, %s, %.1f ms)\n", view->width, view->height, args.method.c_str(),
                    median(totals));
    return 0;
}

} // namespace focal
