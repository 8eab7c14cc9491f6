// PieceTimer: the forward pass of one piece in whole ticks, one class whose stages have sources
// of their own: piece_stepping.cpp (the loop over knots, the regular span), piece_span_check.cpp,
// piece_beta.cpp, piece_landings.cpp and piece_final_spans.cpp. What every candidate span calls
// is inline below, so that each stage's loops inline it; a helper with one caller is declared
// inline and defined next to it (a call from another source does not compile).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "forward_pass.hpp"
#include "grid.hpp"
#include "limits.hpp"
#include "lsb_rounding.hpp"
#include "pathstream/host/planner.hpp"
#include "pathstream/machine/machine.hpp"
#include "vec.hpp"

namespace pathstream::host::planner_detail {

class PieceTimer {
public:
    /// One piece, the limits less the margins of `options`; the references must outlive it.
    PieceTimer(const PathGrid& pg, const Piece& piece, const Limits& limits,
               const std::vector<double>& caps, const std::vector<double>& beta,
               const MachineProfile& profile, const PlanOptions& options);

    /// The piece's spans from rest at start_q to rest at its end (ok false, with the place,
    /// where no whole-tick span is found); `resume`'s spans before resume_lambda are kept.
    PieceMotion run(const Vec& start_q, PieceMotion* resume, double resume_lambda,
                    bool short_spans);

private:
    /// The span that arrived at a knot: where it started and its ticks (0: none, at rest).
    struct Arrival {
        Knot from;
        std::uint32_t ticks = 0;
    };

    /// A span tried by evaluate: path acceleration a, end, violation f (<= 0: within all).
    struct Candidate {
        double a = 0;
        Knot end;
        double f = 0;
    };

    // The regular span (piece_stepping.cpp).

    /// The fastest span of m ticks from k within the limits and beta (false: none); ~90 evaluates.
    bool step(const Knot& k, std::uint32_t m, Knot& next);
    /// The feasible end of a bracket [lo, hi] of accelerations (regula falsi): up to 40 evaluates.
    Candidate boundary(const Knot& k, Candidate lo, Candidate hi, std::uint32_t m, double jerk);
    /// The span of m ticks from k at path acceleration a (rising by `jerk`), its end on the LSB
    /// grid, and how far it breaks the limits, the tolerance or beta: the unit of the search,
    /// one path lookup, fit_end, violation and span_deviation.
    Candidate evaluate(const Knot& k, double a, std::uint32_t m, double jerk = 0);

    // What the executed span breaks (piece_span_check.cpp).

    /// Moves k1, the end of a span of m ticks from k0, onto the LSB grid as the emitter
    /// rounds it: the nearest point and tangent within the limits, else the least violating.
    void fit_end(const Knot& k0, const Vec& v0, Knot& k1, std::uint32_t m) const;
    /// The velocity jump at k0 where the tick count changes, over the acceleration limit, or 0.
    inline double junction(const Arrival& in, const Knot& k0, const Vec& v0, const Knot& k1,
                           std::uint32_t m) const;
    /// How far the executed span k0 -> k1 of m ticks exceeds the axis limits, the feed and
    /// (with `caps`) the speed caps, and its junction with `in`: ratio - 1, <= 0 within.
    double violation(const Knot& k0, const Arrival& in, const Knot& k1, std::uint32_t m,
                     bool caps = true) const;
    /// violation with k0's velocity already rounded for the span (v0 = span_velocity(k0.v, m)).
    double violation(const Knot& k0, const Arrival& in, const Knot& k1, std::uint32_t m,
                     const Vec& v0, bool caps = true) const;
    /// Largest distance of the executed span from the path (0 where it cannot leave it): a
    /// path lookup at every sixth of the span, at every tick (up to 256) across a corner.
    double span_deviation(const Knot& k, const Knot& end, std::uint32_t m);
    /// span_deviation with k's velocity already rounded for the span (v0 = span_velocity(k.v, m)).
    double span_deviation(const Knot& k, const Knot& end, std::uint32_t m, const Vec& v0);

    // The speed kept under the lookahead's beta (piece_beta.cpp; under_beta inline below).

    /// Whether path acceleration a for tau seconds from k keeps s^2 under beta (nodes, end).
    bool under_beta(const Knot& k, double a, double tau) const;
    /// The largest a in [a_lo, a_hi] under beta (false: not even a_lo): closed form, verified.
    bool max_under_beta(const Knot& k, double tau, double a_lo, double a_hi, double& a) const;
    /// max_under_beta's boundary in closed form, solved interval by interval of the grid.
    inline double solve_under_beta(const Knot& k, double tau, double a_lo, double a_hi) const;
    /// under_beta for a path acceleration rising linearly: A + J (t - tau/2).
    inline bool jerk_under_beta(const Knot& k, double a, double jerk, double tau) const;
    /// Replaces `best` by a span of rising path acceleration (A >= -brake times the limit)
    /// where one ends faster; false when there is no span at all. Four jerks, each a search.
    bool rise_across(const Knot& k, double brake, bool have, Knot& best);

    // Knots landed on corners and dips of beta (piece_landings.cpp).

    /// A span ending on the next crossed corner where its speed binds (ticks; 0: a regular one).
    std::uint32_t corner_landing(const Knot& k, Knot& out);
    /// A knot on the next dip of beta within three spans, soonest (ticks of this span; 0: none).
    std::uint32_t dip_landing(const Knot& k, Knot& out);
    /// The span leaving a dip: the regular one or a rising one, whichever ends faster (0: none).
    std::uint32_t leave_dip(const Knot& k, Knot& out);
    /// The first span of the fewest ticks that reach node c at speed^2 xc along dir, a landing
    /// span last (its ticks; 0: none); up to 65536 span pairs.
    std::uint32_t approach(const Knot& k, std::size_t c, const Vec& dir, double xc,
                           std::uint32_t spans_ahead, std::uint32_t direct_ticks,
                           const Knot& direct, Knot& out);
    /// One span from k ending exactly on node c with its velocity along dir, the fewest ticks
    /// from m_lo to m_hi (0: ticks_per_span) that work (0: none).
    std::uint32_t land_on_corner(const Knot& k, std::size_t c, const Vec& dir, double xc, Knot& out,
                                 std::uint32_t m_lo = 1, std::uint32_t m_hi = 0);
    /// Whether a joint whose curvature jumps lies in [l0, l1] (searched from node `from`).
    bool steps_between(double l0, double l1, std::size_t from = static_cast<std::size_t>(-1)) const;

    // The spans that end at rest at the piece's end (piece_final_spans.cpp).

    /// Ticks of a final span from k to rest at the end (0: none of at most ticks_per_span);
    /// one comparison while the end is far.
    std::uint32_t finish(const Knot& k);
    /// Whether the final span of `ticks` ticks from k is within the limits, the tolerance and
    /// the speed caps, and never passes the end point at a tick.
    bool finish_ok(const Knot& k, const Arrival& in, std::uint32_t ticks);
    /// The last two spans at once near the end: the final span's ticks (0: none), the knot
    /// `mid` before it and the first span's ticks; at most 17 first-span lengths, each with
    /// every final one.
    std::uint32_t land(const Knot& k, Knot& mid, std::uint32_t& first_ticks);
    /// The fewest ticks of a rest-to-rest span from q to the end within limits and feed (0: at it).
    std::uint32_t creep_ticks(const Vec& q) const;
    /// What the rounding of a span of tau seconds onto the LSB grid (end points, tangents) may
    /// add to its speed, as the feed and speed-cap checks allow it: an LSB per axis over the
    /// span, or over a regular span where this one is shorter.
    double speed_rounding(double tau) const;
    /// More than `spans` regular spans from k can cover: the speed stays under the feed (beta,
    /// the feed check at eighths), less what the rounding of the tangents lets through.
    double feed_reach(const Knot& k, std::uint32_t spans) const;

    // Grid lookups and roundings of every candidate span (inline, below).

    /// q on the LSB grid, rounded as the emitter rounds span end points.
    Vec grid_point(const Vec& q) const;
    /// v as a span of m ticks carries it: its tangent rounded to whole LSB as the emitter does.
    Vec span_velocity(const Vec& v, std::uint32_t m) const;
    /// The piece's end point, at rest.
    Knot end_knot() const;
    /// The node index of the interval holding lambda (lambda[i] <= lambda < lambda[i+1]).
    std::size_t interval(double lambda) const;
    /// Per-node values v at arc length lambda, linear between nodes.
    double interpolate(const std::vector<double>& v, double lambda) const;
    /// The lookahead's bound on s^2 at arc length l: linear between nodes, and in the final
    /// interval also the stop at stop_decel_ (final_stop).
    double beta_at(double l) const;
    /// In the final interval (from stop_from_ to the end): the s^2 from which braking at
    /// stop_decel_ stops at the end, at most stop_x_ (0 where that does not apply).
    double final_stop(double l) const;
    /// Curvature vector at arc length l, linear between nodes.
    Vec curvature_at(double l) const;
    /// The largest path acceleration the axes allow along unit tangent t (no curvature).
    double path_acceleration_limit(const Vec& t) const;
    /// Whether nodes i and i + 1 are the two sides of a joint whose curvature jumps.
    bool curvature_jump(std::size_t i) const;
    /// Hermite value at t in [0, 1] on one axis (positions p0, p1, tangents m0, m1 per span).
    static double hermite(double p0, double p1, double m0, double m1, double t);

    const PathGrid& pg_;
    const Grid& g_;
    const Piece& piece_;
    const std::vector<double>& caps_;
    const std::vector<double>& beta_;
    std::size_t axes_;
    double tick_, tick_hz_;
    std::uint32_t n_;
    Vec acc_{}, vel_{};
    double acc_norm_ = 0;
    bool on_dip_ = false;  ///< the current knot landed on a dip or a corner (leave_dip next)
    /// With a jerk limit the jerk stage's filter reshapes the knots' speed profile: the knots
    /// on local minima of beta, the rising spans across a dip no knot landed on and the
    /// shortened span before a landing, whose sharper acceleration changes it would have to
    /// smooth, are not used.
    bool jerk_limited_ = false;
    double feed_ = 0;
    double delta_ = 0;
    double lsb_ = 0, root_axes_ = 1, deviation_limit_ = 0;
    Arrival arrival_;  ///< the span that arrived at the current knot
    double end_lambda_ = 0;
    Vec end_q_{};
    /// The final interval's stop (final_stop): where it starts, the deceleration and the
    /// largest s^2 it applies to; stop_decel_ 0: beta is linear there as everywhere.
    double stop_from_ = 0, stop_decel_ = 0, stop_x_ = 0;
    std::size_t hint_ = 0;  ///< path_at's search hint, moving along the piece with the knots
    mutable std::size_t interval_hint_ = 0;  ///< interval()'s last answer
};

// The lookups and roundings every candidate span makes: inline, because the stages whose hot
// loops call them are in sources of their own.

inline Vec PieceTimer::grid_point(const Vec& q) const {
    return on_lsb_grid(q, lsb_, axes_);
}

// The tangent is dp/du = v m T / lsb, rounded with the emitter's formula and rounding.
inline Vec PieceTimer::span_velocity(const Vec& v, std::uint32_t m) const {
    const double scale = tangent_scale(m, tick_hz_, lsb_);
    Vec r{};
    for (std::size_t i = 0; i < axes_; ++i)
        r[i] = static_cast<double>(scaled_tangent_lsb(v[i], scale)) / scale;
    return r;
}

// Twice the feed's distance: the speed along a span is the Hermite cubic's, checked against
// the feed at eighths of it (its peak between samples is less than twice that), plus the
// rounding allowance of that check and an LSB per axis for the grid.
inline double PieceTimer::feed_reach(const Knot& k, std::uint32_t spans) const {
    const double tau = spans * n_ * tick_;
    return 2 * tau * std::max(k.speed, feed_) + 3 * spans * root_axes_ * lsb_;
}

// Over the span itself the allowance lets a short span hop a whole LSB at any speed: at a feed
// far below an LSB per tick the final span of a piece covered its last LSB in a few ticks,
// 15 times the feed (1 mm/min: 0.25 mm/s and 167 mm/s^2 on the 6 m arc). A regular span is
// long enough to carry the feed (feed_span_ticks), so its allowance is the floor.
inline double PieceTimer::speed_rounding(double tau) const {
    return root_axes_ * lsb_ / std::max(tau, n_ * tick_);
}

inline Knot PieceTimer::end_knot() const {
    Knot e;
    e.lambda = end_lambda_;
    e.q = end_q_;
    return e;
}

// The lookups come in runs near each other: a short walk from the last answer first, a
// binary search when that does not reach.
inline std::size_t PieceTimer::interval(double lambda) const {
    const std::size_t top = piece_.last == piece_.first ? piece_.first : piece_.last - 1;
    std::size_t i = std::clamp(interval_hint_, piece_.first, top);
    for (int steps = 0; steps < 8; ++steps) {
        if (g_.lambda[i] > lambda) {
            if (i == piece_.first) return interval_hint_ = i;
            --i;
        } else if (i < top && g_.lambda[i + 1] <= lambda) {
            ++i;
        } else {
            // lambda[i] <= lambda < lambda[i + 1] (or the top): the last of equal lambdas.
            while (i < top && g_.lambda[i + 1] <= lambda) ++i;
            return interval_hint_ = i;
        }
    }
    const auto b = g_.lambda.begin();
    auto it = std::upper_bound(b + static_cast<std::ptrdiff_t>(piece_.first),
                               b + static_cast<std::ptrdiff_t>(piece_.last) + 1, lambda);
    i = static_cast<std::size_t>(it - b);
    i = i == 0 ? 0 : i - 1;
    return interval_hint_ = std::clamp(i, piece_.first, top);
}

inline double PieceTimer::interpolate(const std::vector<double>& v, double lambda) const {
    const std::size_t i = interval(lambda);
    const double l0 = g_.lambda[i], l1 = g_.lambda[i + 1];
    if (!(l1 > l0)) return std::min(v[i], v[i + 1]);
    const double w = std::clamp((lambda - l0) / (l1 - l0), 0.0, 1.0);
    return (1 - w) * v[i] + w * v[i + 1];
}

// beta interpolated linearly in x = s^2, as TOPP-RA's constant path acceleration between
// nodes has it.
inline double PieceTimer::beta_at(double l) const {
    const double b = interpolate(beta_, l);
    return l > stop_from_ && stop_decel_ > 0 ? std::max(b, final_stop(l)) : b;
}

inline double PieceTimer::final_stop(double l) const {
    return std::min(stop_x_, 2 * stop_decel_ * std::max(0.0, end_lambda_ - l));
}

inline Vec PieceTimer::curvature_at(double l) const {
    const std::size_t i = interval(l);
    const double l0 = g_.lambda[i], l1 = g_.lambda[i + 1];
    const double w = l1 > l0 ? std::clamp((l - l0) / (l1 - l0), 0.0, 1.0) : 1.0;
    Vec r{};
    for (std::size_t a = 0; a < kAxesMax; ++a)
        r[a] = (1 - w) * g_.curvature[i][a] + w * g_.curvature[i + 1][a];
    return r;
}

inline double PieceTimer::path_acceleration_limit(const Vec& t) const {
    double lim = acc_norm_;
    for (std::size_t i = 0; i < axes_; ++i) {
        if (std::fabs(t[i]) > 1e-12) lim = std::min(lim, acc_[i] / std::fabs(t[i]));
    }
    return lim;
}

// A jump by more than a factor of 2: a blend's ends, a line meeting an arc.
inline bool PieceTimer::curvature_jump(std::size_t i) const {
    const double before = g_.curvature_norm[i], after = g_.curvature_norm[i + 1];
    return g_.lambda[i + 1] == g_.lambda[i] &&
           std::max(before, after) > 2 * std::min(before, after) + 1e-9;
}

inline double PieceTimer::hermite(double p0, double p1, double m0, double m1, double t) {
    const double t2 = t * t, t3 = t2 * t;
    return (2 * t3 - 3 * t2 + 1) * p0 + (t3 - 2 * t2 + t) * m0 + (-2 * t3 + 3 * t2) * p1 +
           (t3 - t2) * m1;
}

// x = s^2 and beta are both linear in arc length between nodes: the nodes and the end bound it.
inline bool PieceTimer::under_beta(const Knot& k, double a, double tau) const {
    double v1 = k.speed + a * tau;
    if (v1 < -1e-9 * (1 + k.speed)) return false;
    v1 = std::max(v1, 0.0);
    const double l1 = k.lambda + k.speed * tau + 0.5 * a * tau * tau;
    if (l1 > end_lambda_ + 1e-12) return false;
    const double x0 = k.speed * k.speed;
    const auto tol = [](double b) { return b * 1e-9 + 1e-12; };
    for (std::size_t i = interval(k.lambda) + 1; i <= piece_.last && g_.lambda[i] <= l1; ++i) {
        if (!(g_.lambda[i] > k.lambda)) continue;
        if (x0 + 2 * a * (g_.lambda[i] - k.lambda) > beta_[i] + tol(beta_[i])) return false;
    }
    const double b1 = beta_at(l1);
    return v1 * v1 <= b1 + tol(b1);
}

inline double PieceTimer::violation(const Knot& k0, const Arrival& in, const Knot& k1,
                                    std::uint32_t m, bool caps) const {
    return violation(k0, in, k1, m, span_velocity(k0.v, m), caps);
}

inline double PieceTimer::span_deviation(const Knot& k, const Knot& end, std::uint32_t m) {
    return span_deviation(k, end, m, span_velocity(k.v, m));
}

}  // namespace pathstream::host::planner_detail
