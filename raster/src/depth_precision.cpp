#include <raster/depth_precision.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace raster {

namespace {

// The largest stored D that is still below the far value 0, as a distance from 0.
double lastStepBelowFar(DepthFormat format) {
    // unorm16: codes are (D + 1) 65535 rounded to nearest, so D >= -0.5/65535 becomes 65535.
    // float: -n/d rounds to -0 only below half the smallest subnormal, 2^-150.
    return format == DepthFormat::Unorm16 ? 0.5 / 65535.0 : std::ldexp(1.0, -150);
}

double invFar(const View& view) {
    return view.zfar > 0.0f ? 1.0 / double(view.zfar) : 0.0;
}

std::string number(float v) {
    char text[32];
    std::snprintf(text, sizeof(text), "%.3g", double(v));
    return text;
}

const char* formatName(DepthFormat f) {
    return f == DepthFormat::Unorm16 ? "unorm16" : "float32";
}

} // namespace

float farthestStorableDistance(const View& view, DepthFormat format) {
    // D = -(1/d - 1/f) / (1/n - 1/f) (camera.h) reaches -e at 1/d = e/n + (1 - e)/f.
    const double e = lastStepBelowFar(format);
    return float(1.0 / (e / double(view.znear) + (1.0 - e) * invFar(view)));
}

float depthResolution(const View& view, DepthFormat format, float d) {
    // dD/dd = (1/d^2) / (1/n - 1/f); the step of D is 1/65535, or one float ulp of D (below
    // |D|: the spacing a rounding can land on), which is 2^-24 |D| or finer.
    const double D = std::fabs(double(depthFromDistance(view, d)));
    double step = 1.0 / 65535.0;
    if (format == DepthFormat::Float32) {
        int exponent = 0;
        std::frexp(D > 0.0 ? D : 0x1p-149, &exponent); // D = m 2^exponent, m in [0.5, 1)
        step = std::ldexp(1.0, std::max(exponent - 24, -149));
    }
    const double dd = double(d);
    return float(step * dd * dd * (1.0 / double(view.znear) - invFar(view)));
}

std::optional<std::string> depthPrecisionProblem(const View& view, DepthFormat format, float near_d,
                                                 float far_d, std::string_view target) {
    if (!(far_d > near_d) || !(far_d > view.znear))
        return std::nullopt;
    const std::string prefix = std::string(formatName(format)) + " " + std::string(target) +
                               " with near " + number(view.znear);
    const float last = farthestStorableDistance(view, format);
    if (far_d >= last)
        return prefix + " stores every distance beyond " + number(last) +
               " as the far plane, but the scene reaches " + number(far_d) + ": surfaces beyond " +
               number(last) + " are not drawn (raise the view's znear" +
               (format == DepthFormat::Unorm16 ? " or use float32 depth)" : ")");
    const float step = depthResolution(view, format, far_d);
    if (step > 0.1f * far_d)
        return prefix + " resolves distances near " + number(far_d) + " only to " + number(step) +
               ": surfaces closer together than that compare equal (raise the view's znear" +
               (format == DepthFormat::Unorm16 ? " or use float32 depth)" : ")");
    return std::nullopt;
}

} // namespace raster
