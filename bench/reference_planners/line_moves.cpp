#include "line_moves.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace pathstream::bench {

using host::BezierSegment;
using host::MachineProfile;
using host::PathPoint;

namespace {

double norm(const PathPoint& v) {
    double s = 0;
    for (double x : v) s += x * x;
    return std::sqrt(s);
}

/// Length of P_a - 2 P_b + P_c: a sixth of the cubic's second derivative at one end.
double second_difference(const PathPoint& a, const PathPoint& b, const PathPoint& c) {
    double s = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        const double d = a[i] - 2 * b[i] + c[i];
        s += d * d;
    }
    return std::sqrt(s);
}

/// Equal parameter steps that keep every chord within `tolerance` of the cubic: the second
/// derivative is linear in u, so its largest length is at an end, 6 max(|D0|, |D1|).
std::size_t chord_count(const BezierSegment& s, double tolerance) {
    const double bend = 6 * std::max(second_difference(s.p[0], s.p[1], s.p[2]),
                                     second_difference(s.p[1], s.p[2], s.p[3]));
    const double n = std::ceil(std::sqrt(bend / (8 * tolerance)));
    return n < 1 ? 1 : static_cast<std::size_t>(std::min(n, 1e6));
}

}  // namespace

std::vector<LineMove> flatten_to_lines(const std::vector<BezierSegment>& segments,
                                       const MachineProfile& profile) {
    std::vector<LineMove> moves;
    bool stop_pending = true;  // the job starts at rest
    bool previous_pen = false;
    for (std::size_t k = 0; k < segments.size(); ++k) {
        const BezierSegment& s = segments[k];
        if (k > 0 && s.pen_down != previous_pen) stop_pending = true;
        if (s.pause_before || s.dwell_before > 0) stop_pending = true;
        previous_pen = s.pen_down;
        const double feed = s.feed > 0 ? s.feed : (s.pen_down ? profile.feed : profile.travel_feed);
        const std::size_t n = chord_count(s, profile.chord_tolerance);
        PathPoint from = s.p[0];
        for (std::size_t j = 1; j <= n; ++j) {
            PathPoint to =
                j == n ? s.p[3]
                       : host::bezier_point(s, static_cast<double>(j) / static_cast<double>(n));
            LineMove m;
            m.unit.resize(to.size());
            for (std::size_t i = 0; i < to.size(); ++i) m.unit[i] = to[i] - from[i];
            m.length = norm(m.unit);
            if (m.length < 1e-9) continue;  // nothing to move (a repeated point): keep `from`
            for (double& u : m.unit) u /= m.length;
            m.start = from;
            m.end = to;
            m.feed = feed;
            m.stop_before = stop_pending;
            stop_pending = false;
            moves.push_back(std::move(m));
            from = std::move(to);
        }
    }
    return moves;
}

double along_direction_velocity(const PathPoint& unit, const MachineProfile& profile) {
    double v = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < unit.size(); ++i) {
        if (unit[i] != 0) v = std::min(v, profile.axes[i].max_velocity / std::fabs(unit[i]));
    }
    return v;
}

double along_direction_acceleration(const PathPoint& unit, const MachineProfile& profile) {
    double a = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < unit.size(); ++i) {
        if (unit[i] != 0) a = std::min(a, profile.axes[i].max_acceleration / std::fabs(unit[i]));
    }
    return a;
}

double per_tick_junction_speed2(const PathPoint& from, const PathPoint& to,
                                const MachineProfile& profile) {
    double v2 = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < to.size(); ++i) {
        const double jump = std::fabs(to[i] - from[i]);  // the axis's velocity step per mm/s
        if (jump == 0) continue;
        const double v = profile.axes[i].max_acceleration / (profile.tick_hz * jump);
        v2 = std::min(v2, v * v);
    }
    return v2;
}

TimedMove make_trapezoid(double length, double accel, double v_entry2, double v_cruise2,
                         double v_exit2) {
    TimedMove t;
    t.accel = accel;
    double d_accel = (v_cruise2 - v_entry2) / (2 * accel);
    double d_decel = (v_cruise2 - v_exit2) / (2 * accel);
    if (d_accel + d_decel > length) {  // rounding: the cruise speed is the triangle's peak
        v_cruise2 = std::max({v_entry2, v_exit2, 0.5 * (v_entry2 + v_exit2) + accel * length});
        d_accel = std::min(length, std::max(0.0, (v_cruise2 - v_entry2) / (2 * accel)));
        d_decel = length - d_accel;
    }
    t.v_entry = std::sqrt(v_entry2);
    t.v_cruise = std::sqrt(v_cruise2);
    t.v_exit = std::sqrt(v_exit2);
    t.d_accel = d_accel;
    t.d_decel = d_decel;
    t.d_cruise = std::max(0.0, length - d_accel - d_decel);
    t.t_accel = (t.v_cruise - t.v_entry) / accel;
    t.t_decel = (t.v_cruise - t.v_exit) / accel;
    t.t_cruise = t.d_cruise > 0 ? t.d_cruise / t.v_cruise : 0;
    return t;
}

double PeerPlan::motion_time() const {
    double t = 0;
    for (const TimedMove& m : timed) t += m.duration();
    return t;
}

double max_junction_step_fraction(const PeerPlan& plan, const MachineProfile& profile) {
    double worst = 0;
    for (std::size_t k = 1; k < plan.moves.size(); ++k) {
        const PathPoint& from = plan.moves[k - 1].unit;
        const PathPoint& to = plan.moves[k].unit;
        const double v = plan.timed[k - 1].v_exit;
        for (std::size_t i = 0; i < to.size(); ++i) {
            const double step_limit = profile.axes[i].max_acceleration / profile.tick_hz;
            worst = std::max(worst, v * std::fabs(to[i] - from[i]) / step_limit);
        }
    }
    return worst;
}

std::string consistency_problem(const PeerPlan& plan) {
    char text[200];
    if (plan.timed.size() != plan.moves.size()) return "one profile per move expected";
    if (plan.moves.empty()) return "no moves";
    for (std::size_t k = 0; k < plan.moves.size(); ++k) {
        const LineMove& m = plan.moves[k];
        const TimedMove& t = plan.timed[k];
        const double slack = 1e-9 * std::max(1.0, t.v_cruise);
        const bool finite = std::isfinite(t.duration()) && std::isfinite(t.v_cruise);
        const double sum = t.d_accel + t.d_cruise + t.d_decel;
        const bool ok = finite && t.t_accel >= 0 && t.t_cruise >= 0 && t.t_decel >= 0 &&
                        t.d_accel >= 0 && t.d_cruise >= 0 && t.d_decel >= 0 &&
                        std::fabs(sum - m.length) <= 1e-9 * std::max(1.0, m.length) &&
                        t.v_entry <= t.v_cruise + slack && t.v_exit <= t.v_cruise + slack &&
                        t.v_cruise > 0 && t.accel > 0;
        if (!ok) {
            std::snprintf(text, sizeof text,
                          "move %zu: inconsistent trapezoid (%.6g mm: %.6g/%.6g/%.6g mm, "
                          "%.6g/%.6g/%.6g mm/s)",
                          k, m.length, t.d_accel, t.d_cruise, t.d_decel, t.v_entry, t.v_cruise,
                          t.v_exit);
            return text;
        }
        const double previous_exit = k == 0 ? 0 : plan.timed[k - 1].v_exit;
        if (m.stop_before && (t.v_entry > slack || previous_exit > slack)) {
            std::snprintf(text, sizeof text, "move %zu: not at rest at a stop (%.6g mm/s)", k,
                          t.v_entry);
            return text;
        }
        if (std::fabs(t.v_entry - previous_exit) > slack) {
            std::snprintf(text, sizeof text, "move %zu: entry %.9g mm/s after exit %.9g mm/s", k,
                          t.v_entry, previous_exit);
            return text;
        }
    }
    if (plan.timed.back().v_exit > 1e-9) return "not at rest at the end";
    if (!(plan.motion_time() > 0)) return "motion time not positive";
    return {};
}

}  // namespace pathstream::bench
