// The spans that end at rest exactly at the piece's end: a final span of at most
// ticks_per_span ticks (finish, finish_ok), or that span and the one before it chosen together
// (land) where no final span fits from the current knot, and the one rest-to-rest span of a
// piece too short for speed caps to resolve (creep_ticks). finish and land are tried at every
// knot before the regular span: the end must be reached at a whole tick, at rest, on the LSB
// grid, and the regular spans alone would overshoot it or stop short.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <utility>

#include "forward_pass.hpp"
#include "grid.hpp"
#include "piece_timer.hpp"
#include "vec.hpp"

namespace pathstream::host::planner_detail {

/// Ticks of a final span from k to rest at the piece's end, or 0 if none of at most
/// ticks_per_span ticks is within the limits from here.
std::uint32_t PieceTimer::finish(const Knot& k) {
    const double d = end_lambda_ - k.lambda;
    double lo_f, hi_f;
    if (d > (k.speed * tick_ + acc_norm_ * tick_ * tick_) * n_ * n_) return 0;  // far away
    if (d > feed_reach(k, 1)) return 0;  // farther than the feed goes
    // A knot whose velocity rounds to no motion on the grid starts the final span from rest.
    const Vec v_grid = span_velocity(k.v, n_);
    bool moving = false;
    for (std::size_t i = 0; i < axes_; ++i) moving = moving || v_grid[i] != 0;
    if (k.speed > 0 && moving) {
        const double kc = 2 * d / (k.speed * tick_);  // ticks at constant deceleration
        lo_f = std::floor(0.75 * kc);
        hi_f = std::ceil(1.5 * kc) + 1;
    } else {
        double t = 0;
        for (std::size_t i = 0; i < axes_; ++i) {
            t = std::max(t, std::sqrt(6 * std::fabs(end_q_[i] - k.q[i]) / acc_[i]));
        }
        t = std::max(t, std::sqrt(6 * d / acc_norm_));
        lo_f = std::ceil(t / tick_ - 1e-9);
        hi_f = n_;
    }
    if (lo_f > n_) return 0;
    const std::uint32_t lo = static_cast<std::uint32_t>(std::max(1.0, lo_f));
    const std::uint32_t hi = static_cast<std::uint32_t>(std::min<double>(n_, std::max(hi_f, lo_f)));
    const std::uint32_t stride = std::max<std::uint32_t>(1, (hi - lo) / 64);
    for (std::uint32_t t = lo; t <= hi; t += stride) {
        if (!finish_ok(k, arrival_, t)) continue;
        std::uint32_t best = t;  // with a coarse stride, look for a shorter one just below
        while (stride > 1 && best > lo && best + stride > t + 1 && finish_ok(k, arrival_, best - 1))
            --best;
        return best;
    }
    return 0;
}

/// True when the final span of `ticks` ticks from k to rest at the end is within the limits
/// and never passes the end point at a tick.
bool PieceTimer::finish_ok(const Knot& k, const Arrival& in, std::uint32_t ticks) {
    const double tau = ticks * tick_;
    const Vec v0 = span_velocity(k.v, ticks);
    // A creep from rest over the last half tolerance of the piece runs along its chord, and
    // every point of that chord is within half the remaining length of the path: the speed
    // caps (tolerance and span fit at a curvature peak of a few micrometres, which fall to
    // hundredths of a mm/s) say nothing about it, as for a piece within the tolerance.
    bool creep = end_lambda_ - k.lambda <= 0.5 * delta_;
    for (std::size_t i = 0; i < axes_ && creep; ++i) creep = v0[i] == 0;
    if (violation(k, in, end_knot(), ticks, !creep) > 0) return false;
    if (span_deviation(k, end_knot(), ticks) > deviation_limit_) return false;
    if (creep) return true;
    // Under the speed caps along the way (corners, feed, chord tolerance): the cubic's speed
    // at eighths of the span against the cap where its point projects onto the chord. (Its
    // accelerations, the bends included, were checked above on the cubic itself.)
    const Vec chord = sub(end_q_, k.q);
    const double c2 = dot(chord, chord), d = end_lambda_ - k.lambda;
    for (int s = 1; s < 8 && c2 > 0; ++s) {
        const double w = s / 8.0, w2 = w * w;
        double along = 0, speed2 = 0;
        for (std::size_t i = 0; i < axes_; ++i) {
            const double x = (2 * w2 * w - 3 * w2 + 1) * k.q[i] +
                             (w2 * w - 2 * w2 + w) * v0[i] * tau +
                             (-2 * w2 * w + 3 * w2) * end_q_[i];
            const double v = ((6 * w2 - 6 * w) * k.q[i] + (3 * w2 - 4 * w + 1) * v0[i] * tau +
                              (-6 * w2 + 6 * w) * end_q_[i]) /
                             tau;
            along += (x - k.q[i]) * chord[i];
            speed2 += v * v;
        }
        const double l = k.lambda + d * std::clamp(along / c2, 0.0, 1.0);
        const double speed = std::max(0.0, std::sqrt(speed2) - speed_rounding(tau));
        if (speed * speed > interpolate(caps_, l) * (1 + 1e-6) + 1e-9) return false;
    }
    const double len2 = c2;
    if (ticks < 2 || len2 <= 0) return true;
    const std::uint32_t samples = std::min<std::uint32_t>(ticks - 1, 64);
    for (std::uint32_t j = 1; j <= samples; ++j) {
        const double t = static_cast<double>(j) / (samples + 1);
        double along = 0;
        for (std::size_t i = 0; i < axes_; ++i) {
            const double p = hermite(k.q[i], end_q_[i], v0[i] * tau, 0, t);
            along += (p - end_q_[i]) * chord[i];
        }
        if (along > 1e-9 * len2) return false;
    }
    return true;
}

/// The last two spans at once, when the end is near: a span of m ticks (ticks_per_span / 2
/// to ticks_per_span) with constant path acceleration A, then a final span of f ticks
/// (1..ticks_per_span) to rest at the end, the fewest m + f first (a shorter first span
/// lands at a whole tick where the regular one cannot: the sharp polyline's 1,000 stops
/// needed 250 retries with m fixed, 93 with it free). Along the path both spans' end
/// accelerations are affine in A, so for each (m, f) the A that keep them within the path
/// acceleration limit L (the smallest a_i / |t_i| at the end) form an exact interval; its
/// middle, then its ends, are checked on the executed spans (at most 16,384 of them per knot,
/// which bounds only spans of about 200 ticks and more). Returns f (0: none), the knot
/// between the two spans and m (`first_ticks`).
std::uint32_t PieceTimer::land(const Knot& k, Knot& mid, std::uint32_t& first_ticks) {
    const double tau_n = n_ * tick_;
    const double d = end_lambda_ - k.lambda, v = k.speed;
    // Reachable only if the end is within two spans at the current speed plus full
    // acceleration; cheap test first.
    if (d > v * 2 * tau_n + acc_norm_ * 2 * tau_n * tau_n || d > feed_reach(k, 2)) return 0;
    std::size_t h = hint_;
    const double lim = path_acceleration_limit(path_at(pg_, piece_, end_lambda_, h).t);
    constexpr std::uint32_t kMaxEvaluated = 16384;
    std::uint32_t evaluated = 0;
    // At most 16 first-span lengths: with spans of thousands of ticks (the profile allows up
    // to 65536) the pairs would otherwise be billions at every knot near the end.
    const std::uint32_t m_min =
        jerk_limited_ ? n_ : std::max<std::uint32_t>({1, n_ / 2, n_ > 16 ? n_ - 16 : 1});
    for (std::uint32_t total = m_min + 1; total <= 2 * n_; ++total) {
        for (std::uint32_t m = std::min(n_, total - 1); m >= m_min && total - m <= n_; --m) {
            const std::uint32_t f = total - m;
            const double tau = m * tick_;
            const double tf = f * tick_;
            double lo = std::max(-lim, -v / tau), hi = lim;      // the first span, and V' >= 0
            hi = std::min(hi, 2 * (d - v * tau) / (tau * tau));  // d' >= 0
            // The final span's length d' within what the feed covers in tf: its velocity is
            // quadratic in time, so Simpson's rule gives its chord exactly from its start
            // (under beta, so the feed), its middle (checked against the feed plus the
            // rounding allowance) and its end (rest); 5 % and two more allowances for the
            // path's arc over the chord and the grid. At a slow feed, with spans of thousands
            // of ticks, nearly every pair passes the acceleration bounds below, and the pairs
            // whose final span could only fail the feed made landing cost seconds.
            lo = std::max(
                lo, 2 * (d - v * tau - 1.05 * feed_ * tf - 3 * root_axes_ * lsb_) / (tau * tau));
            // Final span along the path: a0 = 6 d'/tf^2 - 4 V'/tf, a1 = -6 d'/tf^2 + 2 V'/tf.
            const double base = 6 * (d - v * tau) / (tf * tf);
            const double a0c = base - 4 * v / tf, a0s = -(3 * tau * tau / (tf * tf) + 4 * tau / tf);
            const double a1c = -base + 2 * v / tf, a1s = 3 * tau * tau / (tf * tf) + 2 * tau / tf;
            for (const auto& [c, sl] : {std::pair{a0c, a0s}, std::pair{a1c, a1s}}) {
                double x = (-lim - c) / sl, y = (lim - c) / sl;
                if (x > y) std::swap(x, y);
                lo = std::max(lo, x);
                hi = std::min(hi, y);
            }
            if (lo > hi) continue;
            for (const double a :
                 {0.5 * (lo + hi), hi, lo, lo + 0.75 * (hi - lo), lo + 0.25 * (hi - lo)}) {
                if (!under_beta(k, a, tau)) continue;
                // Spans of thousands of ticks (a profile's, or a slow feed's, with 1-LSB hops
                // where even the longest span covers under an LSB) have millions of pairs:
                // the next knot tries again, nearer.
                if (++evaluated > kMaxEvaluated) return 0;
                Candidate c = evaluate(k, a, m);
                // A knot on the end point: moving, the final span would leave it and come back
                // (a stop with a wiggle of an LSB); at rest, it would only wait there.
                if (c.f > 0 || c.end.q == end_q_ || !finish_ok(c.end, Arrival{k, m}, f)) continue;
                mid = c.end;
                first_ticks = m;
                return f;
            }
        }
    }
    return 0;
}

/// Ticks of the rest-to-rest span from q to the end (zero tangents: peak acceleration
/// 6 d / tau^2 and peak velocity 1.5 d / tau per axis), the fewest within the limits and the
/// feed; 0 when q is the end already.
std::uint32_t PieceTimer::creep_ticks(const Vec& q) const {
    double tau = 0, d2 = 0;
    for (std::size_t i = 0; i < axes_; ++i) {
        const double d = std::fabs(end_q_[i] - q[i]);
        d2 += d * d;
        tau = std::max({tau, std::sqrt(6 * d / acc_[i]), 1.5 * d / vel_[i]});
    }
    if (!(d2 > 0)) return 0;
    tau = std::max(tau, 1.5 * std::sqrt(d2) / feed_);
    return static_cast<std::uint32_t>(std::clamp(std::ceil(tau / tick_ - 1e-9), 1.0, 65536.0));
}

}  // namespace pathstream::host::planner_detail
