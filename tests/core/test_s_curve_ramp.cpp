// The S-curve ramp of the device's own moves under a jerk limit (s_curve_ramp.hpp) and the
// AxisMove built on it: the ramp's knots are exact (their sum is the cruise tangent, every step
// within the jerk and every value within the acceleration), and a jerk-limited move takes close
// to the time-optimal S-curve's ticks instead of the J/2 * 1 tick ramps it replaced.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <random>

#include "core/property_settings.hpp"
#include "core/s_curve_reference.hpp"
#include "pathstream/device/homing.hpp"
#include "pathstream/device/s_curve_ramp.hpp"

using namespace pathstream;
using namespace pathstream::device;

TEST_CASE(
    "SCurveRamp: the knots sum to the cruise tangent, step by at most `step`, stay within `peak`",
    "[device][jog][jerk]") {
    std::mt19937_64 rng(test::property_seed());
    const auto pick = [&](std::int64_t lo, std::int64_t hi) {
        return std::uniform_int_distribution<std::int64_t>(lo, hi)(rng);
    };
    for (int c = 0; c < 20000; ++c) {
        SCurveRamp r;
        r.step = 6 * pick(1, c % 3 == 0 ? 3 : 200);
        r.peak = 6 * pick(1, c % 5 == 0 ? 5 : 2000);
        const std::int64_t cruise = 6 * pick(1, c % 2 == 0 ? 50 : 200000);
        r.plan(cruise);
        INFO("step " << r.step << " peak " << r.peak << " cruise " << cruise);
        REQUIRE(r.at(0) == 0);
        REQUIRE(r.at(r.spans) == 0);
        std::int64_t sum = 0, previous = 0;
        std::uint32_t broken = 0;  // the first knot that breaks a rule (0: none)
        for (std::uint32_t i = 1; i <= r.spans && broken == 0; ++i) {
            const std::int64_t a = r.at(i);
            if (a % 6 != 0 || a < 0 || a > r.peak || std::llabs(a - previous) > r.step) broken = i;
            sum += a;
            previous = a;
        }
        REQUIRE(broken == 0);
        REQUIRE(sum == cruise);
    }
}

namespace {

constexpr unsigned kAxes = 2;

}  // namespace

TEST_CASE("AxisMove under a jerk limit: S-curves within 1.4x of the optimal S-curve's ticks",
          "[device][jog][jerk]") {
    // The pen plotter in LSB (1 um, 1 kHz, 3000 mm/s^2, 250 mm/s) with 10^5 and 10^6 mm/s^3,
    // a 100 mm/s jog of 10 and 100 mm: 0.220 / 1.102 s at 10^5 and 0.158 / 1.071 s at 10^6; the
    // ramps that accelerated at J/2 * 1 tick took 1.200 / 3.600 s and 0.336 / 1.200 s.
    for (const std::uint32_t max_jerk : {1000000u, 10000000u}) {  // units of 100 LSB/s^3
        for (const std::int64_t distance : {10000, -100000}) {
            MotionLimits<kAxes> l;
            l.tick_hz = 1000;
            for (auto& a : l.axis) {
                a.max_velocity = 250000;
                a.max_acceleration = 3000000;
                a.max_jerk = max_jerk;
            }
            const Lsb start[kAxes] = {5, -5};
            AxisMove<kAxes> move;
            REQUIRE(move.plan(start, 1, distance, 100000, l) == Status::kOk);
            std::uint64_t ticks = 0;
            WireSpan w;
            while (move.next(w)) ticks += w.ticks;
            const double optimum = test::s_curve_seconds(static_cast<double>(std::llabs(distance)),
                                                         100000, 3000000, max_jerk * 100.0) *
                                   1000;
            INFO("max_jerk " << max_jerk << " distance " << distance << ": " << ticks
                             << " ticks, optimum " << optimum);
            CHECK(ticks <= 1.4 * optimum);
            CHECK(w.end[1] == start[1] + distance);
        }
    }
}

TEST_CASE("AxisMove under a jerk limit: never faster than the requested velocity",
          "[device][jog][jerk]") {
    // A homing latch defines zero at its speed: the ramps and the cruise stay at or under the
    // requested velocity however slow (the spans lengthen so that a cruise tangent of 6 LSB
    // fits under it). The creep span at the end (rest to rest) is bounded by the axis's limit.
    for (const std::uint32_t velocity : {40u, 100u, 1000u, 7000u, 100000u}) {
        MotionLimits<kAxes> l;
        l.tick_hz = 1000;
        for (auto& a : l.axis) {
            a.max_velocity = 250000;
            a.max_acceleration = 3000000;
            a.max_jerk = 1000000;
        }
        const Lsb start[kAxes] = {0, 0};
        AxisMove<kAxes> move;
        REQUIRE(move.plan(start, 0, 20000, velocity, l) == Status::kOk);
        WireSpan w;
        Lsb at = 0;
        int spans = 0;
        while (move.next(w)) {
            const std::int64_t chord = w.end[0] - at;
            at = w.end[0];
            ++spans;
            const bool creep = w.start_tangent[0] == 0 && w.end_tangent[0] == 0;
            if (creep) continue;
            INFO("velocity " << velocity << " span " << spans << " of " << w.ticks
                             << " ticks, tangents " << w.start_tangent[0] << " " << w.end_tangent[0]
                             << ", chord " << chord);
            // Monotone inside each span (ramps, cruise): the knots carry the peak.
            CHECK(std::uint64_t(
                      std::max(std::llabs(w.start_tangent[0]), std::llabs(w.end_tangent[0]))) *
                      l.tick_hz <=
                  std::uint64_t{velocity} * w.ticks);
        }
        CHECK(at == 20000);
        CHECK(spans > 1);
    }
}

TEST_CASE(
    "AxisMove under a jerk limit, random limits: planned or refused, and every span passes the "
    "device's rules",
    "[device][jog][jerk]") {
    // Limits over their whole ranges (extremes included): plan() either refuses (kBadLimits) or
    // gives spans that pass the exact limit check, the jerk inside each span and the steps at
    // every join (rest at both ends), and end exactly on the target.
    std::mt19937_64 rng(test::property_seed());
    const auto log_pick = [&](double lo, double hi) {
        return std::exp(std::uniform_real_distribution<double>(std::log(lo), std::log(hi))(rng));
    };
    int planned = 0;
    for (int c = 0; c < 400; ++c) {
        MotionLimits<kAxes> l;
        l.tick_hz = static_cast<std::uint32_t>(log_pick(1, 100000));
        for (auto& a : l.axis) {
            a.max_velocity = static_cast<std::uint32_t>(log_pick(1, 4e9));
            a.max_acceleration = static_cast<std::uint32_t>(log_pick(1, 4e9));
            a.max_jerk = static_cast<std::uint32_t>(log_pick(1, 4e9));
        }
        const auto distance = static_cast<std::int64_t>(log_pick(1, 2.6e8)) * (c % 2 == 0 ? 1 : -1);
        const auto velocity = static_cast<std::uint32_t>(log_pick(1, 4e9));
        const Lsb start[kAxes] = {static_cast<Lsb>(-distance / 2), 7};
        AxisMove<kAxes> move;
        const Status s = move.plan(start, 0, distance, velocity, l);
        INFO("case " << c << " hz " << l.tick_hz << " v " << l.axis[0].max_velocity << " a "
                     << l.axis[0].max_acceleration << " j " << l.axis[0].max_jerk << " distance "
                     << distance << " velocity " << velocity);
        if (s != Status::kOk) {
            CHECK(s == Status::kBadLimits);
            continue;
        }
        ++planned;
        Lsb at[kAxes] = {start[0], start[1]};
        TickAcceleration previous{};
        WireSpan w;
        std::int64_t spans = 0;
        bool ok = true;
        constexpr std::int64_t kChecked = 200000;  // a longer move's first spans only
        while (spans < kChecked && move.next(w) && ok) {
            ++spans;
            const Span<kAxes> span = to_core_span<kAxes>(w, at, 0);
            for (unsigned a = 0; a < kAxes; ++a) at[a] = w.end[a];
            ValidatedSpan<kAxes> v;
            ok = validate_span(span, v) == Status::kOk;
            if (!ok) break;
            const AxisLimits& lim = l.axis[0];
            ok = check_axis_limits(v.cubic[0], v.timing, lim, l.tick_hz) == Status::kOk &&
                 check_axis_jerk(v.cubic[0], v.timing, lim, l.tick_hz) == Status::kOk &&
                 check_acceleration_step(start_acceleration(v.cubic[0], v.timing), previous, lim,
                                         l.tick_hz) == Status::kOk;
            previous = end_acceleration(v.cubic[0], v.timing);
        }
        INFO("span " << spans);
        CHECK(ok);
        if (spans == kChecked) continue;
        CHECK(check_end_at_rest(previous, l.axis[0], l.tick_hz) == Status::kOk);
        CHECK(at[0] == start[0] + distance);
        CHECK(at[1] == start[1]);
    }
    CHECK(planned > 50);
}
