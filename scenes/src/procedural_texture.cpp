#include "procedural_texture.h"

#include "mesh_builder.h"

#include <raster/check.h>

#include <array>
#include <utility>

namespace scenes::detail {
namespace {

struct Glyph {
    char c;
    std::array<uint8_t, 7> rows; // 5 bits per row, bit 4 = leftmost column
};

// A classic 5x7 dot-matrix font (HD44780-style shapes), drawn for this project.
constexpr Glyph kFont[] = {
    {'A', {0x0E, 0x11, 0x11, 0x11, 0x1F, 0x11, 0x11}},
    {'B', {0x1E, 0x11, 0x11, 0x1E, 0x11, 0x11, 0x1E}},
    {'C', {0x0E, 0x11, 0x10, 0x10, 0x10, 0x11, 0x0E}},
    {'D', {0x1C, 0x12, 0x11, 0x11, 0x11, 0x12, 0x1C}},
    {'E', {0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x1F}},
    {'F', {0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x10}},
    {'G', {0x0E, 0x11, 0x10, 0x17, 0x11, 0x11, 0x0F}},
    {'H', {0x11, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11}},
    {'I', {0x0E, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0E}},
    {'J', {0x07, 0x02, 0x02, 0x02, 0x02, 0x12, 0x0C}},
    {'K', {0x11, 0x12, 0x14, 0x18, 0x14, 0x12, 0x11}},
    {'L', {0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x1F}},
    {'M', {0x11, 0x1B, 0x15, 0x15, 0x11, 0x11, 0x11}},
    {'N', {0x11, 0x11, 0x19, 0x15, 0x13, 0x11, 0x11}},
    {'O', {0x0E, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E}},
    {'P', {0x1E, 0x11, 0x11, 0x1E, 0x10, 0x10, 0x10}},
    {'Q', {0x0E, 0x11, 0x11, 0x11, 0x15, 0x12, 0x0D}},
    {'R', {0x1E, 0x11, 0x11, 0x1E, 0x14, 0x12, 0x11}},
    {'S', {0x0F, 0x10, 0x10, 0x0E, 0x01, 0x01, 0x1E}},
    {'T', {0x1F, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04}},
    {'U', {0x11, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E}},
    {'V', {0x11, 0x11, 0x11, 0x11, 0x11, 0x0A, 0x04}},
    {'W', {0x11, 0x11, 0x11, 0x15, 0x15, 0x15, 0x0A}},
    {'X', {0x11, 0x11, 0x0A, 0x04, 0x0A, 0x11, 0x11}},
    {'Y', {0x11, 0x11, 0x11, 0x0A, 0x04, 0x04, 0x04}},
    {'Z', {0x1F, 0x01, 0x02, 0x04, 0x08, 0x10, 0x1F}},
    {'0', {0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E}},
    {'1', {0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E}},
    {'2', {0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F}},
    {'3', {0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E}},
    {'4', {0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02}},
    {'5', {0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E}},
    {'6', {0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E}},
    {'7', {0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08}},
    {'8', {0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E}},
    {'9', {0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C}},
    {' ', {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}},
    {'.', {0x00, 0x00, 0x00, 0x00, 0x00, 0x0C, 0x0C}},
    {',', {0x00, 0x00, 0x00, 0x00, 0x0C, 0x04, 0x08}},
    {':', {0x00, 0x0C, 0x0C, 0x00, 0x0C, 0x0C, 0x00}},
    {';', {0x00, 0x0C, 0x0C, 0x00, 0x0C, 0x04, 0x08}},
    {'!', {0x04, 0x04, 0x04, 0x04, 0x04, 0x00, 0x04}},
    {'?', {0x0E, 0x11, 0x01, 0x02, 0x04, 0x00, 0x04}},
    {'-', {0x00, 0x00, 0x00, 0x1F, 0x00, 0x00, 0x00}},
    {'+', {0x00, 0x04, 0x04, 0x1F, 0x04, 0x04, 0x00}},
    {'/', {0x00, 0x01, 0x02, 0x04, 0x08, 0x10, 0x00}},
    {'\'', {0x0C, 0x04, 0x08, 0x00, 0x00, 0x00, 0x00}},
    {'(', {0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02}},
    {')', {0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08}},
    {'=', {0x00, 0x00, 0x1F, 0x00, 0x1F, 0x00, 0x00}},
    {'#', {0x0A, 0x0A, 0x1F, 0x0A, 0x1F, 0x0A, 0x0A}},
    {'*', {0x00, 0x04, 0x15, 0x0E, 0x15, 0x04, 0x00}},
    {'%', {0x18, 0x19, 0x02, 0x04, 0x08, 0x13, 0x03}},
};

constexpr std::array<uint8_t, 7> kUnknownGlyph = {0x1F, 0x11, 0x11, 0x11, 0x11, 0x11, 0x1F};

const std::array<uint8_t, 7>& glyphRows(char c) {
    if (c >= 'a' && c <= 'z')
        c = static_cast<char>(c - 'a' + 'A');
    for (const Glyph& g : kFont)
        if (g.c == c)
            return g.rows;
    return kUnknownGlyph;
}

uint8_t toByte(float v) {
    const float clamped = v < 0.0f ? 0.0f : (v > 255.0f ? 255.0f : v);
    return static_cast<uint8_t>(clamped + 0.5f);
}

Rgba8 mix(Rgba8 a, Rgba8 b, float t) {
    auto lerp = [t](uint8_t x, uint8_t y) {
        return toByte(static_cast<float>(x) + (static_cast<float>(y) - static_cast<float>(x)) * t);
    };
    return {lerp(a.r, b.r), lerp(a.g, b.g), lerp(a.b, b.b), lerp(a.a, b.a)};
}

raster::Image blankImage(std::string name, uint32_t width, uint32_t height) {
    FOCAL_CHECK(width >= 1 && height >= 1 && width <= 1024 && height <= 1024);
    raster::Image image;
    image.name = std::move(name);
    image.srgb = true;
    image.levels.resize(1);
    image.levels[0].width = width;
    image.levels[0].height = height;
    image.levels[0].rgba8.assign(size_t{width} * height * 4, 0);
    return image;
}

} // namespace

void setPixel(raster::Image& image, int x, int y, Rgba8 color) {
    raster::MipLevel& level = image.levels[0];
    if (x < 0 || y < 0 || x >= static_cast<int>(level.width) || y >= static_cast<int>(level.height))
        return;
    uint8_t* p = &level.rgba8[(static_cast<size_t>(y) * level.width + static_cast<size_t>(x)) * 4];
    p[0] = color.r;
    p[1] = color.g;
    p[2] = color.b;
    p[3] = color.a;
}

void fillRect(raster::Image& image, int x0, int y0, int x1, int y1, Rgba8 color) {
    for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x)
            setPixel(image, x, y, color);
}

raster::Image solidImage(std::string name, uint32_t width, uint32_t height, Rgba8 color) {
    raster::Image image = blankImage(std::move(name), width, height);
    fillRect(image, 0, 0, static_cast<int>(width), static_cast<int>(height), color);
    return image;
}

raster::Image checkerImage(std::string name, uint32_t size, uint32_t cells, Rgba8 a, Rgba8 b) {
    FOCAL_CHECK(cells >= 1 && size % cells == 0);
    raster::Image image = blankImage(std::move(name), size, size);
    const uint32_t cell = size / cells;
    for (uint32_t y = 0; y < size; ++y)
        for (uint32_t x = 0; x < size; ++x)
            setPixel(image, static_cast<int>(x), static_cast<int>(y),
                     ((x / cell) + (y / cell)) % 2 == 0 ? a : b);
    return image;
}

int textWidth(std::string_view text, int scale) {
    if (text.empty())
        return 0;
    return (static_cast<int>(text.size()) * kGlyphAdvance - 1) * scale;
}

void drawText(raster::Image& image, std::string_view text, int x, int y, int scale, Rgba8 color) {
    for (size_t k = 0; k < text.size(); ++k) {
        const std::array<uint8_t, 7>& rows = glyphRows(text[k]);
        const int gx = x + static_cast<int>(k) * kGlyphAdvance * scale;
        for (int row = 0; row < 7; ++row)
            for (int col = 0; col < 5; ++col)
                if (rows[static_cast<size_t>(row)] & (0x10 >> col))
                    fillRect(image, gx + col * scale, y + row * scale, gx + (col + 1) * scale,
                             y + (row + 1) * scale, color);
    }
}

void drawTextCentered(raster::Image& image, std::string_view text, int cx, int y, int scale,
                      Rgba8 color) {
    drawText(image, text, cx - textWidth(text, scale) / 2, y, scale, color);
}

raster::Image leafImage(uint32_t size) {
    raster::Image image = blankImage("leaf", size, size);
    const Rgba8 dark{38, 92, 28, 255};
    const Rgba8 light{96, 158, 52, 255};
    const Rgba8 rib{170, 200, 110, 255};
    const Rgba8 stem{92, 70, 40, 255};
    const float inv = 1.0f / static_cast<float>(size);
    // Leaf coordinates: s in [-1, 1] across, t in [0, 1] from the blade's base to its tip; the
    // blade occupies t in [0.1, 1] of the image height, the stem the bottom tenth.
    auto inside = [](float s, float t) {
        if (t < 0.0f)
            return s > -0.05f && s < 0.05f && t > -0.12f; // stem
        if (t > 1.0f)
            return false;
        // Half-width profile: rounded at the base, pointed at the tip.
        const float w = 0.92f * sinf64(kPi * (0.15f + 0.85f * t)) * (1.05f - 0.45f * t);
        return s > -w && s < w;
    };
    for (uint32_t y = 0; y < size; ++y) {
        for (uint32_t x = 0; x < size; ++x) {
            int covered = 0;
            for (uint32_t sy = 0; sy < 4; ++sy) {
                for (uint32_t sx = 0; sx < 4; ++sx) {
                    const float u =
                        (static_cast<float>(x) + (static_cast<float>(sx) + 0.5f) * 0.25f) * inv;
                    const float v =
                        (static_cast<float>(y) + (static_cast<float>(sy) + 0.5f) * 0.25f) * inv;
                    covered += inside(2.0f * u - 1.0f, (0.9f - v) / 0.88f) ? 1 : 0;
                }
            }
            const float u = (static_cast<float>(x) + 0.5f) * inv;
            const float v = (static_cast<float>(y) + 0.5f) * inv;
            const float s = 2.0f * u - 1.0f;
            const float t = (0.9f - v) / 0.88f;
            Rgba8 c = mix(dark, light, 0.35f + 0.5f * (1.0f - (s < 0.0f ? -s : s)));
            // Side veins: thin lighter lines slanting towards the tip.
            const float vein = t * 9.0f - (s < 0.0f ? -s : s) * 3.0f;
            const float frac = vein - static_cast<float>(static_cast<int>(vein));
            if (t > 0.05f && frac < 0.12f)
                c = mix(c, rib, 0.35f);
            if (s > -0.03f && s < 0.03f)
                c = rib;
            if (t < 0.0f)
                c = stem;
            c.a = toByte(static_cast<float>(covered) * (255.0f / 16.0f));
            setPixel(image, static_cast<int>(x), static_cast<int>(y), c);
        }
    }
    return image;
}

raster::Image barkImage(uint32_t size) {
    raster::Image image = blankImage("bark", size, size);
    const Rgba8 dark{60, 44, 32, 255};
    const Rgba8 light{120, 96, 74, 255};
    for (uint32_t y = 0; y < size; ++y) {
        for (uint32_t x = 0; x < size; ++x) {
            // Streaks along v: a per-column value, wavy in y, plus fine noise.
            const uint32_t column = (x + (hash32(y / 8) % 3)) % size;
            const float streak = hashUnit(column / 3, 1);
            const float grain = hashUnit(x + y * size, 2);
            setPixel(image, static_cast<int>(x), static_cast<int>(y),
                     mix(dark, light, 0.75f * streak + 0.25f * grain));
        }
    }
    return image;
}

raster::Image brickImage(uint32_t size, uint32_t rows) {
    FOCAL_CHECK(rows >= 1 && size % rows == 0);
    raster::Image image = blankImage("brick", size, size);
    const Rgba8 mortar{200, 195, 185, 255};
    const uint32_t course = size / rows;
    const uint32_t brick = course * 2;
    const uint32_t joint = course / 8 > 0 ? course / 8 : 1;
    for (uint32_t y = 0; y < size; ++y) {
        const uint32_t row = y / course;
        const uint32_t shift = (row % 2) * (brick / 2);
        for (uint32_t x = 0; x < size; ++x) {
            const uint32_t xs = (x + shift) % size;
            const uint32_t id = row * 64 + xs / brick;
            const bool is_mortar = (y % course) < joint || (xs % brick) < joint;
            const float tone = hashUnit(id, 3);
            const Rgba8 base{toByte(150.0f + 40.0f * tone), toByte(70.0f + 25.0f * tone),
                             toByte(50.0f + 15.0f * tone), 255};
            const float grain = hashUnit(x + y * size, 4);
            setPixel(image, static_cast<int>(x), static_cast<int>(y),
                     is_mortar ? mortar : mix(base, Rgba8{90, 40, 30, 255}, 0.25f * grain));
        }
    }
    return image;
}

} // namespace scenes::detail
