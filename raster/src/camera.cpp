#include <raster/camera.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <bit>
#include <cmath>

namespace raster {

float focalLengthPx(const View& view) {
    return 0.5f * float(view.height) / std::tan(0.5f * view.yfov);
}

glm::mat4 viewMatrix(const View& view) {
    const glm::vec3 eye = view.eye + view.lens_offset.x * view.right + view.lens_offset.y * view.up;
    const glm::vec3 back = -view.forward;
    glm::mat4 m(1.0f); // column-major: m[col][row]
    m[0][0] = view.right.x, m[1][0] = view.right.y, m[2][0] = view.right.z;
    m[0][1] = view.up.x, m[1][1] = view.up.y, m[2][1] = view.up.z;
    m[0][2] = back.x, m[1][2] = back.y, m[2][2] = back.z;
    m[3][0] = -glm::dot(view.right, eye);
    m[3][1] = -glm::dot(view.up, eye);
    m[3][2] = -glm::dot(back, eye);
    return m;
}

glm::mat4 projectionMatrix(const View& view) {
    // With d = -z_cam, the pinhole maps camera point (x, y) to pixel offsets f*x/d right and
    // f*y/d up of the centre. The eye moved by o keeps the plane d = d_f fixed by adding
    // f*o/d_f (an off-axis frustum); pixel_shift adds a constant (y in rows, so subtracted).
    const float f = focalLengthPx(view);
    const float half_w = 0.5f * float(view.width);
    const float half_h = 0.5f * float(view.height);
    const float df = view.focus_distance;
    const float shift_x = (f * view.lens_offset.x / df + view.pixel_shift.x) / half_w;
    const float shift_y = (f * view.lens_offset.y / df - view.pixel_shift.y) / half_h;
    const float n = view.znear;
    glm::mat4 p(0.0f);
    p[0][0] = f / half_w;
    p[1][1] = f / half_h;
    p[2][0] = -shift_x; // x_clip += shift_x * d, and d = -z_cam
    p[2][1] = -shift_y;
    p[2][3] = -1.0f; // w_clip = d
    if (view.zfar > 0.0f) {
        // z_clip = n (d - F) / (F - n), so z_clip / w_clip = -(1/d - 1/F) / (1/n - 1/F).
        const float k = n / (view.zfar - n);
        p[2][2] = -k;
        p[3][2] = -view.zfar * k;
    } else {
        p[3][2] = -n; // z_clip = -n: D = -n/d, with one rounding (no 1 - n/d cancellation)
    }
    return p;
}

float depthFromDistance(const View& view, float d) {
    if (view.zfar > 0.0f)
        return -(1.0f / d - 1.0f / view.zfar) / (1.0f / view.znear - 1.0f / view.zfar);
    return -view.znear / d;
}

namespace {
// Floats (no NaN) as integers in the same order; -0 and +0 share a key.
int32_t orderedKey(float v) {
    const int32_t bits = std::bit_cast<int32_t>(v);
    return bits >= 0 ? bits : -(bits & 0x7fffffff);
}
float fromOrderedKey(int32_t key) {
    return key >= 0 ? std::bit_cast<float>(key)
                    : std::bit_cast<float>(uint32_t(-key) | 0x80000000u);
}
} // namespace

float firstDepthAtDistance(const View& view, float d) {
    // Bisection over every float from -inf to 1 for the first one that reaches d.
    int32_t lo = orderedKey(-INFINITY);
    int32_t hi = orderedKey(1.0f);
    if (!(distanceFromDepth(view, 1.0f) >= d))
        return 1.0f;
    while (lo < hi) { // invariant: the answer's key lies in [lo, hi]
        const int32_t mid = int32_t(lo + (int64_t(hi) - lo) / 2); // hi - lo can exceed int32
        if (distanceFromDepth(view, fromOrderedKey(mid)) >= d)
            hi = mid;
        else
            lo = mid + 1;
    }
    return fromOrderedKey(lo);
}

View viewFromCamera(const Camera& camera, uint32_t width, uint32_t height) {
    View v;
    v.eye = glm::vec3(camera.world[3]);
    v.right = glm::normalize(glm::vec3(camera.world[0]));
    v.up = glm::normalize(glm::vec3(camera.world[1]));
    v.forward = -glm::normalize(glm::vec3(camera.world[2]));
    v.yfov = camera.yfov;
    v.width = width;
    v.height = height;
    v.znear = camera.znear;
    v.zfar = camera.zfar;
    v.focus_distance = 1.0f;
    return v;
}

View viewFramingBounds(const Bounds& bounds, uint32_t width, uint32_t height) {
    const glm::vec3 centre = 0.5f * (bounds.min + bounds.max);
    const float radius = std::max(0.5f * glm::length(bounds.max - bounds.min), 1e-3f);
    const float yfov = 0.7853982f; // 45 degrees
    const float aspect = float(width) / float(height);
    const float half_fov = std::min(0.5f * yfov, std::atan(std::tan(0.5f * yfov) * aspect));
    const float dist = 1.05f * radius / std::sin(half_fov);
    const glm::vec3 dir = glm::normalize(glm::vec3(0.0f, 0.35f, 1.0f));
    return viewLookAt(centre + dist * dir, centre, glm::vec3(0.0f, 1.0f, 0.0f), yfov, width, height,
                      std::max(dist - 2.0f * radius, 1e-3f * dist), dist + 2.0f * radius);
}

View viewLookAt(glm::vec3 eye, glm::vec3 target, glm::vec3 up, float yfov, uint32_t width,
                uint32_t height, float znear, float zfar) {
    View v;
    v.eye = eye;
    v.forward = glm::normalize(target - eye);
    v.right = glm::normalize(glm::cross(v.forward, up));
    v.up = glm::cross(v.right, v.forward);
    v.yfov = yfov;
    v.width = width;
    v.height = height;
    v.znear = znear;
    v.zfar = zfar;
    v.focus_distance = glm::length(target - eye);
    return v;
}

} // namespace raster
