// Depth precision: how finely each depth format separates distances for a view, and a check
// that the distances a scene spans can be stored at all. Pure functions of the view and the
// format; the CLI turns a failed check into a warning with the numbers (docs/targets.md,
// "Depth precision").
#pragma once

#include <raster/camera.h>
#include <raster/storage.h>

#include <optional>
#include <string>
#include <string_view>

namespace raster {

// The distance from which on every depth stores as the far value D = 0 (the clear value), so
// the strict depth test drops the surface: unorm16 rounds D >= -2^-17 up to code 65535; a float
// D = -n/d only reaches 0 by underflow, beyond n * 2^149 (infinite as a float). With a finite
// far plane f it lies just before f.
float farthestStorableDistance(const View& view, DepthFormat format);

// The step between neighbouring stored values at distance d, in world units: surfaces closer
// together than this along the view axis can compare equal (first drawn wins).
float depthResolution(const View& view, DepthFormat format, float d);

// Whether `format` can hold the distances [near_d, far_d] a scene spans in front of the view
// (from its bounds): nullopt when it can, else one line with the numbers, e.g.
// "unorm16 depth with near 1e-05 stores every distance beyond 1.31 as the far plane, but the
// scene reaches 25.3: surfaces beyond 1.31 are not drawn (raise --near or use float32 depth)".
// Also warns when the resolution at far_d is coarser than a tenth of far_d.
// `target` names the buffer ("depth", "layer depth", "fragment depth").
std::optional<std::string> depthPrecisionProblem(const View& view, DepthFormat format, float near_d,
                                                 float far_d, std::string_view target);

} // namespace raster
