#include <raster/scene.h>

#include <glm/common.hpp>

namespace raster {

Bounds worldBounds(const Scene& scene) {
    Bounds b;
    for (const Instance& inst : scene.instances) {
        for (const Primitive& prim : scene.meshes[inst.mesh].primitives) {
            for (const glm::vec3& p : prim.positions) {
                const glm::vec3 w = glm::vec3(inst.world * glm::vec4(p, 1.0f));
                if (b.empty) {
                    b.min = b.max = w;
                    b.empty = false;
                } else {
                    b.min = glm::min(b.min, w);
                    b.max = glm::max(b.max, w);
                }
            }
        }
    }
    return b;
}

uint64_t triangleCount(const Scene& scene) {
    uint64_t n = 0;
    for (const Instance& inst : scene.instances)
        for (const Primitive& prim : scene.meshes[inst.mesh].primitives)
            n += prim.indices.size() / 3;
    return n;
}

const Material& materialOf(const Scene& scene, const Primitive& primitive) {
    static const Material kDefault{}; // glTF 2.0 §3.9.7: the default material
    if (primitive.material < 0 || size_t(primitive.material) >= scene.materials.size())
        return kDefault;
    return scene.materials[size_t(primitive.material)];
}

} // namespace raster
