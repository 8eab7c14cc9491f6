#include "grbl_style.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pathstream::bench {

double grbl_junction_speed2(const host::PathPoint& from, const host::PathPoint& to,
                            const host::MachineProfile& profile, double junction_deviation) {
    // cos_turn = -u1.u2 is the cosine of the angle the two lines make at the vertex: -1 going
    // straight on, +1 turning back.
    double cos_turn = 0;
    host::PathPoint bend(to.size());
    for (std::size_t i = 0; i < to.size(); ++i) {
        cos_turn -= from[i] * to[i];
        bend[i] = to[i] - from[i];
    }
    if (cos_turn > 0.999999) return 0;                                         // a reversal
    if (cos_turn < -0.999999) return std::numeric_limits<double>::infinity();  // straight on
    double bend_length = 0;
    for (double b : bend) bend_length += b * b;
    bend_length = std::sqrt(bend_length);
    for (double& b : bend) b /= bend_length;
    const double a_bend = along_direction_acceleration(bend, profile);
    const double sin_half = std::sqrt(0.5 * (1 - cos_turn));
    return a_bend * junction_deviation * sin_half / (1 - sin_half);
}

PeerPlan plan_grbl_style(std::vector<LineMove> moves, const host::MachineProfile& profile,
                         JunctionRule rule, double junction_deviation) {
    const std::size_t n = moves.size();
    std::vector<double> nominal2(n), accel(n), max_entry2(n), entry2(n);
    for (std::size_t k = 0; k < n; ++k) {
        const double v = std::min(moves[k].feed, along_direction_velocity(moves[k].unit, profile));
        nominal2[k] = v * v;
        accel[k] = along_direction_acceleration(moves[k].unit, profile);
        if (k == 0 || moves[k].stop_before) {
            max_entry2[k] = 0;
        } else {
            const host::PathPoint& from = moves[k - 1].unit;
            const host::PathPoint& to = moves[k].unit;
            double junction2 = grbl_junction_speed2(from, to, profile, junction_deviation);
            if (rule == JunctionRule::per_tick)
                junction2 = std::min(junction2, per_tick_junction_speed2(from, to, profile));
            max_entry2[k] = std::min({junction2, nominal2[k], nominal2[k - 1]});
        }
    }
    // Backward: each entry no faster than the move can brake from to the next entry (0 at the end).
    double next_entry2 = 0;
    for (std::size_t k = n; k-- > 0;) {
        entry2[k] = std::min(max_entry2[k], next_entry2 + 2 * accel[k] * moves[k].length);
        next_entry2 = entry2[k];
    }
    // Forward: each entry no faster than the previous move can reach from its own entry.
    for (std::size_t k = 1; k < n; ++k) {
        entry2[k] = std::min(entry2[k], entry2[k - 1] + 2 * accel[k - 1] * moves[k - 1].length);
    }
    PeerPlan plan;
    plan.timed.reserve(n);
    for (std::size_t k = 0; k < n; ++k) {
        const double exit2 = k + 1 < n ? entry2[k + 1] : 0;
        const double peak2 = 0.5 * (entry2[k] + exit2) + accel[k] * moves[k].length;
        const double cruise2 = std::max({std::min(nominal2[k], peak2), entry2[k], exit2});
        plan.timed.push_back(make_trapezoid(moves[k].length, accel[k], entry2[k], cruise2, exit2));
    }
    plan.moves = std::move(moves);
    return plan;
}

}  // namespace pathstream::bench
