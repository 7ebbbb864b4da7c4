// Looking inside a frame (issue 22): the stage observer a dof::FrameRenderer reports a frame's
// stages to, in the order the frame ran them, each with what it produced (images, counts,
// tables, point sets), the paper section it implements and one paragraph saying what it does;
// and the per-pixel probes that say what made a pixel. `focal steps` and `focal probe` are built
// on it, and an embedder captures the same stages with its own observer.
//
// Consumes nothing by itself: FrameRenderer::render(..., observer) calls it after the frame,
// on the calling thread. Every image, table and probe passed to a callback is borrowed for that
// call only (copy what you keep). Observing costs extra work and memory (a fragment-list render
// of the pinhole view, copies of the method's buffers into float images, the probes) but never
// changes the frame's bytes; a frame rendered without an observer does none of it.
#pragma once

#include <dof/accum.h>
#include <dof/gather.h>
#include <dof/multilayer.h>
#include <dof/multiview.h>

#include <glm/vec2.hpp>

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <variant>
#include <vector>

namespace dof {

// How an image's values are meant to be read (and turned into a picture).
enum class StageImageKind : uint8_t {
    Color,    // 4 channels: linear RGBA (alpha: coverage or opacity, as the caption says)
    Distance, // 1 channel: distance along the view axis (world units); +inf: nothing there
    Signed,   // 1 channel: a signed quantity around 0 (the signed circle of confusion, pixels)
    Count,    // 1 channel: a non-negative count (fragments, triangles)
    Id,       // 1 channel: an identifier (primitive index); -1: none
};

// One image a stage produced: `height` rows of `width` pixels, `channels` floats per pixel,
// `stride` floats from one row to the next. `scale` frame pixels per image pixel (1: frame-sized;
// a tile heat map has the tile size; an N-buffer or mip level 2^level).
struct StageImage {
    std::string name;
    std::string caption;
    StageImageKind kind = StageImageKind::Color;
    uint32_t width = 0, height = 0, channels = 4;
    uint32_t scale = 1;
    const float* pixels = nullptr;
    size_t stride = 0;
};

// Numbers in rows and named columns (layer bounds, the border table T, level sizes).
struct StageTable {
    std::string name;
    std::vector<std::string> columns;
    std::vector<std::vector<double>> rows;
};

// A point set drawn on a plane (lens samples on the aperture, their cells' centroids).
struct StagePoints {
    std::string name;
    std::string x_label, y_label;
    glm::vec2 x_range{-1.0f, 1.0f}, y_range{-1.0f, 1.0f};
    std::vector<glm::vec2> points;
};

struct Stage {
    std::string id;    // "<group>.<name>", unique in a frame, stable across versions
    std::string group; // "raster", "targets", "accum", "gather", "multiview", "multilayer"
    std::string title;
    std::string paper; // the paper section (and equation) implemented; empty for plain raster
    std::string text;  // one paragraph: what the stage consumes, computes and produces
    double ms = -1.0;  // the stage's time in this frame; negative: not timed on its own
    std::vector<std::pair<std::string, double>> counts;
    std::vector<StageImage> images;
    std::vector<StageTable> tables;
    std::vector<StagePoints> plots;
};

// A raster fragment at a probed pixel: one entry of the pinhole view's fragment list (every
// fragment of every triangle there, nearest first; ties by primitive order).
struct ProbeFragment {
    float distance = 0.0f;  // along the view axis
    uint32_t primitive = 0; // submission index of its triangle
    float rgba[4] = {};     // shaded linear colour and opacity
};

// What made one pixel of the frame.
struct PixelProbe {
    uint32_t x = 0, y = 0;
    float rgba[4] = {}; // the frame's result at the pixel (the bytes written to the image)
    std::vector<ProbeFragment> fragments;
    // The method's own record, made by the method's code on this frame's data: accum's views
    // (accum.h), gather's taps (probeGather), multiview's lens rays (probeMultiview),
    // multilayer's reads and slices (Multilayer::probe); nothing for pinhole. Its rgba equals
    // `rgba` bit for bit.
    std::variant<std::monostate, AccumPixelProbe, GatherPixelProbe, MultiviewPixelProbe,
                 MultilayerPixelProbe>
        method;
};

class FrameObserver {
public:
    virtual ~FrameObserver() = default;
    // The pixels to probe in this frame, asked once before the frame (x < width, y < height;
    // others are reported as an error Status by FrameRenderer::render).
    virtual std::span<const glm::uvec2> probePixels() { return {}; }
    // Every stage of the frame, in order, after the frame rendered.
    virtual void stage(const Stage& stage) = 0;
    // Each probed pixel, in probePixels() order, after the stages.
    virtual void probe(const PixelProbe& probe) { (void)probe; }
};

} // namespace dof
