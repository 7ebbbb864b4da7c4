// Scene model: focal's own description of what to render. Produced by glTF import
// (gltf_import.h) and the built-in scene generators (scenes/); consumed by geometry.
// Plain data owned by the Scene; arrays refer to each other by index, never by pointer.
#pragma once

#include <raster/texture.h>

#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace raster {

enum class AlphaMode : uint8_t { Opaque, Mask, Blend };

// A texture binding: which image, how to sample it, which UV set, and KHR_texture_transform
// folded into one 3x3 matrix (uv' = transform * (u, v, 1)).
struct TextureRef {
    int32_t image = -1;   // index into Scene::images, -1 = none
    int32_t sampler = -1; // index into Scene::samplers, -1 = default sampler
    uint32_t texcoord = 0;
    glm::mat3 transform{1.0f};
};

// glTF 2.0 metallic-roughness material, the parts focal shades with.
struct Material {
    std::string name;
    glm::vec4 base_color_factor{1.0f}; // linear RGBA
    TextureRef base_color_texture;     // sRGB
    glm::vec3 emissive_factor{0.0f};   // linear RGB
    TextureRef emissive_texture;       // sRGB
    float metallic_factor = 1.0f;
    float roughness_factor = 1.0f;
    AlphaMode alpha_mode = AlphaMode::Opaque;
    float alpha_cutoff = 0.5f;
    bool double_sided = false;
    bool unlit = false; // KHR_materials_unlit
};

// One triangle list. Optional attribute arrays are empty or have positions.size() entries.
struct Primitive {
    std::vector<glm::vec3> positions;
    std::vector<glm::vec3> normals;    // empty: geometry uses the face normal
    std::vector<glm::vec2> texcoords0; // empty: uv = (0,0)
    std::vector<glm::vec4> colors;     // linear RGBA; empty: white
    std::vector<uint32_t> indices;     // 3 per triangle, each < positions.size()
    int32_t material = -1;             // index into Scene::materials, -1 = glTF default material
};

struct Mesh {
    std::string name;
    std::vector<Primitive> primitives;
};

// A mesh placed in the world by a node (its world matrix is the product along the node path).
struct Instance {
    uint32_t mesh = 0;
    glm::mat4 world{1.0f};
};

// glTF perspective camera placed by its node: looks down -Z of `world`, +Y up.
struct Camera {
    std::string name;
    glm::mat4 world{1.0f};
    float yfov = 0.8f;         // radians
    float aspect_ratio = 0.0f; // 0: take it from the image size
    float znear = 0.1f;
    float zfar = 0.0f; // 0: infinite projection
};

// KHR_lights_punctual.
struct Light {
    enum class Type : uint8_t { Directional, Point, Spot };
    std::string name;
    Type type = Type::Directional;
    glm::vec3 color{1.0f}; // linear RGB
    float intensity = 1.0f;
    float range = 0.0f; // 0: infinite
    glm::vec3 position{0.0f};
    glm::vec3 direction{0.0f, 0.0f, -1.0f}; // world space, the way the light travels
    float inner_cone_angle = 0.0f;
    float outer_cone_angle = 0.7853982f;
};

// A lens the scene suggests (built-in scenes carry one; glTF files do not).
struct LensHint {
    float aperture_radius = 0.0f; // world units
    float focus_distance = 1.0f;  // world units along the view axis
};

struct Bounds {
    glm::vec3 min{0.0f};
    glm::vec3 max{0.0f};
    bool empty = true;
};

struct Scene {
    std::string source; // file path or builtin:NAME, for messages
    std::vector<Mesh> meshes;
    std::vector<Material> materials;
    std::vector<Image> images;
    std::vector<Sampler> samplers;
    std::vector<Instance> instances;
    std::vector<Camera> cameras;
    std::vector<Light> lights;
    std::vector<std::string> extensions_used;
    std::vector<std::string> extensions_required;
    glm::vec3 background{0.0f}; // linear RGB behind everything
    std::optional<LensHint> lens;
    std::vector<std::string> warnings; // non-fatal findings from import
};

// World-space bounds of every instanced vertex.
Bounds worldBounds(const Scene& scene);
// Triangles drawn (instances times their meshes' triangles).
uint64_t triangleCount(const Scene& scene);
// The material a primitive uses (the glTF default material when it has none).
const Material& materialOf(const Scene& scene, const Primitive& primitive);

} // namespace raster
