// False colours for pictures of numbers (fragment counts, tile loads, identifiers): linear RGB
// for an image writer. Shared by the target dumps and the stage stepper's pictures.
#pragma once

#include <glm/vec3.hpp>

#include <cstdint>

namespace focal {

// A perceptual-ish heat map: black -> blue -> magenta -> orange -> white over t in [0, 1].
glm::vec3 heat(float t);

// A colour per identifier (a hash of it, well spread for neighbouring ids).
glm::vec3 idColour(uint32_t id);

} // namespace focal
