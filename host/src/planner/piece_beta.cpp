// The speed kept under the lookahead: beta (the backward pass's controllable speed) bounds
// s^2 at every node, so no span may end above it or pass a node above it, or the rest of the
// piece could not be run to its stop. Constant path acceleration keeps s^2 linear in arc
// length, which makes the largest acceleration under beta a closed form (solve_under_beta);
// a path acceleration rising along the span (rise_across, leaving a dip) needs the times the
// nodes are passed, found by Newton's method.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "forward_pass.hpp"
#include "piece_timer.hpp"
#include "vec.hpp"

namespace pathstream::host::planner_detail {

/// Largest A in [a_lo, a_hi] keeping the speed under beta, or false if even a_lo fails.
bool PieceTimer::max_under_beta(const Knot& k, double tau, double a_lo, double a_hi,
                                double& a) const {
    if (!under_beta(k, a_lo, tau)) return false;
    if (under_beta(k, a_hi, tau)) {
        a = a_hi;
        return true;
    }
    // The boundary in closed form; rounding may put it a hair outside, so it is verified
    // and backed off, and the bisection remains for what the closed form cannot place.
    a = solve_under_beta(k, tau, a_lo, a_hi);
    for (int back = 0; back < 4 && a > a_lo; ++back) {
        if (under_beta(k, a, tau)) return true;
        a -= std::ldexp(1e-12, 2 * back) * (1 + std::fabs(a));
    }
    double lo = a_lo, hi = a_hi;
    for (int it = 0; it < 64 && hi - lo > 1e-12 * (1 + std::fabs(lo)); ++it) {
        const double m = 0.5 * (lo + hi);
        (under_beta(k, m, tau) ? lo : hi) = m;
    }
    a = lo;
    return true;
}

/// under_beta's boundary in closed form: the end of the span moves along the grid as A
/// grows (l1 = l0 + V0 tau + A tau^2 / 2), so A is split at the nodes; in each interval the
/// nodes passed cap A linearly and the end's x = (V0 + A tau)^2 against beta interpolated
/// linearly is a quadratic. The largest A in [a_lo, a_hi] meeting them (a_lo if none).
inline double PieceTimer::solve_under_beta(const Knot& k, double tau, double a_lo,
                                           double a_hi) const {
    const double s = k.speed, x0 = s * s, tau2 = tau * tau;
    const auto a_at = [&](double l) { return 2 * (l - k.lambda - s * tau) / tau2; };
    const double top = std::min(a_hi, a_at(end_lambda_ + 1e-12));
    double best = a_lo, cap = top;
    const std::size_t first = interval(k.lambda);
    for (std::size_t j = first; j < piece_.last; ++j) {
        const double lj = g_.lambda[j], lj1 = g_.lambda[j + 1];
        if (j > first && lj > k.lambda)
            cap = std::min(cap, (beta_[j] * (1 + 1e-9) + 1e-12 - x0) / (2 * (lj - k.lambda)));
        const double seg_lo = j == first ? a_lo : a_at(lj);
        const double seg_hi = j + 1 == piece_.last ? top : a_at(lj1);
        if (seg_lo > cap) break;
        const double lo = std::max(seg_lo, a_lo), hi = std::min(seg_hi, cap);
        if (lo <= hi && lj1 > lj) {
            // (s + A tau)^2 <= (1 + 1e-9) beta(l1(A)) + 1e-12, beta linear in A here.
            const double slope = (beta_[j + 1] - beta_[j]) / (lj1 - lj);
            const double r0 = (1 + 1e-9) * (beta_[j] + slope * (k.lambda + s * tau - lj)) + 1e-12;
            const double r1 = (1 + 1e-9) * slope * tau2 / 2;
            const double qa = tau2, qb = 2 * s * tau - r1, qc = x0 - r0;
            const double disc = qb * qb - 4 * qa * qc;
            if (disc >= 0) {
                const double root = std::sqrt(disc);
                // The larger root without cancellation.
                const double r_hi = qb <= 0 ? (-qb + root) / (2 * qa) : (2 * qc) / (-qb - root);
                const double r_lo = qb <= 0 ? (2 * qc) / (-qb + root) : (-qb - root) / (2 * qa);
                if (std::isfinite(r_hi) && r_hi >= lo && (!std::isfinite(r_lo) || r_lo <= hi)) {
                    best = std::max(best, std::min(hi, r_hi));
                }
            }
        }
        // The final interval's stop (final_stop): (s + A tau)^2 <= 2 u (end - l1(A)), and
        // at most its largest s^2.
        if (stop_decel_ > 0 && lj == stop_from_ && lj1 > lj && lo <= hi) {
            const double u = stop_decel_;
            const double qa = tau2, qb = 2 * s * tau + u * tau2,
                         qc = x0 - 2 * u * (end_lambda_ - k.lambda - s * tau);
            const double disc = qb * qb - 4 * qa * qc;
            if (disc >= 0) {
                const double root = (-qb + std::sqrt(disc)) / (2 * qa);
                const double a = std::min({hi, root, (std::sqrt(stop_x_) - s) / tau});
                if (a >= lo) best = std::max(best, a);
            }
        }
        if (seg_hi >= top) break;
    }
    return best;
}

/// True when the path profile s(t) = V0 + (A - J tau/2) t + J t^2/2 stays non-negative and
/// its s^2 under beta at every node passed and at the end.
inline bool PieceTimer::jerk_under_beta(const Knot& k, double a, double jerk, double tau) const {
    const double a0 = a - 0.5 * jerk * tau;
    const auto speed = [&](double t) { return k.speed + a0 * t + 0.5 * jerk * t * t; };
    const auto dist = [&](double t) {
        return k.speed * t + 0.5 * a0 * t * t + jerk * t * t * t / 6;
    };
    if (jerk > 0 && a0 < 0) {
        const double t_min = -a0 / jerk;
        if (t_min < tau && speed(t_min) < 0) return false;
    }
    const double l1 = k.lambda + dist(tau);
    if (l1 > end_lambda_ + 1e-12 || speed(tau) < 0) return false;
    const auto tol = [](double b) { return b * 1e-9 + 1e-12; };
    for (std::size_t i = interval(k.lambda) + 1; i <= piece_.last && g_.lambda[i] <= l1; ++i) {
        if (!(g_.lambda[i] > k.lambda)) continue;
        // The time the node is passed: Newton kept inside [lo, hi] (dist increases while
        // the speed is non-negative), from the time at the mean speed.
        const double target = g_.lambda[i] - k.lambda;
        double lo = 0, hi = tau, t = std::clamp(tau * target / (l1 - k.lambda), 0.0, tau);
        for (int it = 0; it < 8; ++it) {
            const double f = dist(t) - target, v = speed(t);
            if (std::fabs(f) <= 1e-12 * (1 + target)) break;
            (f < 0 ? lo : hi) = t;
            const double next = v > 0 ? t - f / v : 0.5 * (lo + hi);
            t = next > lo && next < hi ? next : 0.5 * (lo + hi);
        }
        const double s = speed(t);
        if (s * s > beta_[i] + tol(beta_[i])) return false;
    }
    const double v1 = speed(tau), b1 = beta_at(l1);
    return v1 * v1 <= b1 + tol(b1);
}

/// Replaces `best` (a span of ticks_per_span ticks from k, if `have`) by a span whose path
/// acceleration rises linearly, A + J (t - tau/2) with A >= -brake times the path
/// acceleration limit, where one ends faster. Returns whether there is a span at all.
bool PieceTimer::rise_across(const Knot& k, double brake, bool have, Knot& best) {
    const double tau = n_ * tick_;
    const double lim = k.speed > 0 ? path_acceleration_limit(scaled(k.v, 1 / k.speed)) : acc_norm_;
    const double a_min = -brake * lim;
    // J tau = 2 f lim: the end acceleration up to 2 lim above the start's (the set scaled
    // to a largest f of 0.5, 1.5, 2 or 3 was not better on the bench's corner paths; f = 1
    // and 0.5 alone lose 0.04 s on the 1,000-segment spiral).
    for (const double frac : {1.0, 0.75, 0.5, 0.25}) {
        const double jerk = 2 * frac * lim / tau;
        // The largest A under beta (arithmetic only), then the executed span's limits by
        // regula falsi (Illinois) between a feasible and an infeasible A, as in step.
        if (!jerk_under_beta(k, a_min, jerk, tau)) continue;
        double a_beta = lim;
        if (!jerk_under_beta(k, a_beta, jerk, tau)) {
            double lo = a_min, hi = lim;
            for (int it = 0; it < 16; ++it) {
                const double mid = 0.5 * (lo + hi);
                (jerk_under_beta(k, mid, jerk, tau) ? lo : hi) = mid;
            }
            a_beta = lo;
        }
        Candidate hi = evaluate(k, a_beta, n_, jerk);
        if (hi.f > 0) {
            const Candidate lo = evaluate(k, a_min, n_, jerk);
            if (lo.f > 0) continue;
            hi = boundary(k, lo, hi, n_, jerk);
        }
        if (!have || hi.end.speed > best.speed) {
            best = hi.end;
            have = true;
        }
    }
    return have;
}

}  // namespace pathstream::host::planner_detail
