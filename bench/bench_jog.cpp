// bench_jog: how long the device's own rest-to-rest moves (jog, homing: AxisMove) take under a
// jerk limit, against the time-optimal S-curve and against the baseline measured in the same
// run: the constant-acceleration ramps at J/2 * 1 tick that AxisMove used under a jerk limit
// before its S-curves (the same planner with no jerk limit and that acceleration). Motion
// times are tick counts (deterministic); every span of every move is checked against the
// device's rules (exact limits, the jerk inside each span, the acceleration steps at every
// join, rest at both ends) and must end on the target.
//
//   build/default/bench/bench_jog [--markdown]
//
// Exit status: 0; 1 if a move is refused or a span breaks a rule or a move misses its target;
// 2 on a usage error.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>

#include "core/s_curve_reference.hpp"
#include "pathstream/device/homing.hpp"

namespace {

using namespace pathstream;
using namespace pathstream::device;

constexpr unsigned kAxes = 2;

// The pen plotter in LSB: 1 um, 1 kHz, 250 mm/s, 3000 mm/s^2.
MotionLimits<kAxes> plotter(std::uint32_t max_jerk) {
    MotionLimits<kAxes> l;
    l.tick_hz = 1000;
    for (auto& a : l.axis) {
        a.max_velocity = 250000;
        a.max_acceleration = 3000000;
        a.max_jerk = max_jerk;
    }
    return l;
}

struct Run {
    bool ok = false;
    std::uint64_t ticks = 0;
    std::uint64_t spans = 0;
};

// Plans and walks one move, checking every span with the device's rules under `check`.
Run run(std::int64_t distance, std::uint32_t velocity, const MotionLimits<kAxes>& plan_with,
        const MotionLimits<kAxes>& check) {
    Run r;
    const Lsb start[kAxes] = {0, 0};
    AxisMove<kAxes> move;
    if (move.plan(start, 0, distance, velocity, plan_with) != Status::kOk) return r;
    Lsb at[kAxes] = {0, 0};
    TickAcceleration previous{};
    WireSpan w;
    while (move.next(w)) {
        const Span<kAxes> s = to_core_span<kAxes>(w, at, 0);
        for (unsigned a = 0; a < kAxes; ++a) at[a] = w.end[a];
        ValidatedSpan<kAxes> v;
        if (validate_span(s, v) != Status::kOk) return r;
        const AxisLimits& l = check.axis[0];
        if (check_axis_limits(v.cubic[0], v.timing, l, check.tick_hz) != Status::kOk ||
            check_axis_jerk(v.cubic[0], v.timing, l, check.tick_hz) != Status::kOk ||
            check_acceleration_step(start_acceleration(v.cubic[0], v.timing), previous, l,
                                    check.tick_hz) != Status::kOk) {
            return r;
        }
        previous = end_acceleration(v.cubic[0], v.timing);
        r.ticks += w.ticks;
        ++r.spans;
    }
    r.ok = check_end_at_rest(previous, check.axis[0], check.tick_hz) == Status::kOk &&
           at[0] == distance && at[1] == 0;
    return r;
}

}  // namespace

int main(int argc, char** argv) {
    bool markdown = false;
    for (int i = 1; i < argc; ++i) {
        if (std::strcmp(argv[i], "--markdown") == 0) {
            markdown = true;
        } else if (std::strcmp(argv[i], "--help") == 0) {
            std::printf(
                "usage: bench_jog [--markdown]\n"
                "  Jogs of the pen plotter (1 um LSB, 1 kHz, 3000 mm/s^2) at 100 mm/s under a jerk "
                "limit:\n"
                "  AxisMove's S-curves against the optimal S-curve and against "
                "constant-acceleration\n"
                "  ramps at J/2 per tick (the baseline), every span checked with the device's "
                "rules.\n"
                "  Exit 1 if a move is refused, breaks a rule or misses its target; 2 on a usage "
                "error.\n");
            return 0;
        } else {
            std::fprintf(stderr, "bench_jog: unknown argument %s (see --help)\n", argv[i]);
            return 2;
        }
    }
    const char* head = markdown ? "| jerk mm/s^3 | distance mm | S-curve s | spans | J/2 ramps s | "
                                  "optimum s | x optimum | faster than J/2 ramps |\n"
                                  "|---:|---:|---:|---:|---:|---:|---:|---:|\n"
                                : "jerk mm/s^3  distance mm  S-curve s  spans  J/2 ramps s  "
                                  "optimum s  x optimum  faster than J/2 ramps\n";
    std::printf(
        "bench_jog: pen plotter in LSB (1 um, 1 kHz, 250 mm/s, 3000 mm/s^2), jogs at 100 mm/s\n%s",
        head);
    bool failed = false;
    for (const std::uint32_t max_jerk :
         {1000000u, 10000000u}) {  // 1e5 and 1e6 mm/s^3 (units of 100 LSB/s^3)
        const MotionLimits<kAxes> limits = plotter(max_jerk);
        // The baseline: no jerk limit, the acceleration J/2 * 1 tick (J / (2 hz) LSB/s^2).
        MotionLimits<kAxes> baseline = limits;
        for (auto& a : baseline.axis) {
            a.max_acceleration = static_cast<std::uint32_t>(std::uint64_t{max_jerk} * kJerkUnitLsb /
                                                            (2 * limits.tick_hz));
            a.max_jerk = 0;
        }
        for (const std::int64_t distance : {1000, 10000, 100000, 1000000}) {
            const Run s = run(distance, 100000, limits, limits);
            const Run b = run(distance, 100000, baseline, limits);
            const double jerk_mm = max_jerk * 100.0 * 1e-3;
            const double optimum =
                test::s_curve_seconds(static_cast<double>(distance) * 1e-3, 100, 3000, jerk_mm);
            const double seconds = static_cast<double>(s.ticks) / limits.tick_hz;
            const double base = static_cast<double>(b.ticks) / limits.tick_hz;
            if (!s.ok || !b.ok) failed = true;
            std::printf(
                markdown ? "| %.0e | %.0f | %.3f | %llu | %.3f | %.3f | %.2f | %.2fx |%s\n"
                         : "%11.0e  %11.0f  %9.3f  %5llu  %11.3f  %9.3f  %9.2f  %20.2fx%s\n",
                jerk_mm, static_cast<double>(distance) * 1e-3, seconds,
                static_cast<unsigned long long>(s.spans), base, optimum, seconds / optimum,
                base / seconds, s.ok && b.ok ? "" : "  FAILED (refused, a rule, or the target)");
        }
    }
    std::printf(
        "bench_jog: %s\n",
        failed ? "FAILED" : "every span within the device's rules, every move on its target");
    return failed ? 1 : 0;
}
