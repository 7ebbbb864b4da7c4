#include "apps/false_colour.h"

#include <algorithm>

namespace focal {

glm::vec3 heat(float t) {
    t = std::clamp(t, 0.0f, 1.0f);
    const glm::vec3 stops[5] = {
        {0, 0, 0}, {0.05f, 0.1f, 0.6f}, {0.7f, 0.1f, 0.55f}, {1.0f, 0.55f, 0.05f}, {1, 1, 0.9f}};
    const float x = t * 4.0f;
    const int i = std::min(int(x), 3);
    const glm::vec3 a = stops[i], b = stops[i + 1];
    const float f = x - float(i);
    return a + f * (b - a);
}

glm::vec3 idColour(uint32_t id) {
    // A 32-bit integer mix (the murmur3 finaliser), three bytes as the channels.
    uint32_t h = id + 0x9e3779b9u;
    h ^= h >> 16;
    h *= 0x85ebca6bu;
    h ^= h >> 13;
    h *= 0xc2b2ae35u;
    h ^= h >> 16;
    const auto channel = [&](int shift) {
        return 0.1f + 0.9f * float((h >> shift) & 0xffu) / 255.0f;
    };
    return {channel(0), channel(8), channel(16)};
}

} // namespace focal
