#include "tick_sampling.hpp"

#include <algorithm>
#include <cmath>

namespace pathstream::bench {

namespace {

/// Distance travelled `t` seconds into a move's trapezoid (t clamped to the move).
double distance_at(const TimedMove& m, double t) {
    if (t <= 0) return 0;
    if (t < m.t_accel) return m.v_entry * t + 0.5 * m.accel * t * t;
    t -= m.t_accel;
    if (t < m.t_cruise) return m.d_accel + m.v_cruise * t;
    t -= m.t_cruise;
    if (t < m.t_decel) return m.d_accel + m.d_cruise + m.v_cruise * t - 0.5 * m.accel * t * t;
    return m.d_accel + m.d_cruise + m.d_decel;
}

}  // namespace

TickFigures sample_at_ticks(const PeerPlan& plan, const host::MachineProfile& profile) {
    TickFigures f;
    if (plan.moves.empty()) return f;
    const std::size_t axes = plan.moves.front().start.size();
    const double tick = profile.tick_seconds();
    const double total = plan.motion_time();
    f.ticks = static_cast<std::uint64_t>(std::ceil(total / tick));

    std::size_t move = 0;
    double move_start_time = 0;  // of `move`
    std::vector<double> before(axes), now(axes), after(axes);
    // Position at time t; t never decreases from one call to the next.
    const auto position = [&](double t, std::vector<double>& out) {
        while (move + 1 < plan.moves.size() && t >= move_start_time + plan.timed[move].duration()) {
            move_start_time += plan.timed[move].duration();
            ++move;
        }
        const LineMove& m = plan.moves[move];
        const double s = std::min(m.length, distance_at(plan.timed[move], t - move_start_time));
        for (std::size_t i = 0; i < axes; ++i) out[i] = m.start[i] + m.unit[i] * s;
    };
    position(0, before);
    position(std::min(total, tick), now);
    for (std::uint64_t k = 1; k <= f.ticks; ++k) {
        position(std::min(total, static_cast<double>(k + 1) * tick), after);
        for (std::size_t i = 0; i < axes; ++i) {
            const double step = std::fabs(now[i] - before[i]);
            const double second = std::fabs(after[i] - 2 * now[i] + before[i]);
            const double a_limit = profile.axes[i].max_acceleration;
            f.max_velocity_fraction =
                std::max(f.max_velocity_fraction, step / (profile.axes[i].max_velocity * tick));
            if (second / (a_limit * tick * tick) > f.max_acceleration_fraction) {
                f.max_acceleration_fraction = second / (a_limit * tick * tick);
                f.worst_time = static_cast<double>(k) * tick;
            }
            if (second / tick > f.max_velocity_step) {
                f.max_velocity_step = second / tick;
                f.velocity_step_limit = a_limit * tick;
            }
        }
        before.swap(now);
        now.swap(after);
    }
    const LineMove& last = plan.moves.back();
    double error = 0;
    for (std::size_t i = 0; i < axes; ++i) error = std::max(error, std::fabs(now[i] - last.end[i]));
    f.end_error = error;
    return f;
}

}  // namespace pathstream::bench
