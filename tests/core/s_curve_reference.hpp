// The time-optimal rest-to-rest S-curve in closed form (double): the reference the device's
// own jerk-limited moves are measured against, by the tests and by bench_jog.
#pragma once

#include <algorithm>
#include <cmath>

namespace pathstream::test {

/// Seconds of the time-optimal rest-to-rest move over `distance` at up to velocity v,
/// acceleration a and jerk j (any one unit of length): a symmetric profile whose cruise, where
/// it has one, is at v; shorter moves never reach it and take the largest peak speed that fits
/// (bisection).
inline double s_curve_seconds(double distance, double v, double a, double j) {
    double time = 0;
    const auto ramp = [&](double peak_speed) {  // one ramp to peak_speed: its distance
        const double t_jerk = std::min(a / j, std::sqrt(peak_speed / j));
        const double t_const = std::max(0.0, peak_speed / (j * t_jerk) - t_jerk);
        time = 2 * t_jerk + t_const;
        return peak_speed * time / 2;
    };
    if (2 * ramp(v) <= distance) return 2 * time + (distance - 2 * ramp(v)) / v;
    double lo = 0, hi = v;
    for (int i = 0; i < 200; ++i) {
        const double mid = 0.5 * (lo + hi);
        (2 * ramp(mid) <= distance ? lo : hi) = mid;
    }
    ramp(lo);
    return 2 * time;
}

}  // namespace pathstream::test
