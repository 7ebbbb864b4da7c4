#include "apps/equal_error.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

namespace focal {

double timeOf(const SweepPoint& p, TimeKind kind) {
    return kind == TimeKind::Render ? p.render_ms : p.process_ms;
}

AccumCost accumCostToReach(std::span<const SweepPoint> accum, double target, TimeKind kind) {
    // Usable points, by increasing N (stable: equal N keep their order).
    std::vector<const SweepPoint*> pts;
    for (const SweepPoint& p : accum)
        if (!std::isnan(p.value) && p.samples > 0.0 && std::isfinite(timeOf(p, kind)))
            pts.push_back(&p);
    std::stable_sort(pts.begin(), pts.end(), [](const SweepPoint* a, const SweepPoint* b) {
        return a->samples < b->samples;
    });
    AccumCost c;
    if (pts.empty())
        return c;

    // First crossing of the running maximum.
    constexpr double kNone = -std::numeric_limits<double>::infinity();
    double best = kNone, best_before = kNone;
    size_t i = 0;
    for (; i < pts.size(); ++i) {
        best_before = best;
        best = std::max(best, pts[i]->value);
        if (best >= target)
            break;
    }
    if (i == pts.size()) {
        c.reach = AccumReach::NotReached;
        c.samples = pts.back()->samples;
        c.ms = timeOf(*pts.back(), kind);
        return c;
    }
    const SweepPoint& hi = *pts[i];
    if (i == 0) {
        c.reach = AccumReach::FirstSetting;
        c.samples = hi.samples;
        c.ms = timeOf(hi, kind);
        return c;
    }

    // Interpolate between the bracketing settings: metric linear in log2 N, time linear in N.
    const SweepPoint& lo = *pts[i - 1];
    c.reach = AccumReach::Interpolated;
    c.below = lo.setting;
    c.above = hi.setting;
    const double t_lo = timeOf(lo, kind), t_hi = timeOf(hi, kind);
    if (!std::isfinite(best) || hi.samples == lo.samples) {
        c.samples = hi.samples;
        c.ms = t_hi;
        return c;
    }
    const double f = (target - best_before) / (best - best_before);
    const double log_n =
        std::log2(lo.samples) + f * (std::log2(hi.samples) - std::log2(lo.samples));
    c.samples = std::exp2(log_n);
    c.ms = t_lo + (c.samples - lo.samples) / (hi.samples - lo.samples) * (t_hi - t_lo);
    return c;
}

MethodCost cheapestToReach(std::span<const SweepPoint> method, double target, TimeKind kind) {
    MethodCost c;
    for (size_t i = 0; i < method.size(); ++i) {
        const double t = timeOf(method[i], kind);
        if (std::isnan(method[i].value) || method[i].value < target || !std::isfinite(t))
            continue;
        if (!c.reached || t < c.ms) {
            c.reached = true;
            c.index = i;
            c.ms = t;
        }
    }
    return c;
}

SpeedUp speedUpAtEqualError(std::span<const SweepPoint> accum, std::span<const SweepPoint> method,
                            double target, TimeKind kind) {
    SpeedUp s;
    s.accum = accumCostToReach(accum, target, kind);
    s.method = cheapestToReach(method, target, kind);
    if (s.accum.reach == AccumReach::NoData) {
        s.bound = RatioBound::AccumNoData;
        return s;
    }
    if (!s.method.reached || s.method.ms <= 0.0) {
        s.bound = RatioBound::MethodNotReached;
        return s;
    }
    s.ratio = s.accum.ms / s.method.ms;
    s.bound = s.accum.reach == AccumReach::NotReached     ? RatioBound::AtLeast
              : s.accum.reach == AccumReach::FirstSetting ? RatioBound::AtMost
                                                          : RatioBound::Exact;
    return s;
}

std::string formatSpeedUp(const SpeedUp& s) {
    const char* prefix = "";
    switch (s.bound) {
    case RatioBound::MethodNotReached:
        return "not reached";
    case RatioBound::AccumNoData:
        return "no accum data";
    case RatioBound::AtLeast:
        prefix = ">";
        break;
    case RatioBound::AtMost:
        prefix = "<=";
        break;
    case RatioBound::Exact:
        break;
    }
    char buf[64];
    std::snprintf(buf, sizeof buf, s.ratio >= 10.0 ? "%s%.1fx" : "%s%.2fx", prefix, s.ratio);
    return buf;
}

const char* reachName(AccumReach r) {
    switch (r) {
    case AccumReach::Interpolated:
        return "interpolated";
    case AccumReach::FirstSetting:
        return "first_setting";
    case AccumReach::NotReached:
        return "not_reached";
    case AccumReach::NoData:
        break;
    }
    return "no_data";
}

const char* boundName(RatioBound b) {
    switch (b) {
    case RatioBound::Exact:
        return "exact";
    case RatioBound::AtLeast:
        return "at_least";
    case RatioBound::AtMost:
        return "at_most";
    case RatioBound::MethodNotReached:
        return "method_not_reached";
    case RatioBound::AccumNoData:
        break;
    }
    return "accum_no_data";
}

} // namespace focal
