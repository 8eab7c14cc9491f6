// check_plan's jerk figures on hand-made spans: a straight-line S-curve whose jerk is exactly
// the limit, and a trapezoid whose acceleration steps at its joins. The profile uses 1024 Hz
// and 2^-10 mm per LSB so that every figure is a binary fraction and the boundaries are exact.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <vector>

#include "pathstream/host/planner.hpp"
#include "pathstream/machine/device_setup.hpp"
#include "pathstream/tick_cubic.hpp"

using namespace pathstream;
using namespace pathstream::host;

namespace {

constexpr double kLsb = 1.0 / 1024;  // mm
constexpr double kHz = 1024;

MachineProfile profile(double max_jerk) {
    MachineProfile p;
    p.mm_per_lsb = kLsb;
    p.tick_hz = kHz;
    for (const char* name : {"x", "y"}) {
        AxisLimits a;
        a.name = name;
        a.max_velocity = 1000;       // 1000 LSB/tick
        a.max_acceleration = 10000;  // ~9.5 LSB/tick^2
        a.max_jerk = max_jerk;
        p.axes.push_back(a);
    }
    return p;
}

// An 8-tick Hermite span on both axes (y moves half as far), validated by the core.
CoreSpan hermite(std::int64_t p0, std::int64_t p1, std::int64_t t0, std::int64_t t1) {
    CoreSpan s;
    s.basis = Basis::kHermite;
    s.ticks = 8;
    REQUIRE(make_span_timing(Basis::kHermite, 8, s.timing) == Status::kOk);
    for (std::int64_t share : {2, 1}) {
        const std::array<std::int32_t, 4> c = {
            static_cast<std::int32_t>(p0 * share / 2), static_cast<std::int32_t>(p1 * share / 2),
            static_cast<std::int32_t>(t0 * share / 2), static_cast<std::int32_t>(t1 * share / 2)};
        s.control.push_back(c);
        const std::int32_t control[4] = {c[0], c[1], c[2], c[3]};
        TickCubic cubic;
        REQUIRE(make_tick_cubic(Basis::kHermite, control, s.timing, cubic) == Status::kOk);
        s.cubic.push_back(cubic);
    }
    return s;
}

// Spans of 8 ticks following per-span jerks (units of j = 3/256 LSB/tick^3, so that every
// boundary has whole positions and tangents) or, for `trapezoid`, per-span accelerations in
// units of 1/32 LSB/tick^2 with no jerk inside. Positions and tangents stay even so the half
// shares of y are exact.
Plan plan_of(const std::vector<int>& steps, bool trapezoid) {
    Plan plan;
    std::int64_t p = 0, tangent = 0, a32 = 0;  // x: position, T = 8v, 32a
    for (int step : steps) {
        std::int64_t dp = 0, dt = 0;
        if (trapezoid) {
            // Constant a = step/32 over 8 ticks: dp = 8v + 32a = T + step, dT = 64a = 2 step.
            dp = tangent + step;
            dt = 2 * step;
        } else {
            dp = tangent + a32 + step;
            dt = 2 * a32 + 3 * step;
            a32 += 3 * step;
        }
        plan.spans.push_back(hermite(2 * p, 2 * (p + dp), 2 * tangent, 2 * (tangent + dt)));
        p += dp;
        tangent += dt;
        plan.total_ticks += 8;
    }
    REQUIRE(tangent == 0);
    REQUIRE(a32 == 0);
    return plan;
}

const std::vector<int> kSCurve = {1, 1,  1,  1,  0,  0, -1, -1, -1, -1, 0, 0,
                                  0, -1, -1, -1, -1, 0, 0,  1,  1,  1,  1};
const std::vector<int> kTrapezoid = {1, 1, 1, 1, 0, 0, -1, -1, -1, -1};

}  // namespace

TEST_CASE("check_plan: an S-curve at exactly the jerk limit is within it",
          "[planner][check][jerk]") {
    // x doubles every value of plan_of: j = 2 * 3/256 LSB/tick^3 = 3/128 * 1024^3 / 1024 mm/s^3
    // = 24576 mm/s^3 exactly; y, half of it, 12288.
    const Plan plan = plan_of(kSCurve, false);
    const std::vector<BezierSegment> none;
    {
        const PlanCheck c = check_plan(plan, none, profile(24576));
        CHECK(c.jerk_limited);
        CHECK(c.axis_jerk_lsb[0] == 3.0 / 128);
        CHECK(c.axis_jerk[0] == 24576);
        CHECK(c.axis_jerk[1] == 12288);
        CHECK(c.axis_jerk_fraction_exact[0] == 1);
        CHECK(c.axis_jerk_fraction_exact[1] == 0.5);
        CHECK(c.max_jerk_fraction_exact == 1);
        // Continuous acceleration everywhere, from rest and back to it.
        CHECK(c.axis_join_acceleration_step_lsb[0] == 0);
        CHECK(c.max_join_acceleration_step_fraction == 0);
        CHECK(c.within_limits);
    }
    {
        const PlanCheck c = check_plan(plan, none, profile(24575));
        CHECK(c.max_jerk_fraction_exact > 1);
        CHECK_FALSE(c.within_limits);
    }
    {
        // No max_jerk: the figures are there, the check does not fail on them.
        const PlanCheck c = check_plan(plan, none, profile(0));
        CHECK_FALSE(c.jerk_limited);
        CHECK(c.axis_jerk[0] == 24576);
        CHECK(c.axis_jerk_fraction_exact[0] == 0);
        CHECK(c.within_limits);
    }
}

TEST_CASE("check_plan: a trapezoid's acceleration steps fail a jerk limit",
          "[planner][check][jerk]") {
    // x: a = 2/32 = 1/16 LSB/tick^2 on the ramps; the steps at the joins (rest -> ramp, ramp ->
    // cruise, ...) are 1/16 LSB/tick^2 = 1/16 * 1024^2 / 1024 = 64 mm/s^2; no jerk inside.
    const Plan plan = plan_of(kTrapezoid, true);
    const std::vector<BezierSegment> none;
    const PlanCheck free = check_plan(plan, none, profile(0));
    CHECK(free.within_limits);
    CHECK(free.axis_jerk[0] == 0);
    CHECK(free.axis_join_acceleration_step_lsb[0] == 1.0 / 16);
    CHECK(free.axis_join_acceleration_step[0] == 64);
    CHECK(free.axis_join_acceleration_step[1] == 32);
    // One tick of jerk J is J * 1024^-3 * 1024 LSB/tick^2: the step 1/16 is exactly one tick of
    // J = 65536 mm/s^3.
    const PlanCheck at = check_plan(plan, none, profile(65536));
    CHECK(at.max_join_acceleration_step_fraction == 1);
    CHECK(at.within_limits);
    const PlanCheck tight = check_plan(plan, none, profile(24576));
    CHECK(tight.axis_join_acceleration_step_fraction[0] == Approx(65536.0 / 24576));
    CHECK(tight.max_jerk_fraction_exact == 0);
    CHECK_FALSE(tight.within_limits);
}

TEST_CASE("check_plan: a pause joins with rest on both sides", "[planner][check][jerk]") {
    // Two trapezoids back to back: the first ends decelerating at 1/16 LSB/tick^2, the second
    // starts accelerating at 1/16, so their join steps by 1/8. With a pause between them each
    // side joins with rest instead: 1/16 at most.
    const Plan one = plan_of(kTrapezoid, true);
    Plan two = one;
    const std::size_t first = one.spans.size();
    const Plan second = plan_of(kTrapezoid, true);
    for (CoreSpan s : second.spans) {
        const CoreSpan& last = two.spans[first - 1];
        std::int64_t ends[2];
        for (std::size_t a = 0; a < 2; ++a) ends[a] = last.control[a][1];
        CoreSpan moved = hermite(ends[0] + s.control[0][0], ends[0] + s.control[0][1],
                                 s.control[0][2], s.control[0][3]);
        REQUIRE(moved.control[1][0] == ends[1] + s.control[1][0]);
        two.spans.push_back(moved);
    }
    const std::vector<BezierSegment> none;
    CHECK(check_plan(two, none, profile(0)).axis_join_acceleration_step_lsb[0] == 1.0 / 8);
    two.spans[first - 1].pause_after = true;
    CHECK(check_plan(two, none, profile(0)).axis_join_acceleration_step_lsb[0] == 1.0 / 16);
}

TEST_CASE("device_limits: max_jerk in units of 100 LSB/s^3, 0 without one", "[device][jerk]") {
    MachineProfile p = profile(0);
    p.mm_per_lsb = 0.001;
    p.tick_hz = 1000;
    p.axes[0].max_jerk = 12345.6;  // 12,345,600 LSB/s^3: 123,456 units
    DeviceLimitsLsb l = device_limits(p);
    CHECK(l.max_jerk == std::vector<std::uint32_t>{123456, 0});
    p.axes[0].max_jerk = 12345.601;  // rounded up: the device allows what the planner may use
    CHECK(device_limits(p).max_jerk[0] == 123457);
    p.axes[1].max_jerk = 1e10;  // 1e13 LSB/s^3: over 32 bits of units
    CHECK_THROWS_WITH(device_limits(p), Catch::Contains("axis y max_jerk"));
}
