#include "klipper_style.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pathstream::bench {

namespace {

/// A move's limits and the caps its junction with the previous move puts on its start.
struct QueuedMove {
    double length = 0, accel = 0;
    double max_cruise2 = 0;
    double delta2 = 0;         ///< 2 a L: the v^2 the move can gain or shed
    double smooth_delta2 = 0;  ///< the same at the smoothed acceleration
    double max_start2 = 0;
    double max_smoothed2 = 0;
};

/// The junction caps of `m` after `previous` (unit directions `from`, `to`); `tick_cap2` is
/// the per-tick cap (infinite when the peer runs on its own rule).
void cap_junction(QueuedMove& m, const QueuedMove& previous, const host::PathPoint& from,
                  const host::PathPoint& to, double junction_deviation, double tick_cap2) {
    double start2 =
        std::min({m.max_cruise2, previous.max_cruise2, previous.max_start2 + previous.delta2});
    double cos_turn = 0;  // -u1.u2: -1 straight on, +1 back
    for (std::size_t i = 0; i < to.size(); ++i) cos_turn -= from[i] * to[i];
    const double sin_half = std::sqrt(std::max(0.5 * (1 - cos_turn), 0.0));
    const double cos_half = std::sqrt(std::max(0.5 * (1 + cos_turn), 0.0));
    if (1 - sin_half > 0 && cos_half > 0) {
        const double r = sin_half / (1 - sin_half);
        const double tan_quarter = 0.25 * sin_half / cos_half;  // (L a tan/2) = delta2 tan / 4
        start2 = std::min({start2, r * junction_deviation * m.accel,
                           r * junction_deviation * previous.accel, m.delta2 * tan_quarter,
                           previous.delta2 * tan_quarter});
    }
    // On top of Klipper's own caps, and before the smoothed cap is derived from them, so that
    // both lookaheads see the held junction.
    m.max_start2 = std::min(start2, tick_cap2);
    m.max_smoothed2 = std::min(m.max_start2, previous.max_smoothed2 + previous.smooth_delta2);
}

}  // namespace

PeerPlan plan_klipper_style(std::vector<LineMove> moves, const host::MachineProfile& profile,
                            JunctionRule rule, double square_corner_velocity,
                            double minimum_cruise_ratio) {
    double a_max = std::numeric_limits<double>::infinity();
    for (const host::AxisLimits& axis : profile.axes)
        a_max = std::min(a_max, axis.max_acceleration);
    const double junction_deviation =
        square_corner_velocity * square_corner_velocity * (std::sqrt(2.0) - 1) / a_max;

    const std::size_t n = moves.size();
    std::vector<QueuedMove> q(n);
    for (std::size_t k = 0; k < n; ++k) {
        QueuedMove& m = q[k];
        const double v = std::min(moves[k].feed, along_direction_velocity(moves[k].unit, profile));
        m.length = moves[k].length;
        m.accel = along_direction_acceleration(moves[k].unit, profile);
        m.max_cruise2 = v * v;
        m.delta2 = 2 * m.length * m.accel;
        m.smooth_delta2 = m.delta2 * (1 - minimum_cruise_ratio);
        if (k == 0 || moves[k].stop_before) {
            m.max_start2 = m.max_smoothed2 = 0;  // from rest
        } else {
            const host::PathPoint& from = moves[k - 1].unit;
            const host::PathPoint& to = moves[k].unit;
            const double tick_cap2 = rule == JunctionRule::per_tick
                                         ? per_tick_junction_speed2(from, to, profile)
                                         : std::numeric_limits<double>::infinity();
            cap_junction(m, q[k - 1], from, to, junction_deviation, tick_cap2);
        }
    }

    // Backward pass. Moves whose smoothed profile only decelerates towards the end wait in
    // `waiting` until the smoothed peak before them is known.
    struct Waiting {
        std::size_t move;
        double start2;
    };
    std::vector<Waiting> waiting;
    std::vector<TimedMove> timed(n);
    // A move ends at the speed the next one starts at: that one is already set (the pass runs
    // backward, and waiting moves are set later ones first, before the move that releases
    // them). Klipper ends at min(end, cruise), which leaves a velocity step at the junction
    // where the next move's start was capped by a different peak (or not at all); the cruise
    // is raised to that start instead (reachable: a start is capped by what the previous move
    // can reach), never slower than Klipper.
    const auto set_profile = [&](std::size_t k, double start2, double cruise2) {
        const double end2 = k + 1 < n ? timed[k + 1].v_entry * timed[k + 1].v_entry : 0;
        cruise2 = std::max(cruise2, end2);
        timed[k] =
            make_trapezoid(q[k].length, q[k].accel, std::min(start2, cruise2), cruise2, end2);
    };
    double next_end2 = 0, next_smoothed2 = 0, peak_cruise2 = 0;
    for (std::size_t k = n; k-- > 0;) {
        const QueuedMove& m = q[k];
        const double reachable_start2 = next_end2 + m.delta2;
        const double start2 = std::min(m.max_start2, reachable_start2);
        const double reachable_smoothed2 = next_smoothed2 + m.smooth_delta2;
        const double smoothed2 = std::min(m.max_smoothed2, reachable_smoothed2);
        if (smoothed2 < reachable_smoothed2) {
            // The smoothed profile accelerates in this move; where it can also decelerate (or
            // moves wait behind it), its peak here caps the cruise of this move and the waiting
            // ones.
            if (smoothed2 + m.smooth_delta2 > next_smoothed2 || !waiting.empty()) {
                peak_cruise2 = std::min(m.max_cruise2, 0.5 * (smoothed2 + reachable_smoothed2));
                for (const Waiting& w : waiting) {
                    const double cruise2 = std::min(peak_cruise2, w.start2);
                    set_profile(w.move, w.start2, cruise2);
                }
                waiting.clear();
            }
            const double cruise2 =
                std::min({0.5 * (start2 + reachable_start2), m.max_cruise2, peak_cruise2});
            set_profile(k, start2, cruise2);
        } else {
            waiting.push_back({k, start2});
        }
        next_end2 = start2;
        next_smoothed2 = smoothed2;
    }
    for (const Waiting& w : waiting)
        set_profile(w.move, w.start2, std::min(peak_cruise2, w.start2));

    PeerPlan plan;
    plan.timed = std::move(timed);
    plan.moves = std::move(moves);
    return plan;
}

}  // namespace pathstream::bench
