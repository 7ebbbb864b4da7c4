// MultiviewSettings described once (settings_table.h): Lee, Eisemann & Seidel 2009, "Depth-of-
// Field Rendering with Multiview Synthesis", section by section.
#include <dof/multiview.h>

#include <cmath>
#include <string>

namespace dof {

namespace {

using S = MultiviewSettings;
constexpr std::string_view kMethod = "multiview";

constexpr ParamChoice kTraversal[] = {choice("false-position", Traversal::FalsePosition),
                                      choice("scan", Traversal::Scan)};
constexpr ParamChoice kConeCentre[] = {choice("cell", ConeCentre::Cell),
                                       choice("sample", ConeCentre::Sample)};
constexpr ParamChoice kJitter[] = {
    choice("none", JitterMode::None), choice("noise", JitterMode::Noise),
    choice("halton", JitterMode::Halton), choice("rotate", JitterMode::Rotate)};
constexpr ParamChoice kRouting[] = {choice("max-vertex", raster::LayerRouting::MaxVertexDepth),
                                    choice("per-fragment", raster::LayerRouting::PerFragment)};
constexpr ParamChoice kOffscreen[] = {choice("discard", OffscreenPolicy::Discard),
                                      choice("clamp", OffscreenPolicy::Clamp)};
constexpr ParamChoice kConeShading[] = {choice("centre", ConeShading::Centre),
                                        choice("footprint", ConeShading::Footprint)};

const Param<S> kParams[] = {
    {{.name = "layer_spacing_px",
      .flag = "layer-spacing",
      .min = 0.0,
      .max = kUnbounded,
      .min_open = true,
      .paper = "Lee et al. 2009, §4.1 Eq. 4",
      .help = "CoC growth delta between layers in pixels; the layer count follows (at most 64)"},
     field<&S::layer_spacing_px>()},
    {{.name = "layers",
      .flag = "layers",
      .max = double(raster::kMaxLayers),
      .paper = "Lee et al. 2009, §4.1",
      .help = "layer budget M (overrides layer_spacing_px; 0 = from the spacing)"},
     field<&S::layers>()},
    {{.name = "overlap",
      .flag = "overlap",
      .max = 1.0,
      .paper = "Lee et al. 2009, §4.2",
      .help = "layer overlap fraction, in 1/d"},
     field<&S::overlap>()},
    {{.name = "routing",
      .flag = "routing",
      .type = ParamType::Choice,
      .choices = kRouting,
      .paper = "Lee et al. 2009, §4.2",
      .help = "layer routing: max-vertex (the paper) or per-fragment (exact)"},
     field<&S::routing>()},
    {{.name = "traversal",
      .flag = "traversal",
      .type = ParamType::Choice,
      .choices = kTraversal,
      .paper = "Lee et al. 2009, §4.3 and §6",
      .help = "height-field intersection: false-position (the paper) or scan (every texel on the "
              "path, exact)"},
     field<&S::traversal>()},
    {{.name = "iterations",
      .flag = "iterations",
      .max = 64.0,
      .paper = "Lee et al. 2009, §4.3",
      .help = "false-position iterations per layer"},
     field<&S::iterations>()},
    {{.name = "refine_steps",
      .flag = "refine-steps",
      .max = 32.0,
      .paper = "Lee et al. 2009, §4.3",
      .help = "binary-search steps after the false position"},
     field<&S::refine_steps>()},
    {{.name = "bound_init",
      .flag = "bound-init",
      .type = ParamType::Switch,
      .paper = "Lee et al. 2009, §4.3",
      .help = "start the false position from the layer's depth bounds and look up the segment "
              "ends only when the first point is empty"},
     field<&S::bound_init>()},
    {{.name = "thickness_px",
      .flag = "thickness",
      .max = kUnbounded,
      .min_open = true,
      .special = {"inf", kUnbounded},
      .help = "with the scan, how far behind its depth a layer texel is solid, as a CoC "
              "difference in pixels; inf = the paper's height field"},
     field<&S::thickness_px>()},
    {{.name = "culling",
      .flag = "culling",
      .type = ParamType::Switch,
      .paper = "Lee et al. 2009, §4.3",
      .help = "early layer culling with N-buffers (lossless)"},
     field<&S::culling>()},
    {{.name = "precompute_paths",
      .flag = "precompute-paths",
      .type = ParamType::Switch,
      .help = "with jitter none and the scan, walk each lens ray's path through each layer once "
              "per frame, not once per pixel (same image)"},
     field<&S::precompute_paths>()},
    {{.name = "skip_unblurred",
      .flag = "skip-unblurred",
      .type = ParamType::Switch,
      .help = "return the pinhole render when the lens cannot change the image (off: run every "
              "stage)"},
     field<&S::skip_unblurred>()},
    {{.name = "cone",
      .flag = "cone",
      .type = ParamType::Switch,
      .paper = "Lee et al. 2009, §4.4",
      .help = "approximate cone tracing"},
     field<&S::cone>()},
    {{.name = "cone_misses",
      .flag = "cone-misses",
      .type = ParamType::Switch,
      .help = "with the cones, a ray crossing a layer without a hit also looks its cone up there "
              "(off: the paper's rule, cones only at hits)"},
     field<&S::cone_misses>()},
    {{.name = "cone_centre",
      .flag = "cone-centre",
      .type = ParamType::Choice,
      .choices = kConeCentre,
      .paper = "Lee et al. 2009, §4.4",
      .help = "with the cones and jitter none, centre each ray's cone on the centroid of its "
              "lens sample's Voronoi cell in the aperture (cell) or on the ray (sample: the "
              "paper)"},
     field<&S::cone_centre>()},
    {{.name = "jitter",
      .flag = "jitter",
      .type = ParamType::Choice,
      .choices = kJitter,
      .paper = "Lee et al. 2009, §4.5",
      .help = "per-pixel lens sample variation: none, noise (16 pairwise noise offsets), halton "
              "(2N sequence offsets), rotate"},
     field<&S::jitter>()},
    {{.name = "offscreen",
      .flag = "offscreen",
      .type = ParamType::Choice,
      .choices = kOffscreen,
      .paper = "Lee et al. 2009, §4.3",
      .help = "rays leaving the image: clamp (read the border texels) or discard (the paper)"},
     field<&S::offscreen>()},
    {{.name = "guard_band_px",
      .flag = "guard-band",
      .max = 1024.0,
      .paper = "Lee et al. 2009, §4.3 (Handling Off-Screen Pixels)",
      .help = "render the layers over the image and a band around it as wide as the largest "
              "visible |C|, at most this many pixels, so rays leaving the image read the scene "
              "there (0: the image alone, the paper's choice)"},
     field<&S::guard_band_px>()},
    {{.name = "view_dependent",
      .flag = "view-dependent",
      .type = ParamType::Flag,
      .paper = "Lee et al. 2009, §5",
      .help = "shade every hit from its lens ray's own origin"},
     field<&S::view_dependent>()},
    {{.name = "cone_shading",
      .flag = "cone-shading",
      .type = ParamType::Choice,
      .choices = kConeShading,
      .paper = "Lee et al. 2009, §4.4 and §5",
      .help = "with the cones and per-ray shading, shade the cone's centre texel or average 5 "
              "shaded taps of its footprint"},
     field<&S::cone_shading>()},
};

} // namespace

std::span<const Param<MultiviewSettings>> multiviewParams() {
    return kParams;
}

raster::Status validate(const MultiviewSettings& s, uint32_t sample_count) {
    if (sample_count == 0)
        return settingsError(kMethod, "samples must be at least 1");
    if (raster::Status st = checkParams(kMethod, multiviewParams(), s); !st.ok())
        return st;
    if (s.tile_size == 0 || s.tile_size > 1024)
        return settingsError(kMethod,
                             "tile_size must be in [1, 1024], got " + std::to_string(s.tile_size));
    if (s.jitter == JitterMode::Halton) {
        if (!s.sequence_2n || s.sequence_2n->size() == 0)
            return settingsError(kMethod, "jitter halton needs a 2N-sample sequence_2n");
        if (s.sequence_2n->size() < sample_count)
            return settingsError(kMethod, "jitter halton: sequence_2n must hold at least the "
                                          "samples");
    }
    if (s.env_map) {
        const EnvironmentMap& e = *s.env_map;
        if (e.width == 0 || e.height == 0 || e.rgb.size() != size_t(e.width) * e.height * 3)
            return settingsError(kMethod, "env_map is empty or its size does not match");
        if (!std::isfinite(e.intensity) || e.intensity < 0.0f)
            return settingsError(kMethod, "env_map intensity must be a non-negative number");
    }
    return {};
}

} // namespace dof
