// llvmpipe_bench: renders a focal scene with Mesa's llvmpipe (OpenGL through OSMesa, headless)
// so focal's rasterizer can be timed against the standard CPU OpenGL driver on the same work.
// Consumes a scene from focal's own loader (builtin:NAME or a glTF path) and focal's View; produces
// the median milliseconds per frame as JSON on stdout and, optionally, one PNG. Benchmark-only:
// not part of the library, the CLI or the tests (docs/benchmarks.md, "Rasterizer throughput").
//
// The workload mirrors raster/src/shading.cpp and tile_raster.cpp: the same triangles, view and
// projection (z/w = D + 1 in [0,1] via glClipControl; focal stores D in [-1, 0]), per-pixel Lambert
// + energy-normalised Blinn-Phong over the scene's punctual lights (or focal's default light),
// ambient 0.12 x albedo, emissive, base colour and emissive textures as sRGB with focal's own mip
// chains (trilinear per the glTF sampler), vertex colours, alpha test for MASK, "over" blending
// without depth writes for BLEND, back-face culling unless double-sided, and a float32 depth
// buffer. Each timed frame is clear + every draw + glFinish. Thread count: LP_NUM_THREADS (set by
// --threads before the context exists; 0 = llvmpipe runs the rasterizer inline on the calling
// thread).

#define GL_GLEXT_PROTOTYPES 1
#include "apps/image_io.h"
#include "apps/scene_source.h"

#include <raster/camera.h>
#include <raster/scene.h>
#include <raster/texture.h>

#include <glm/geometric.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>

#include <GL/osmesa.h>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <string>
#include <sys/resource.h>
#include <vector>

namespace {

constexpr float kPi = 3.14159265358979f;
constexpr float kDefaultLightIntensity = kPi; // raster/src/shading.cpp

struct Options {
    std::string scene;
    uint32_t width = 800;
    uint32_t height = 600;
    int camera = 0;
    int threads = -1; // -1: leave LP_NUM_THREADS as the environment has it
    uint32_t repeat = 7;
    uint32_t warmup = 1;
    std::string png;
    std::string target = "srgb8"; // colour target: srgb8 | rgba16f | rgba32f
};

int fail(const std::string& message) {
    std::fprintf(stderr, "llvmpipe_bench: error: %s\n", message.c_str());
    return 1;
}

void usage() {
    std::fprintf(stderr,
                 "usage: llvmpipe_bench SCENE [--width W] [--height H] [--camera I] [--threads T]\n"
                 "                      [--repeat K] [--warmup N] [--png OUT.png]\n"
                 "                      [--target srgb8|rgba16f|rgba32f]\n"
                 "SCENE is builtin:NAME or a .gltf/.glb path. --threads sets LP_NUM_THREADS\n"
                 "(0 = llvmpipe rasterizes inline). Prints JSON with the median ms per frame.\n");
}

bool parseArgs(int argc, char** argv, Options& o) {
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        auto next = [&](const char* what) -> const char* {
            if (i + 1 >= argc) {
                std::fprintf(stderr, "llvmpipe_bench: error: %s needs a value\n", what);
                return nullptr;
            }
            return argv[++i];
        };
        auto number = [&](const char* what, long lo, long hi, long& out) {
            const char* v = next(what);
            if (!v)
                return false;
            char* end = nullptr;
            out = std::strtol(v, &end, 10);
            if (*v == '\0' || *end != '\0' || out < lo || out > hi) {
                std::fprintf(stderr, "llvmpipe_bench: error: %s expects an integer in [%ld, %ld]\n",
                             what, lo, hi);
                return false;
            }
            return true;
        };
        long n = 0;
        if (a == "--width") {
            if (!number("--width", 1, 16384, n))
                return false;
            o.width = uint32_t(n);
        } else if (a == "--height") {
            if (!number("--height", 1, 16384, n))
                return false;
            o.height = uint32_t(n);
        } else if (a == "--camera") {
            if (!number("--camera", 0, 1 << 20, n))
                return false;
            o.camera = int(n);
        } else if (a == "--threads") {
            if (!number("--threads", 0, 256, n))
                return false;
            o.threads = int(n);
        } else if (a == "--repeat") {
            if (!number("--repeat", 1, 100000, n))
                return false;
            o.repeat = uint32_t(n);
        } else if (a == "--warmup") {
            if (!number("--warmup", 0, 1000, n))
                return false;
            o.warmup = uint32_t(n);
        } else if (a == "--png") {
            const char* v = next("--png");
            if (!v)
                return false;
            o.png = v;
        } else if (a == "--target") {
            const char* v = next("--target");
            if (!v)
                return false;
            o.target = v;
            if (o.target != "srgb8" && o.target != "rgba16f" && o.target != "rgba32f") {
                std::fprintf(stderr, "llvmpipe_bench: error: unknown --target %s\n", v);
                return false;
            }
        } else if (a == "-h" || a == "--help") {
            return false;
        } else if (!a.empty() && a[0] != '-' && o.scene.empty()) {
            o.scene = a;
        } else {
            std::fprintf(stderr, "llvmpipe_bench: error: unexpected argument '%s'\n", a.c_str());
            return false;
        }
    }
    if (o.scene.empty()) {
        std::fprintf(stderr, "llvmpipe_bench: error: no scene given\n");
        return false;
    }
    return true;
}

// ---- Shaders ------------------------------------------------------------------------------

const char* kVertexShader = R"(#version 330 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec2 a_uv;
layout(location = 3) in vec4 a_color;
uniform mat4 u_view_proj;
uniform mat4 u_world;
uniform mat3 u_normal_matrix;
out vec3 v_world;
out vec3 v_normal;
out vec2 v_uv;
out vec4 v_color;
void main() {
    vec4 world = u_world * vec4(a_position, 1.0);
    v_world = world.xyz;
    v_normal = u_normal_matrix * a_normal;
    v_uv = a_uv;
    v_color = a_color;
    gl_Position = u_view_proj * world;
}
)";

// Everything that decides which code a fragment runs; one program per distinct key, as an
// engine's shader permutations (uniform branches would cost llvmpipe both sides).
struct ShaderKey {
    bool base_texture = false;
    bool emissive_texture = false;
    bool mask = false;
    bool unlit = false;
    bool normals = false;
    bool operator<(const ShaderKey& o) const { return bits() < o.bits(); }
    unsigned bits() const {
        return unsigned(base_texture) | unsigned(emissive_texture) << 1 | unsigned(mask) << 2 |
               unsigned(unlit) << 3 | unsigned(normals) << 4;
    }
};

// The scene's lights are fixed, so each light's code is emitted for its type (as shading.cpp's
// loop would run it); their parameters are uniforms.
std::string fragmentShader(const ShaderKey& key, const std::vector<raster::Light>& lights) {
    std::string s = "#version 330 core\n";
    auto define = [&](const char* name, bool on) {
        if (on)
            s += std::string("#define ") + name + "\n";
    };
    define("BASE_TEXTURE", key.base_texture);
    define("EMISSIVE_TEXTURE", key.emissive_texture);
    define("ALPHA_MASK", key.mask);
    define("UNLIT", key.unlit);
    define("HAS_NORMALS", key.normals);
    s += "#define LIGHT_COUNT " + std::to_string(std::max<size_t>(lights.size(), 1)) + "\n";
    s += R"(
in vec3 v_world;
in vec3 v_normal;
in vec2 v_uv;
in vec4 v_color;
out vec4 o_color;
uniform vec4 u_base_factor;
uniform vec3 u_emissive_factor;
uniform float u_alpha_cutoff;
uniform float u_metallic;
uniform float u_shininess;
uniform float u_spec_norm;
uniform float u_blend;  // 1: BLEND material (alpha out), 0: opaque/mask (alpha 1)
uniform vec3 u_eye;
uniform sampler2D u_base_tex;
uniform mat3 u_base_uv;
uniform sampler2D u_emissive_tex;
uniform mat3 u_emissive_uv;
uniform vec3 u_light_position[LIGHT_COUNT];
uniform vec3 u_light_direction[LIGHT_COUNT];  // unit, the way the light travels
uniform vec3 u_light_radiance[LIGHT_COUNT];
uniform float u_light_range[LIGHT_COUNT];
uniform vec2 u_light_cone[LIGHT_COUNT];  // cos(outer), cos(inner)

vec3 g_n, g_v, g_diffuse, g_f0, g_result;

void addLight(vec3 l, vec3 radiance) {
    float n_dot_l = dot(g_n, l);
    if (n_dot_l > 0.0) {
        vec3 h = normalize(l + g_v);
        float n_dot_h = max(dot(g_n, h), 0.0);
        vec3 brdf = g_diffuse + g_f0 * (u_spec_norm * pow(n_dot_h, u_shininess));
        g_result += brdf * radiance * n_dot_l;
    }
}

void addPunctual(int i, bool spot) {
    vec3 to_light = u_light_position[i] - v_world;
    float dist2 = max(dot(to_light, to_light), 1e-8);
    vec3 l = to_light * inversesqrt(dist2);
    float attenuation = 1.0 / dist2;
    if (u_light_range[i] > 0.0) {
        float r = dist2 / (u_light_range[i] * u_light_range[i]);
        attenuation *= clamp(1.0 - r * r, 0.0, 1.0);
    }
    if (spot) {
        float cd = dot(u_light_direction[i], -l);
        float t = clamp((cd - u_light_cone[i].x) / max(u_light_cone[i].y - u_light_cone[i].x, 1e-4),
                        0.0, 1.0);
        attenuation *= t * t;
    }
    addLight(l, u_light_radiance[i] * attenuation);
}

void main() {
    vec4 base = u_base_factor * v_color;
#ifdef BASE_TEXTURE
    base *= texture(u_base_tex, (u_base_uv * vec3(v_uv, 1.0)).xy);
#endif
#ifdef ALPHA_MASK
    if (!(base.a >= u_alpha_cutoff))
        discard;
#endif
    vec3 emissive = u_emissive_factor;
#ifdef EMISSIVE_TEXTURE
    emissive *= texture(u_emissive_tex, (u_emissive_uv * vec3(v_uv, 1.0)).xy).rgb;
#endif
    vec3 albedo = base.rgb;
    float alpha = mix(1.0, clamp(base.a, 0.0, 1.0), u_blend);
#ifdef UNLIT
    o_color = vec4(albedo + emissive, alpha);
    return;
#else
#ifdef HAS_NORMALS
    vec3 n = gl_FrontFacing ? v_normal : -v_normal;
#else
    vec3 n = cross(dFdx(v_world), dFdy(v_world));
    if (dot(n, u_eye - v_world) < 0.0)
        n = -n;
#endif
    float len = length(n);
    g_n = len > 0.0 ? n / len : vec3(0.0, 0.0, 1.0);
    g_v = normalize(u_eye - v_world);
    g_diffuse = albedo * (1.0 - u_metallic) * (1.0 / 3.14159265358979);
    g_f0 = mix(vec3(0.04), albedo, u_metallic);
    g_result = emissive + 0.12 * albedo;
)";
    if (lights.empty()) {
        s += "    addLight(-u_light_direction[0], u_light_radiance[0]);\n";
    } else {
        for (size_t i = 0; i < lights.size(); ++i) {
            const std::string idx = std::to_string(i);
            switch (lights[i].type) {
            case raster::Light::Type::Directional:
                s += "    addLight(-u_light_direction[" + idx + "], u_light_radiance[" + idx +
                     "]);\n";
                break;
            case raster::Light::Type::Point:
                s += "    addPunctual(" + idx + ", false);\n";
                break;
            case raster::Light::Type::Spot:
                s += "    addPunctual(" + idx + ", true);\n";
                break;
            }
        }
    }
    s += R"(    o_color = vec4(g_result, alpha);
#endif
}
)";
    return s;
}

GLuint compile(GLenum type, const std::string& source, std::string& error) {
    const GLuint shader = glCreateShader(type);
    const char* text = source.c_str();
    glShaderSource(shader, 1, &text, nullptr);
    glCompileShader(shader);
    GLint ok = 0;
    glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[4096] = {};
        glGetShaderInfoLog(shader, sizeof(log), nullptr, log);
        error = std::string("shader compile failed: ") + log;
        glDeleteShader(shader);
        return 0;
    }
    return shader;
}

struct Program {
    GLuint id = 0;
    GLint view_proj, world, normal_matrix, base_factor, emissive_factor, alpha_cutoff, metallic,
        shininess, spec_norm, blend, eye, base_uv, emissive_uv;
};

bool linkProgram(const ShaderKey& key, const std::vector<raster::Light>& lights, Program& p,
                 std::string& error) {
    const GLuint vs = compile(GL_VERTEX_SHADER, kVertexShader, error);
    if (!vs)
        return false;
    const GLuint fs = compile(GL_FRAGMENT_SHADER, fragmentShader(key, lights), error);
    if (!fs)
        return false;
    p.id = glCreateProgram();
    glAttachShader(p.id, vs);
    glAttachShader(p.id, fs);
    glLinkProgram(p.id);
    glDeleteShader(vs);
    glDeleteShader(fs);
    GLint ok = 0;
    glGetProgramiv(p.id, GL_LINK_STATUS, &ok);
    if (!ok) {
        char log[4096] = {};
        glGetProgramInfoLog(p.id, sizeof(log), nullptr, log);
        error = std::string("program link failed: ") + log;
        return false;
    }
    auto loc = [&](const char* name) { return glGetUniformLocation(p.id, name); };
    p.view_proj = loc("u_view_proj");
    p.world = loc("u_world");
    p.normal_matrix = loc("u_normal_matrix");
    p.base_factor = loc("u_base_factor");
    p.emissive_factor = loc("u_emissive_factor");
    p.alpha_cutoff = loc("u_alpha_cutoff");
    p.metallic = loc("u_metallic");
    p.shininess = loc("u_shininess");
    p.spec_norm = loc("u_spec_norm");
    p.blend = loc("u_blend");
    p.eye = loc("u_eye");
    p.base_uv = loc("u_base_uv");
    p.emissive_uv = loc("u_emissive_uv");
    glUseProgram(p.id);
    glUniform1i(loc("u_base_tex"), 0);
    glUniform1i(loc("u_emissive_tex"), 1);
    return true;
}

// ---- Scene upload -------------------------------------------------------------------------

struct GpuPrimitive {
    GLuint vao = 0;
    GLsizei index_count = 0;
    const raster::Primitive* source = nullptr;
};

GLint wrapOf(raster::Wrap w) {
    switch (w) {
    case raster::Wrap::ClampToEdge:
        return GL_CLAMP_TO_EDGE;
    case raster::Wrap::MirroredRepeat:
        return GL_MIRRORED_REPEAT;
    default:
        return GL_REPEAT;
    }
}

GLint minFilterOf(const raster::Sampler& s) {
    const bool lin = s.min == raster::Filter::Linear;
    switch (s.mip) {
    case raster::MipFilter::None:
        return lin ? GL_LINEAR : GL_NEAREST;
    case raster::MipFilter::Nearest:
        return lin ? GL_LINEAR_MIPMAP_NEAREST : GL_NEAREST_MIPMAP_NEAREST;
    default:
        return lin ? GL_LINEAR_MIPMAP_LINEAR : GL_NEAREST_MIPMAP_LINEAR;
    }
}

// Uploads focal's own mip chain (built in linear light), so both renderers filter the same texels.
GLuint uploadImage(const raster::Image& image) {
    GLuint tex = 0;
    glGenTextures(1, &tex);
    glBindTexture(GL_TEXTURE_2D, tex);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    const GLint internal = image.srgb ? GL_SRGB8_ALPHA8 : GL_RGBA8;
    for (size_t level = 0; level < image.levels.size(); ++level) {
        const raster::MipLevel& m = image.levels[level];
        glTexImage2D(GL_TEXTURE_2D, GLint(level), internal, GLsizei(m.width), GLsizei(m.height), 0,
                     GL_RGBA, GL_UNSIGNED_BYTE, m.rgba8.data());
    }
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_BASE_LEVEL, 0);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, GLint(image.levels.size()) - 1);
    return tex;
}

GLuint makeSampler(const raster::Sampler& s) {
    GLuint id = 0;
    glGenSamplers(1, &id);
    glSamplerParameteri(id, GL_TEXTURE_WRAP_S, wrapOf(s.wrap_s));
    glSamplerParameteri(id, GL_TEXTURE_WRAP_T, wrapOf(s.wrap_t));
    glSamplerParameteri(id, GL_TEXTURE_MAG_FILTER,
                        s.mag == raster::Filter::Linear ? GL_LINEAR : GL_NEAREST);
    glSamplerParameteri(id, GL_TEXTURE_MIN_FILTER, minFilterOf(s));
    return id;
}

GpuPrimitive uploadPrimitive(const raster::Primitive& prim) {
    GpuPrimitive g;
    g.source = &prim;
    g.index_count = GLsizei(prim.indices.size());
    glGenVertexArrays(1, &g.vao);
    glBindVertexArray(g.vao);
    auto attribute = [](GLuint location, GLint components, const void* data, size_t bytes) {
        GLuint buffer = 0;
        glGenBuffers(1, &buffer);
        glBindBuffer(GL_ARRAY_BUFFER, buffer);
        glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(bytes), data, GL_STATIC_DRAW);
        glEnableVertexAttribArray(location);
        glVertexAttribPointer(location, components, GL_FLOAT, GL_FALSE, 0, nullptr);
    };
    attribute(0, 3, prim.positions.data(), prim.positions.size() * sizeof(glm::vec3));
    // Missing attributes are constants, as focal uses them: normal 0 (face normal), uv 0, white.
    if (!prim.normals.empty())
        attribute(1, 3, prim.normals.data(), prim.normals.size() * sizeof(glm::vec3));
    else
        glVertexAttrib3f(1, 0.0f, 0.0f, 0.0f);
    if (!prim.texcoords0.empty())
        attribute(2, 2, prim.texcoords0.data(), prim.texcoords0.size() * sizeof(glm::vec2));
    else
        glVertexAttrib2f(2, 0.0f, 0.0f);
    if (!prim.colors.empty())
        attribute(3, 4, prim.colors.data(), prim.colors.size() * sizeof(glm::vec4));
    else
        glVertexAttrib4f(3, 1.0f, 1.0f, 1.0f, 1.0f);
    GLuint ebo = 0;
    glGenBuffers(1, &ebo);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ebo);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(prim.indices.size() * sizeof(uint32_t)),
                 prim.indices.data(), GL_STATIC_DRAW);
    glBindVertexArray(0);
    return g;
}

// One draw call, prepared once: which program and state, and its per-draw uniforms.
struct DrawCall {
    const Program* program;
    GLuint vao;
    GLsizei index_count;
    glm::mat4 world;
    glm::mat3 normal_matrix;
    bool mirrored;
    const raster::Material* material;
    GLuint base_tex, base_sampler, emissive_tex, emissive_sampler;
    float shininess, spec_norm, metallic;
};

} // namespace

int main(int argc, char** argv) {
    Options opt;
    if (!parseArgs(argc, argv, opt)) {
        usage();
        return 2;
    }
    // llvmpipe reads LP_NUM_THREADS when its screen is created, i.e. at the first context.
    if (opt.threads >= 0)
        setenv("LP_NUM_THREADS", std::to_string(opt.threads).c_str(), 1);
    const char* lp_threads = std::getenv("LP_NUM_THREADS");

    raster::Result<raster::Scene> loaded = focal::loadScene(opt.scene);
    if (!loaded.ok())
        return fail(loaded.status().message());
    const raster::Scene& scene = *loaded;

    // The view, as `focal render` resolves it without --eye/--target/--yfov/--near/--far.
    raster::View view;
    if (!scene.cameras.empty()) {
        if (opt.camera < 0 || size_t(opt.camera) >= scene.cameras.size())
            return fail(scene.source + ": has no camera " + std::to_string(opt.camera));
        view = raster::viewFromCamera(scene.cameras[size_t(opt.camera)], opt.width, opt.height);
    } else {
        view = raster::viewFramingBounds(raster::worldBounds(scene), opt.width, opt.height);
    }
    // focal's clip space has z/w = D in [-1, 0] (reversed-Z with the sign flipped, camera.h);
    // GL's zero-to-one clip volume needs [0, 1], so z' = z + w gives z'/w = D + 1: the same near
    // and far clip planes and the same depth order (LESS, cleared to 1 = the far plane).
    glm::mat4 depth_shift(1.0f);
    depth_shift[3][2] = 1.0f; // column w, row z
    const glm::mat4 view_proj =
        depth_shift * raster::projectionMatrix(view) * raster::viewMatrix(view);
    const glm::vec3 eye = view.eye;

    // Context: OSMesa with a core profile; rendering goes to an FBO, so the OSMesa buffer only
    // has to exist.
    const int attribs[] = {OSMESA_FORMAT,
                           OSMESA_RGBA,
                           OSMESA_DEPTH_BITS,
                           0,
                           OSMESA_PROFILE,
                           OSMESA_CORE_PROFILE,
                           OSMESA_CONTEXT_MAJOR_VERSION,
                           4,
                           OSMESA_CONTEXT_MINOR_VERSION,
                           5,
                           0};
    OSMesaContext ctx = OSMesaCreateContextAttribs(attribs, nullptr);
    if (!ctx)
        return fail("OSMesaCreateContextAttribs failed (OpenGL 4.5 core profile)");
    std::vector<uint8_t> osmesa_buffer(size_t(opt.width) * opt.height * 4);
    if (!OSMesaMakeCurrent(ctx, osmesa_buffer.data(), GL_UNSIGNED_BYTE, GLsizei(opt.width),
                           GLsizei(opt.height)))
        return fail("OSMesaMakeCurrent failed");
    const char* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    const char* version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
    std::fprintf(stderr, "llvmpipe_bench: GL_RENDERER = %s, GL_VERSION = %s, LP_NUM_THREADS = %s\n",
                 renderer ? renderer : "?", version ? version : "?",
                 lp_threads ? lp_threads : "(unset: one per CPU)");
    if (!renderer || !std::strstr(renderer, "llvmpipe"))
        return fail("OSMesa is not running on llvmpipe");

    // D3D-style depth: clip z/w in [0,1] (focal's D + 1, see view_proj above).
    auto clip_control = reinterpret_cast<PFNGLCLIPCONTROLPROC>(
        reinterpret_cast<void*>(OSMesaGetProcAddress("glClipControl")));
    if (!clip_control)
        return fail("glClipControl is not available");
    clip_control(GL_LOWER_LEFT, GL_ZERO_TO_ONE);

    // Targets: colour (sRGB 8-bit by default, blended in linear light) and float32 depth.
    const GLenum color_format = opt.target == "rgba32f"   ? GL_RGBA32F
                                : opt.target == "rgba16f" ? GL_RGBA16F
                                                          : GL_SRGB8_ALPHA8;
    GLuint fbo = 0, color_rb = 0, depth_rb = 0;
    glGenFramebuffers(1, &fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glGenRenderbuffers(1, &color_rb);
    glBindRenderbuffer(GL_RENDERBUFFER, color_rb);
    glRenderbufferStorage(GL_RENDERBUFFER, color_format, GLsizei(opt.width), GLsizei(opt.height));
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color_rb);
    glGenRenderbuffers(1, &depth_rb);
    glBindRenderbuffer(GL_RENDERBUFFER, depth_rb);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, GLsizei(opt.width),
                          GLsizei(opt.height));
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_rb);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        return fail("framebuffer incomplete");
    if (color_format == GL_SRGB8_ALPHA8)
        glEnable(GL_FRAMEBUFFER_SRGB);
    glViewport(0, 0, GLsizei(opt.width), GLsizei(opt.height));

    // Textures and samplers.
    std::vector<GLuint> textures;
    for (const raster::Image& image : scene.images)
        textures.push_back(uploadImage(image));
    const GLuint default_sampler = makeSampler(raster::Sampler{});
    std::vector<GLuint> samplers;
    for (const raster::Sampler& s : scene.samplers)
        samplers.push_back(makeSampler(s));
    auto samplerOf = [&](const raster::TextureRef& ref) {
        return ref.sampler >= 0 ? samplers[size_t(ref.sampler)] : default_sampler;
    };

    // Meshes.
    std::vector<std::vector<GpuPrimitive>> meshes(scene.meshes.size());
    for (size_t m = 0; m < scene.meshes.size(); ++m)
        for (const raster::Primitive& prim : scene.meshes[m].primitives)
            meshes[m].push_back(uploadPrimitive(prim));

    // Draw list in focal's order (instances, then their primitives), with one program per key.
    std::map<ShaderKey, Program> programs;
    std::vector<DrawCall> draws;
    for (const raster::Instance& inst : scene.instances) {
        const glm::mat3 linear(inst.world);
        for (const GpuPrimitive& g : meshes[inst.mesh]) {
            if (g.index_count < 3)
                continue;
            const raster::Material& m = raster::materialOf(scene, *g.source);
            ShaderKey key;
            key.base_texture = m.base_color_texture.image >= 0;
            key.emissive_texture =
                m.emissive_texture.image >= 0 && m.emissive_factor != glm::vec3(0.0f);
            key.mask = m.alpha_mode == raster::AlphaMode::Mask;
            key.unlit = m.unlit;
            key.normals = !g.source->normals.empty();
            auto it = programs.find(key);
            if (it == programs.end()) {
                Program p;
                std::string error;
                if (!linkProgram(key, scene.lights, p, error))
                    return fail(error);
                it = programs.emplace(key, p).first;
            }
            DrawCall d{};
            d.program = &it->second;
            d.vao = g.vao;
            d.index_count = g.index_count;
            d.world = inst.world;
            d.normal_matrix = glm::transpose(glm::inverse(linear));
            d.mirrored = glm::determinant(linear) < 0.0f;
            d.material = &m;
            d.base_tex = key.base_texture ? textures[size_t(m.base_color_texture.image)] : 0;
            d.base_sampler = samplerOf(m.base_color_texture);
            d.emissive_tex = key.emissive_texture ? textures[size_t(m.emissive_texture.image)] : 0;
            d.emissive_sampler = samplerOf(m.emissive_texture);
            // raster/src/shading.cpp: Blinn-Phong exponent from roughness (Walter et al. 2007).
            const float alpha = std::max(m.roughness_factor * m.roughness_factor, 0.02f);
            d.shininess = 2.0f / (alpha * alpha) - 2.0f;
            d.spec_norm = (d.shininess + 8.0f) / (8.0f * kPi);
            d.metallic = std::clamp(m.metallic_factor, 0.0f, 1.0f);
            draws.push_back(d);
        }
    }

    // Per-frame constants: lights (or focal's default light, raster/src/renderer.cpp) and view.
    std::vector<raster::Light> lights = scene.lights;
    if (lights.empty()) {
        raster::Light def;
        def.type = raster::Light::Type::Directional;
        def.direction = glm::normalize(0.35f * view.right - 0.6f * view.up + 0.7f * view.forward);
        def.color = glm::vec3(1.0f);
        def.intensity = kDefaultLightIntensity;
        lights.push_back(def);
    }
    for (auto& [key, p] : programs) {
        glUseProgram(p.id);
        glUniformMatrix4fv(p.view_proj, 1, GL_FALSE, glm::value_ptr(view_proj));
        glUniform3fv(p.eye, 1, glm::value_ptr(eye));
        for (size_t i = 0; i < lights.size(); ++i) {
            const raster::Light& l = lights[i];
            auto at = [&](const char* name) {
                return glGetUniformLocation(
                    p.id, (std::string(name) + "[" + std::to_string(i) + "]").c_str());
            };
            const glm::vec3 dir = glm::normalize(l.direction);
            const glm::vec3 radiance = l.color * l.intensity;
            glUniform3fv(at("u_light_position"), 1, glm::value_ptr(l.position));
            glUniform3fv(at("u_light_direction"), 1, glm::value_ptr(dir));
            glUniform3fv(at("u_light_radiance"), 1, glm::value_ptr(radiance));
            glUniform1f(at("u_light_range"), l.range);
            glUniform2f(at("u_light_cone"), std::cos(l.outer_cone_angle),
                        std::cos(l.inner_cone_angle));
        }
    }

    const glm::vec3 bg = scene.background;
    auto renderFrame = [&]() {
        glDepthMask(GL_TRUE);
        glClearColor(bg.r, bg.g, bg.b, 1.0f);
        glClearDepth(1.0);
        glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_LESS);
        const Program* current = nullptr;
        for (const DrawCall& d : draws) {
            const raster::Material& m = *d.material;
            if (d.program != current) {
                current = d.program;
                glUseProgram(current->id);
            }
            if (m.double_sided) {
                glDisable(GL_CULL_FACE);
            } else {
                glEnable(GL_CULL_FACE);
                glCullFace(GL_BACK);
            }
            glFrontFace(d.mirrored ? GL_CW : GL_CCW);
            const bool blend = m.alpha_mode == raster::AlphaMode::Blend;
            if (blend) {
                // focal: dst = rgb*a + dst*(1-a), alpha a + dst.a*(1-a); no depth write.
                glEnable(GL_BLEND);
                glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE,
                                    GL_ONE_MINUS_SRC_ALPHA);
                glDepthMask(GL_FALSE);
            } else {
                glDisable(GL_BLEND);
                glDepthMask(GL_TRUE);
            }
            glUniformMatrix4fv(current->world, 1, GL_FALSE, glm::value_ptr(d.world));
            glUniformMatrix3fv(current->normal_matrix, 1, GL_FALSE,
                               glm::value_ptr(d.normal_matrix));
            glUniform4fv(current->base_factor, 1, glm::value_ptr(m.base_color_factor));
            glUniform3fv(current->emissive_factor, 1, glm::value_ptr(m.emissive_factor));
            glUniform1f(current->alpha_cutoff, m.alpha_cutoff);
            glUniform1f(current->metallic, d.metallic);
            glUniform1f(current->shininess, d.shininess);
            glUniform1f(current->spec_norm, d.spec_norm);
            glUniform1f(current->blend, blend ? 1.0f : 0.0f);
            if (d.base_tex) {
                glActiveTexture(GL_TEXTURE0);
                glBindTexture(GL_TEXTURE_2D, d.base_tex);
                glBindSampler(0, d.base_sampler);
                glUniformMatrix3fv(current->base_uv, 1, GL_FALSE,
                                   glm::value_ptr(m.base_color_texture.transform));
            }
            if (d.emissive_tex) {
                glActiveTexture(GL_TEXTURE1);
                glBindTexture(GL_TEXTURE_2D, d.emissive_tex);
                glBindSampler(1, d.emissive_sampler);
                glUniformMatrix3fv(current->emissive_uv, 1, GL_FALSE,
                                   glm::value_ptr(m.emissive_texture.transform));
            }
            glBindVertexArray(d.vao);
            glDrawElements(GL_TRIANGLES, d.index_count, GL_UNSIGNED_INT, nullptr);
        }
        glFinish();
    };

    // Warm-up frames compile llvmpipe's shader variants (JIT); they are not timed.
    for (uint32_t i = 0; i < opt.warmup; ++i)
        renderFrame();
    if (GLenum err = glGetError(); err != GL_NO_ERROR)
        return fail("OpenGL error " + std::to_string(err));
    // Process CPU time over the timed frames: with LP_NUM_THREADS=1 the calling thread (vertex
    // work, binning) and one rasterizer thread can overlap, so it may exceed one core.
    auto cpuMs = [] {
        rusage u{};
        getrusage(RUSAGE_SELF, &u);
        return 1e3 * double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
               1e-3 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
    };
    const double cpu_start = cpuMs();
    const auto wall_start = std::chrono::steady_clock::now();
    std::vector<double> runs;
    for (uint32_t i = 0; i < opt.repeat; ++i) {
        const auto start = std::chrono::steady_clock::now();
        renderFrame();
        runs.push_back(
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count());
    }

    const double cpu_ms = cpuMs() - cpu_start;
    const double wall_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - wall_start)
            .count();

    if (!opt.png.empty()) {
        // Read back linear values (GL bottom-up rows), flip to top-first, write as focal does.
        focal::ImageData img{opt.width, opt.height, 4, {}};
        img.pixels.resize(size_t(opt.width) * opt.height * 4);
        std::vector<float> rows(img.pixels.size());
        if (color_format == GL_SRGB8_ALPHA8) {
            std::vector<uint8_t> bytes(img.pixels.size());
            glReadPixels(0, 0, GLsizei(opt.width), GLsizei(opt.height), GL_RGBA, GL_UNSIGNED_BYTE,
                         bytes.data());
            for (size_t i = 0; i < bytes.size(); ++i)
                rows[i] = i % 4 == 3 ? float(bytes[i]) / 255.0f
                                     : raster::srgbToLinear(float(bytes[i]) / 255.0f);
        } else {
            glReadPixels(0, 0, GLsizei(opt.width), GLsizei(opt.height), GL_RGBA, GL_FLOAT,
                         rows.data());
        }
        const size_t row = size_t(opt.width) * 4;
        for (uint32_t y = 0; y < opt.height; ++y)
            std::memcpy(&img.pixels[y * row], &rows[(opt.height - 1 - y) * row],
                        row * sizeof(float));
        if (raster::Status s = focal::writeImage(opt.png, img); !s.ok())
            return fail(s.message());
    }

    std::vector<double> sorted = runs;
    std::sort(sorted.begin(), sorted.end());
    const size_t n = sorted.size();
    const double median = n % 2 ? sorted[n / 2] : 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]);
    std::printf(
        "{\"renderer\": \"%s\", \"lp_num_threads\": \"%s\", \"scene\": \"%s\", \"width\": %u, "
        "\"height\": %u, \"triangles\": %llu, \"target\": \"%s\", \"programs\": %zu, "
        "\"draws\": %zu, \"time_ms\": {\"total\": %.4f}, \"cores_busy\": %.3f, \"runs\": [",
        renderer, lp_threads ? lp_threads : "", opt.scene.c_str(), opt.width, opt.height,
        static_cast<unsigned long long>(raster::triangleCount(scene)), opt.target.c_str(),
        programs.size(), draws.size(), median, wall_ms > 0.0 ? cpu_ms / wall_ms : 0.0);
    for (size_t i = 0; i < runs.size(); ++i)
        std::printf("%s%.4f", i ? ", " : "", runs[i]);
    std::printf("]}\n");

    OSMesaDestroyContext(ctx);
    return 0;
}
