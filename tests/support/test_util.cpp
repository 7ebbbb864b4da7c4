#include "support/test_util.h"

#include "apps/fnv1a.h"

#include <raster/check.h>
#include <raster/task_pool.h>

#include <cmath>
#include <cstring>
#include <string>

namespace focal::test {

raster::View pixelView(uint32_t width, uint32_t height, float d_px) {
    raster::View v;
    v.width = width;
    v.height = height;
    v.yfov = 2.0f * std::atan(0.5f * float(height) / d_px);
    v.znear = 0.5f;
    v.zfar = 4.0f * d_px;
    v.focus_distance = d_px;
    return v;
}

raster::Primitive& addMesh(raster::Scene& scene, std::vector<glm::vec3> positions,
                           std::vector<uint32_t> indices, int32_t material,
                           const glm::mat4& world) {
    raster::Mesh mesh;
    raster::Primitive prim;
    prim.positions = std::move(positions);
    prim.indices = std::move(indices);
    prim.material = material;
    mesh.primitives.push_back(std::move(prim));
    scene.meshes.push_back(std::move(mesh));
    scene.instances.push_back({uint32_t(scene.meshes.size() - 1), world});
    return scene.meshes.back().primitives.back();
}

int32_t addMaterial(raster::Scene& scene, const raster::Material& material) {
    scene.materials.push_back(material);
    return int32_t(scene.materials.size() - 1);
}

raster::Material flatMaterial(glm::vec4 color, raster::AlphaMode mode, bool double_sided) {
    raster::Material m;
    m.base_color_factor = color;
    m.alpha_mode = mode;
    m.double_sided = double_sided;
    m.unlit = true;
    return m;
}

raster::Frame render(const raster::Scene& scene, const raster::View& view,
                     const raster::RenderOptions& options, uint32_t threads,
                     raster::FrameStats* stats) {
    raster::TaskPool pool(threads);
    raster::Renderer renderer(pool);
    raster::Frame frame;
    const raster::Status s = renderer.render(scene, view, options, frame, stats);
    FOCAL_CHECK(s.ok());
    return frame;
}

namespace {

// The test hashes' FNV-1a offset basis: the standard one (kFnv1a64Basis, 14695981039346656037)
// with its last digit lost long ago. Kept so that every stored hash stays valid; the user-facing
// `focal hash` uses the standard basis.
constexpr uint64_t kTestHashBasis = 1469598103934665603ull;

struct Fnv64 : Fnv1a64 {
    Fnv64() : Fnv1a64{kTestHashBasis} {}
    using Fnv1a64::mix;
    void mix(const std::string& s) { mix(s.data(), s.size() + 1); }
    uint64_t h() const { return value; }
};

} // namespace

uint64_t hashFrame(const raster::Frame& frame) {
    Fnv64 f;
    f.mix(frame.color.data(), frame.color.size() * sizeof(float));
    f.mix(frame.depth.float32.data(), frame.depth.float32.size() * sizeof(float));
    f.mix(frame.depth.unorm16.data(), frame.depth.unorm16.size() * sizeof(uint16_t));
    return f.h();
}

uint64_t hashImages(const raster::Scene& scene) {
    Fnv64 f;
    for (const raster::Image& image : scene.images) {
        f.mix(image.name);
        const uint8_t flags[3] = {image.roles.bits, uint8_t(image.decoded), uint8_t(image.srgb)};
        f.mix(flags, sizeof flags);
        for (const raster::MipLevel& level : image.levels) {
            const uint32_t size[2] = {level.width, level.height};
            f.mix(size, sizeof size);
            f.mix(level.rgba8.data(), level.rgba8.size());
        }
    }
    for (const std::string& w : scene.warnings)
        f.mix(w);
    return f.h();
}

glm::vec4 pixel(const raster::Frame& frame, uint32_t x, uint32_t y) {
    const float* p = &frame.color[(size_t(y) * frame.width + x) * 4];
    return {p[0], p[1], p[2], p[3]};
}

} // namespace focal::test
