// Speed-up at equal error (issue 18): how much faster a DOF method reaches an error target than
// `accum` does. Consumes one scene's accum sweep and one method's sweep (caller-owned points:
// setting, times, one metric where higher is better); produces each side's cost of reaching the
// target and their ratio. Pure functions, no I/O: `focal bench` feeds them its rows.
#pragma once

#include <cstddef>
#include <span>
#include <string>

namespace focal {

// One benchmarked setting of a method.
struct SweepPoint {
    std::string setting;   // its label, e.g. "N=16"
    double samples = 0.0;  // accum: lens samples (views) N > 0; unused for other methods
    double render_ms = 0;  // median time of the render itself (scene load excluded)
    double process_ms = 0; // whole `focal render` process (load + render + write); NaN = unknown
    double value = 0.0;    // metric, higher is better; +inf = identical to the reference; NaN =
                           // unknown (the point is ignored)
};

enum class TimeKind { Render, Process };

double timeOf(const SweepPoint& p, TimeKind kind);

// How accum reaches a target on its sweep.
enum class AccumReach {
    Interpolated, // between two settings: samples and ms are interpolated (see below)
    FirstSetting, // the smallest N in the sweep already reaches it: ms is an upper bound
    NotReached,   // no setting reaches it: ms, the largest N's time, is a lower bound
    NoData,       // no usable point
};

struct AccumCost {
    AccumReach reach = AccumReach::NoData;
    double samples = 0.0; // N at which the target is reached (or the bounding setting's N)
    double ms = 0.0;      // accum's time at `samples` (or the bound)
    std::string below;    // Interpolated: the bracketing settings' labels
    std::string above;
};

// accum's cost of reaching `target` (metric >= target). Definition:
// 1. Points with a NaN value, N <= 0 or a non-finite time of `kind` are dropped; the rest are
//    sorted by N.
// 2. Non-monotone curves: the metric is replaced by its running maximum in increasing N,
//    M(N_i) = max_{j<=i} value_j (with more views one can always keep the better, cheaper
//    setting), and the first setting i with M(N_i) >= target is the crossing.
// 3. Interpolation between the bracketing settings i-1 and i: M is linear in log2 N (PSNR gains
//    about the same per doubling of the views, and SSIM is near-linear in log N over a
//    bracket), giving N* = 2^(log2 N_{i-1} + f (log2 N_i - log2 N_{i-1})) with
//    f = (target - M_{i-1}) / (M_i - M_{i-1}); time is linear in N between the two settings'
//    times (accum renders N views: its cost is affine in N), t* = t_{i-1} + (N* - N_{i-1}) /
//    (N_i - N_{i-1}) (t_i - t_{i-1}). When M_i is +inf (identical to the reference) there is
//    nothing to interpolate and N* = N_i, t* = t_i.
// 4. Reached at the first setting: the cost is at most its time (FirstSetting). Never reached:
//    at least the largest N's time (NotReached).
AccumCost accumCostToReach(std::span<const SweepPoint> accum, double target, TimeKind kind);

struct MethodCost {
    bool reached = false;
    size_t index = 0; // into the method's points
    double ms = 0.0;
};

// The cheapest point (smallest time of `kind`; the first on ties) with value >= target.
MethodCost cheapestToReach(std::span<const SweepPoint> method, double target, TimeKind kind);

// What the ratio means.
enum class RatioBound {
    Exact,            // accum's interpolated time / the method's time
    AtLeast,          // accum never reached the target: ratio >= the printed value
    AtMost,           // accum reached it at its smallest N: ratio <= the printed value
    MethodNotReached, // no ratio
    AccumNoData,      // no ratio
};

struct SpeedUp {
    AccumCost accum;
    MethodCost method;
    RatioBound bound = RatioBound::MethodNotReached;
    double ratio = 0.0; // accum.ms / method.ms; meaningful for Exact, AtLeast and AtMost
};

SpeedUp speedUpAtEqualError(std::span<const SweepPoint> accum, std::span<const SweepPoint> method,
                            double target, TimeKind kind);

// "3.2x", ">3.2x", "<=3.2x", "not reached", "no accum data".
std::string formatSpeedUp(const SpeedUp& s);

// The JSON names of the enums: "interpolated", "first_setting", "not_reached", "no_data";
// "exact", "at_least", "at_most", "method_not_reached", "accum_no_data".
const char* reachName(AccumReach r);
const char* boundName(RatioBound b);

} // namespace focal
