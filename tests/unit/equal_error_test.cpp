// Tests for apps/equal_error.h: accum's interpolated cost of reaching an error target, the
// cheapest method setting that reaches it, their ratio, and the edge cases (non-monotone curves,
// targets reached by neither or by accum's smallest N, missing data).
#include "apps/equal_error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

namespace {

using focal::AccumReach;
using focal::RatioBound;
using focal::SweepPoint;
using focal::TimeKind;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

SweepPoint accumAt(double n, double ms, double value, double process_ms = kNaN) {
    return {"N=" + std::to_string(int(n)), n, ms, process_ms, value};
}

SweepPoint at(const char* label, double ms, double value, double process_ms = kNaN) {
    return {label, 0.0, ms, process_ms, value};
}

// PSNR-like curve: +3 dB per doubling of N, time 2 ms per view + 2 ms.
std::vector<SweepPoint> accumCurve() {
    return {accumAt(4, 10, 30, 110), accumAt(8, 18, 33, 118), accumAt(16, 34, 36, 134)};
}

TEST(EqualError, InterpolatesMetricInLog2NAndTimeLinearlyInN) {
    const focal::AccumCost c = focal::accumCostToReach(accumCurve(), 35.0, TimeKind::Render);
    ASSERT_EQ(c.reach, AccumReach::Interpolated);
    EXPECT_EQ(c.below, "N=8");
    EXPECT_EQ(c.above, "N=16");
    // f = (35 - 33) / (36 - 33) = 2/3 of the way from log2 8 = 3 to log2 16 = 4.
    const double n = std::exp2(3.0 + 2.0 / 3.0);
    EXPECT_NEAR(c.samples, n, 1e-9);
    EXPECT_NEAR(c.ms, 18.0 + (n - 8.0) / 8.0 * 16.0, 1e-9);
    // Not linear in N: that would give N = 8 + 2/3 * 8.
    EXPECT_GT(std::fabs(c.samples - (8.0 + 16.0 / 3.0)), 0.5);
}

TEST(EqualError, ATargetOnASettingCostsThatSetting) {
    const focal::AccumCost c = focal::accumCostToReach(accumCurve(), 33.0, TimeKind::Render);
    ASSERT_EQ(c.reach, AccumReach::Interpolated);
    EXPECT_DOUBLE_EQ(c.samples, 8.0);
    EXPECT_DOUBLE_EQ(c.ms, 18.0);
}

TEST(EqualError, ProcessTimeUsesTheSameN) {
    const focal::AccumCost r = focal::accumCostToReach(accumCurve(), 35.0, TimeKind::Render);
    const focal::AccumCost p = focal::accumCostToReach(accumCurve(), 35.0, TimeKind::Process);
    EXPECT_DOUBLE_EQ(r.samples, p.samples);
    EXPECT_NEAR(p.ms, r.ms + 100.0, 1e-9);
}

TEST(EqualError, InputOrderDoesNotMatter) {
    std::vector<SweepPoint> shuffled = accumCurve();
    std::swap(shuffled[0], shuffled[2]);
    const focal::AccumCost a = focal::accumCostToReach(accumCurve(), 35.0, TimeKind::Render);
    const focal::AccumCost b = focal::accumCostToReach(shuffled, 35.0, TimeKind::Render);
    EXPECT_EQ(b.reach, AccumReach::Interpolated);
    EXPECT_DOUBLE_EQ(a.samples, b.samples);
    EXPECT_DOUBLE_EQ(a.ms, b.ms);
}

TEST(EqualError, NonMonotoneCurveUsesTheRunningMaximum) {
    // N = 16 is worse than N = 8: the running maximum stays at 36 until N = 32.
    const std::vector<SweepPoint> curve = {accumAt(4, 10, 30), accumAt(8, 18, 36),
                                           accumAt(16, 34, 34), accumAt(32, 66, 38)};
    const focal::AccumCost early = focal::accumCostToReach(curve, 35.0, TimeKind::Render);
    ASSERT_EQ(early.reach, AccumReach::Interpolated);
    EXPECT_EQ(early.above, "N=8"); // the first crossing, not the dip after it
    const focal::AccumCost c = focal::accumCostToReach(curve, 37.0, TimeKind::Render);
    ASSERT_EQ(c.reach, AccumReach::Interpolated);
    EXPECT_EQ(c.below, "N=16");
    EXPECT_EQ(c.above, "N=32");
    // From the running maximum 36 (not N = 16's own 34): f = (37 - 36) / (38 - 36) = 1/2.
    const double n = std::exp2(4.5);
    EXPECT_NEAR(c.samples, n, 1e-9);
    EXPECT_NEAR(c.ms, 34.0 + (n - 16.0) / 16.0 * 32.0, 1e-9);
}

TEST(EqualError, AccumNotReachedGivesALowerBound) {
    // The largest N's time is the bound, even when listed first and not the largest time.
    const std::vector<SweepPoint> curve = {accumAt(16, 30, 36), accumAt(4, 40, 30),
                                           accumAt(8, 18, 33)};
    const std::vector<SweepPoint> method = {at("a", 5, 41)};
    const focal::SpeedUp s = focal::speedUpAtEqualError(curve, method, 40.0, TimeKind::Render);
    EXPECT_EQ(s.accum.reach, AccumReach::NotReached);
    EXPECT_DOUBLE_EQ(s.accum.samples, 16.0);
    EXPECT_DOUBLE_EQ(s.accum.ms, 30.0);
    EXPECT_EQ(s.bound, RatioBound::AtLeast);
    EXPECT_DOUBLE_EQ(s.ratio, 6.0);
    EXPECT_EQ(focal::formatSpeedUp(s), ">6.00x");
}

TEST(EqualError, ReachedAtTheSmallestNGivesAnUpperBound) {
    const std::vector<SweepPoint> method = {at("a", 4, 31)};
    const focal::SpeedUp s =
        focal::speedUpAtEqualError(accumCurve(), method, 29.0, TimeKind::Render);
    EXPECT_EQ(s.accum.reach, AccumReach::FirstSetting);
    EXPECT_DOUBLE_EQ(s.accum.ms, 10.0);
    EXPECT_EQ(s.bound, RatioBound::AtMost);
    EXPECT_EQ(focal::formatSpeedUp(s), "<=2.50x");
}

TEST(EqualError, CheapestSettingThatReachesTheTarget) {
    const std::vector<SweepPoint> method = {at("slow", 9, 37, 50), at("fails", 2, 34.9, 20),
                                            at("fast", 6, 35.5, 60), at("best", 12, 40, 40)};
    const focal::MethodCost r = focal::cheapestToReach(method, 35.0, TimeKind::Render);
    ASSERT_TRUE(r.reached);
    EXPECT_EQ(r.index, 2u);
    EXPECT_DOUBLE_EQ(r.ms, 6.0);
    // Whole-process time can pick another setting.
    const focal::MethodCost p = focal::cheapestToReach(method, 35.0, TimeKind::Process);
    ASSERT_TRUE(p.reached);
    EXPECT_EQ(p.index, 3u);

    const focal::SpeedUp s =
        focal::speedUpAtEqualError(accumCurve(), method, 35.0, TimeKind::Render);
    EXPECT_EQ(s.bound, RatioBound::Exact);
    const double n = std::exp2(3.0 + 2.0 / 3.0);
    EXPECT_NEAR(s.ratio, (18.0 + (n - 8.0) / 8.0 * 16.0) / 6.0, 1e-9);
    EXPECT_EQ(focal::formatSpeedUp(s), "4.57x");
}

TEST(EqualError, MethodNeverReachingTheTargetHasNoRatio) {
    const std::vector<SweepPoint> method = {at("a", 1, 34.99), at("b", 2, kNaN)};
    const focal::SpeedUp s =
        focal::speedUpAtEqualError(accumCurve(), method, 35.0, TimeKind::Render);
    EXPECT_FALSE(s.method.reached);
    EXPECT_EQ(s.bound, RatioBound::MethodNotReached);
    EXPECT_EQ(focal::formatSpeedUp(s), "not reached");
}

TEST(EqualError, IdenticalToTheReferenceIsNotInterpolated) {
    // +inf (accum with the reference's own N): N* is that setting, not the one below.
    const std::vector<SweepPoint> curve = {accumAt(32, 60, 38), accumAt(64, 120, kInf)};
    const focal::AccumCost c = focal::accumCostToReach(curve, 45.0, TimeKind::Render);
    ASSERT_EQ(c.reach, AccumReach::Interpolated);
    EXPECT_DOUBLE_EQ(c.samples, 64.0);
    EXPECT_DOUBLE_EQ(c.ms, 120.0);
}

TEST(EqualError, UnusablePointsAreIgnored) {
    // NaN metric, N = 0 and a missing process time drop out.
    std::vector<SweepPoint> curve = accumCurve();
    curve.push_back(accumAt(12, 26, kNaN, 126));
    curve.push_back(accumAt(0, 1, 50, 101));
    const focal::AccumCost c = focal::accumCostToReach(curve, 35.0, TimeKind::Render);
    EXPECT_EQ(c.below, "N=8");
    EXPECT_EQ(c.above, "N=16");
    const std::vector<SweepPoint> no_process = {accumAt(8, 18, 40)};
    const std::vector<SweepPoint> method = {at("a", 1, 41, 5)};
    const focal::SpeedUp none =
        focal::speedUpAtEqualError(no_process, method, 35.0, TimeKind::Process);
    EXPECT_EQ(none.accum.reach, AccumReach::NoData);
    EXPECT_EQ(none.bound, RatioBound::AccumNoData);
    EXPECT_EQ(focal::formatSpeedUp(none), "no accum data");
}

TEST(EqualError, SsimTargets) {
    const std::vector<SweepPoint> curve = {accumAt(4, 10, 0.95), accumAt(8, 18, 0.975),
                                           accumAt(16, 34, 0.985)};
    const focal::AccumCost c97 = focal::accumCostToReach(curve, 0.97, TimeKind::Render);
    EXPECT_EQ(c97.above, "N=8");
    EXPECT_NEAR(c97.samples, std::exp2(2.0 + 0.8), 1e-9);
    const focal::AccumCost c98 = focal::accumCostToReach(curve, 0.98, TimeKind::Render);
    EXPECT_EQ(c98.above, "N=16");
    EXPECT_NEAR(c98.samples, std::exp2(3.5), 1e-9);
}

} // namespace
