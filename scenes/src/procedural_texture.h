// Procedural textures for the built-in scenes (private to scenes/): checkers, a 5x7 bitmap font
// to write text into an image, a leaf with an alpha mask, and a few surface patterns.
// Produces raster::Image values with level 0 only (8-bit sRGB RGBA, row 0 at the top);
// addImage() in mesh_builder.h builds the mip chain when the image joins a Scene.
#pragma once

#include <raster/texture.h>

#include <cstdint>
#include <string>
#include <string_view>

namespace scenes::detail {

// An sRGB-encoded 8-bit colour, as stored in the image.
struct Rgba8 {
    uint8_t r = 0, g = 0, b = 0, a = 255;
};

raster::Image solidImage(std::string name, uint32_t width, uint32_t height, Rgba8 color);

void setPixel(raster::Image& image, int x, int y, Rgba8 color);
// Fills the rectangle [x0, x1) x [y0, y1), clipped to the image.
void fillRect(raster::Image& image, int x0, int y0, int x1, int y1, Rgba8 color);

// A size x size checker with `cells` squares per side (cells divides size), starting with `a` at
// the top-left.
raster::Image checkerImage(std::string name, uint32_t size, uint32_t cells, Rgba8 a, Rgba8 b);

// Glyphs are 5x7 font pixels on a 6x8 advance; supported: A-Z (lower case maps to upper), 0-9,
// space and . , : ; ! ? - + / ' ( ) = # * %. Anything else draws a hollow box.
inline constexpr int kGlyphAdvance = 6;
inline constexpr int kGlyphHeight = 8;
// Width in texels of `text` drawn with `scale` texels per font pixel (no trailing gap).
int textWidth(std::string_view text, int scale);
// Draws `text` with its top-left corner at (x, y); each font pixel is a scale x scale block.
void drawText(raster::Image& image, std::string_view text, int x, int y, int scale, Rgba8 color);
// Draws `text` centred horizontally on column cx.
void drawTextCentered(raster::Image& image, std::string_view text, int cx, int y, int scale,
                      Rgba8 color);

// A leaf: green blade with a lighter midrib and a stem, alpha 255 inside and 0 outside (edges
// 4x4 supersampled). The stem is at the bottom centre (uv (0.5, 1)), the tip at the top.
raster::Image leafImage(uint32_t size);

// Bark-like vertical streaks for branches (u around, v along), tileable.
raster::Image barkImage(uint32_t size);

// A brick wall with `rows` courses, tileable.
raster::Image brickImage(uint32_t size, uint32_t rows);

} // namespace scenes::detail
