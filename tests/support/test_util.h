// Helpers shared by the tests: small scenes built in code, a pixel-exact view, frame hashing.
#pragma once

#include <raster/camera.h>
#include <raster/frame.h>
#include <raster/renderer.h>
#include <raster/scene.h>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace focal::test {

// A W x H view looking down -z from the origin whose plane z = -d_px maps world (x, y) to pixel
// (W/2 + x, H/2 - y): one world unit is one pixel there. yfov is chosen so f_px = d_px.
raster::View pixelView(uint32_t width, uint32_t height, float d_px);

// Appends a mesh with one primitive and an identity instance; returns the primitive.
raster::Primitive& addMesh(raster::Scene& scene, std::vector<glm::vec3> positions,
                           std::vector<uint32_t> indices, int32_t material = -1,
                           const glm::mat4& world = glm::mat4(1.0f));

// Appends a material and returns its index.
int32_t addMaterial(raster::Scene& scene, const raster::Material& material);

// An unlit material of one colour (alpha_mode and double_sided as given).
raster::Material flatMaterial(glm::vec4 color, raster::AlphaMode mode = raster::AlphaMode::Opaque,
                              bool double_sided = true);

// Renders with `threads` workers and returns the frame (CHECKs success).
raster::Frame render(const raster::Scene& scene, const raster::View& view,
                     const raster::RenderOptions& options = {}, uint32_t threads = 0,
                     raster::FrameStats* stats = nullptr);

// FNV-1a 64 over the colour floats and the stored depth values.
uint64_t hashFrame(const raster::Frame& frame);

// FNV-1a 64 over every image of the scene (name, roles, decoded, sRGB, each level's size and
// texels) and the import warnings, in order.
uint64_t hashImages(const raster::Scene& scene);

glm::vec4 pixel(const raster::Frame& frame, uint32_t x, uint32_t y);

} // namespace focal::test
