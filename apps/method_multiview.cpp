#include "apps/method_multiview.h"

#include "apps/image_io.h"

#include <dof/multiview.h>
#include <raster/renderer.h>

#include <memory>
#include <string>

namespace focal {

namespace {

struct MultiviewArgs {
    float layer_spacing = 2.0f;
    uint32_t layers = 0;
    float overlap = 0.1f;
    uint32_t iterations = 3;
    uint32_t refine_steps = 4;
    std::string cone = "on";
    std::string culling = "on";
    std::string jitter = "noise";
    std::string routing = "max-vertex";
    std::string offscreen = "discard";
    bool view_dependent = false;
    std::string env_map;
    float env_intensity = 1.0f;
};

const char* jitterName(dof::JitterMode j) {
    switch (j) {
    case dof::JitterMode::None:
        return "none";
    case dof::JitterMode::Noise:
        return "noise";
    case dof::JitterMode::Halton:
        return "halton";
    case dof::JitterMode::Rotate:
        return "rotate";
    }
    return "?";
}

raster::Status runMultiview(const MultiviewArgs& a, const MethodInput& in, MethodOutput& out) {
    dof::MultiviewSettings s;
    s.layer_spacing_px = a.layer_spacing;
    s.layers = a.layers;
    s.overlap = a.overlap;
    s.iterations = a.iterations;
    s.refine_steps = a.refine_steps;
    s.cone = a.cone == "on";
    s.culling = a.culling == "on";
    s.jitter = a.jitter == "none"     ? dof::JitterMode::None
               : a.jitter == "halton" ? dof::JitterMode::Halton
               : a.jitter == "rotate" ? dof::JitterMode::Rotate
                                      : dof::JitterMode::Noise;
    s.routing = a.routing == "per-fragment" ? raster::LayerRouting::PerFragment
                                            : raster::LayerRouting::MaxVertexDepth;
    s.offscreen =
        a.offscreen == "clamp" ? dof::OffscreenPolicy::Clamp : dof::OffscreenPolicy::Discard;
    s.view_dependent = a.view_dependent;
    s.seed = in.lens_samples.seed();
    s.color_format = in.target_color.value_or(raster::ColorFormat::Half);
    s.depth_format = in.target_depth.value_or(raster::DepthFormat::Float32);

    dof::EnvironmentMap env;
    if (!a.env_map.empty()) {
        raster::Result<ImageData> img = readImage(a.env_map);
        if (!img.ok())
            return raster::Status::error("--env-map: " + img.status().message());
        env.width = img->width;
        env.height = img->height;
        env.intensity = a.env_intensity;
        env.rgb.resize(size_t(env.width) * env.height * 3);
        for (size_t i = 0; i < size_t(env.width) * env.height; ++i)
            for (uint32_t c = 0; c < 3; ++c)
                env.rgb[i * 3 + c] =
                    img->pixels[i * img->channels + std::min(c, img->channels - 1)];
        s.env_map = &env;
    }
    // §4.5's 2N-sample sequence: the same pattern and seed, twice as many samples.
    // TODO(multiview): MethodInput does not carry the aperture shape, so the sequence uses the
    // circle; polygon/image apertures with --jitter halton need it passed through. #7
    std::optional<dof::LensSampleSet> seq;
    if (s.jitter == dof::JitterMode::Halton) {
        raster::Result<dof::LensSampleSet> r =
            dof::LensSampleSet::create(dof::ApertureShape{}, dof::LensPattern::Halton,
                                       2 * in.lens_samples.size(), in.lens_samples.seed());
        if (!r.ok())
            return r.status();
        seq = std::move(*r);
        s.sequence_2n = &*seq;
    }

    raster::Renderer renderer(in.pool);
    raster::Frame pinhole;
    raster::LayeredTarget layers;
    const dof::PinholeFn pin = [&](const raster::View& v, raster::Frame& f) {
        return renderer.render(in.scene, v, in.options, f);
    };
    const dof::LayersFn lay = [&](const raster::View& v, const raster::LayeredTargetDesc& d,
                                  raster::LayeredTarget& t) {
        return renderer.renderLayers(in.scene, v, in.options, d, t);
    };
    dof::ShadingInputs shading;
    shading.scene = &in.scene;
    raster::Result<dof::MultiviewStats> r =
        dof::renderMultiview(in.view, in.lens, in.lens_samples, s, shading, in.scene.background,
                             pin, lay, in.pool, out.rgba, &pinhole, &layers);
    if (!r.ok())
        return r.status();
    const dof::MultiviewStats& st = *r;
    out.depth.resize(size_t(pinhole.width) * pinhole.height);
    for (size_t i = 0; i < out.depth.size(); ++i) {
        const float d = pinhole.depth.load(i);
        out.depth[i] = d < 1.0f ? raster::distanceFromDepth(in.view, d) : INFINITY;
    }
    out.params = {
        {"samples", in.lens_samples.size()},
        {"layer_spacing_px", st.delta_px},
        {"layer_spacing_requested_px", a.layer_spacing},
        {"layers_requested", a.layers},
        {"overlap", a.overlap},
        {"iterations", a.iterations},
        {"refine_steps", a.refine_steps},
        {"cone", s.cone},
        {"culling", s.culling},
        {"jitter", jitterName(s.jitter)},
        {"routing", a.routing},
        {"offscreen", a.offscreen},
        {"view_dependent", s.view_dependent},
        {"env_map", a.env_map},
        {"env_intensity", a.env_intensity},
        {"layer_color", s.color_format == raster::ColorFormat::Half ? "half" : "float32"},
        {"layer_depth", s.depth_format == raster::DepthFormat::Unorm16 ? "unorm16" : "float32"}};
    out.counts = {{"layers", st.layers},
                  {"layers_empty", st.layers_empty},
                  {"budget_limited", st.budget_limited},
                  {"d_near", st.d_near},
                  {"d_far", st.d_far},
                  {"lambda", st.lambda},
                  {"nbuffer_levels", st.nbuffer_levels},
                  {"mip_levels", st.mip_levels},
                  {"rays", st.rays},
                  {"rays_discarded", st.rays_discarded},
                  {"rays_background", st.rays_background},
                  {"layer_tests", st.layer_tests},
                  {"layers_culled_pixel", st.layer_culled_pixel},
                  {"layers_culled_tile", st.layer_culled_tile},
                  {"layers_culled_ray", st.layer_culled_ray},
                  {"cone_partial", st.cone_partial},
                  {"texel_fetches", st.texel_fetches},
                  {"layered_bytes", st.layered_bytes},
                  {"scratch_bytes", st.scratch_bytes}};
    out.stage_ms = {{"pinhole", st.ms_pinhole},
                    {"decomposition", st.ms_decomposition},
                    {"nbuffer", st.ms_nbuffer},
                    {"mipmaps", st.ms_mipmaps},
                    {"tracing", st.ms_tracing}};
    return {};
}

} // namespace

MethodEntry makeMultiviewMethod() {
    auto args = std::make_shared<MultiviewArgs>();
    MethodEntry e;
    e.name = "multiview";
    e.summary = "Lee, Eisemann & Seidel 2009: lens rays traced through depth layers";
    e.add_options = [args](CLI::App& cmd) {
        cmd.add_option("--layer-spacing", args->layer_spacing,
                       "multiview: CoC growth delta between layers in pixels (Lee Sec. 4.1, "
                       "Eq. 4); the layer count follows (at most 64)")
            ->capture_default_str();
        cmd.add_option("--layers", args->layers,
                       "multiview: layer budget M (overrides --layer-spacing; 0 = from spacing)")
            ->capture_default_str()
            ->check(CLI::Range(0, 64));
        cmd.add_option("--overlap", args->overlap, "multiview: layer overlap fraction (Sec. 4.2)")
            ->capture_default_str()
            ->check(CLI::Range(0.0, 1.0));
        cmd.add_option("--iterations", args->iterations,
                       "multiview: false-position iterations per layer (Sec. 4.3)")
            ->capture_default_str()
            ->check(CLI::Range(0, 64));
        cmd.add_option("--refine-steps", args->refine_steps,
                       "multiview: binary-search steps after the false position (Sec. 4.3)")
            ->capture_default_str()
            ->check(CLI::Range(0, 32));
        cmd.add_option("--cone", args->cone, "multiview: approximate cone tracing (Sec. 4.4)")
            ->capture_default_str()
            ->check(CLI::IsMember({"on", "off"}));
        cmd.add_option("--culling", args->culling,
                       "multiview: early layer culling with N-buffers (Sec. 4.3)")
            ->capture_default_str()
            ->check(CLI::IsMember({"on", "off"}));
        cmd.add_option("--jitter", args->jitter,
                       "multiview: per-pixel lens sample variation (Sec. 4.5): none, noise "
                       "(16 pairwise noise offsets), halton (2N sequence offsets), rotate")
            ->capture_default_str()
            ->check(CLI::IsMember({"none", "noise", "halton", "rotate"}));
        cmd.add_option("--routing", args->routing,
                       "multiview: layer routing (Sec. 4.2): max-vertex (the paper) or "
                       "per-fragment (exact)")
            ->capture_default_str()
            ->check(CLI::IsMember({"max-vertex", "per-fragment"}));
        cmd.add_option("--offscreen", args->offscreen,
                       "multiview: rays leaving the image: discard (the paper) or clamp")
            ->capture_default_str()
            ->check(CLI::IsMember({"discard", "clamp"}));
        cmd.add_flag("--view-dependent", args->view_dependent,
                     "multiview: shade every hit from its lens ray's own origin (Sec. 5)");
        cmd.add_option("--env-map", args->env_map,
                       "multiview: equirectangular environment map for reflections (Sec. 5)");
        cmd.add_option("--env-intensity", args->env_intensity, "multiview: environment map scale")
            ->capture_default_str();
    };
    e.run = [args](const MethodInput& in, MethodOutput& out) {
        return runMultiview(*args, in, out);
    };
    return e;
}

} // namespace focal
