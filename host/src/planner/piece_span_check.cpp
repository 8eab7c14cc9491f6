// What the executed span breaks: a candidate span's end moved onto the LSB grid as the
// emitter will round it (fit_end), then the cubic the device will run between its two knots
// measured against the axis limits, the feed, the speed caps and the velocity jump where the
// tick count changes (violation, junction), and against the chord tolerance (span_deviation).
// Every span the forward pass keeps has passed them: the limits hold for the exact cubic, not
// only for the planned profile.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "forward_pass.hpp"
#include "grid.hpp"
#include "lsb_rounding.hpp"
#include "piece_timer.hpp"
#include "vec.hpp"

namespace pathstream::host::planner_detail {

/// The end point and end velocity of a span of m ticks from k0 (start velocity v0) moved to
/// the LSB grid: rounded to nearest, unless that puts an axis over its limits (rounding
/// moves the end accelerations by up to 9 / m^2 LSB/tick^2), in which case the point and
/// the tangent may each move one LSB further: the nearest combination within the limits,
/// else the least violating one (the caller's search then backs off).
void PieceTimer::fit_end(const Knot& k0, const Vec& v0, Knot& k1, std::uint32_t m) const {
    const double tau = m * tick_, scale = tangent_scale(m, tick_hz_, lsb_);
    for (std::size_t i = 0; i < axes_; ++i) {
        // In LSB: a0 m^2 = 6 dP - 4 T0 - 2 T1, a1 m^2 = -6 dP + 2 T0 + 4 T1, p'(u) = T.
        const double lim_a = acc_[i] * tau * tau / lsb_, lim_v = vel_[i] * scale;
        const double p0 = std::round(k0.q[i] / lsb_);
        const double t0 = static_cast<double>(scaled_tangent_lsb(v0[i], scale));
        const double p = std::round(k1.q[i] / lsb_);
        const double t = static_cast<double>(scaled_tangent_lsb(k1.v[i], scale));
        const auto cost = [&](double p1, double t1) {
            const double a0 = 6 * (p1 - p0) - 4 * t0 - 2 * t1,
                         a1 = -6 * (p1 - p0) + 2 * t0 + 4 * t1;
            double peak = std::max(std::fabs(t0), std::fabs(t1));
            if (a0 * a1 < 0) peak = std::max(peak, std::fabs(t0 + 0.5 * a0 * a0 / (a0 - a1)));
            return std::max(std::max(std::fabs(a0), std::fabs(a1)) / lim_a, peak / lim_v);
        };
        double best = cost(p, t), bp = 0, bt = 0;
        for (int dp = -1; dp <= 1 && best > 1; ++dp) {
            for (int dt = -1; dt <= 1; ++dt) {
                const double c = cost(p + dp, t + dt);
                const bool nearer = std::abs(dp) + std::abs(dt) < std::fabs(bp) + std::fabs(bt);
                if ((c <= 1 && (best > 1 || nearer)) || (best > 1 && c < best)) {
                    best = c;
                    bp = dp;
                    bt = dt;
                }
            }
        }
        k1.q[i] = (p + bp) * lsb_;
        k1.v[i] = (t + bt) / scale;
    }
}

/// Where the tick count changes at a moving knot, the two spans' tangents are rounded on
/// different scales and the velocity jumps by up to 1/2 LSB per tick of the shorter one:
/// the second difference of the exact cubic across the knot (tick before, knot, tick
/// after) over each axis's limit. 0 where the tick count does not change (then it is a
/// weighted mean of the two spans' accelerations, which are checked).
inline double PieceTimer::junction(const Arrival& in, const Knot& k0, const Vec& v0, const Knot& k1,
                                   std::uint32_t m) const {
    if (in.ticks == 0 || in.ticks == m) return 0;
    const double tp = in.ticks * tick_, tau = m * tick_;
    const Vec va = span_velocity(in.from.v, in.ticks);
    double worst = 0;
    for (std::size_t i = 0; i < axes_; ++i) {
        const double before =
            hermite(in.from.q[i] - k0.q[i], 0, va[i] * tp, k0.v[i] * tp, 1 - 1.0 / in.ticks);
        const double after = hermite(0, k1.q[i] - k0.q[i], v0[i] * tau, k1.v[i] * tau, 1.0 / m);
        worst = std::max(worst, std::fabs(before + after) / (tick_ * tick_ * acc_[i]));
    }
    return worst;
}

/// How far the Hermite span between two knots over tau seconds exceeds the limits: max over
/// axes of |acceleration| / limit (exact: it is linear in a cubic, so its ends bound it) and
/// peak |velocity| / limit (exact: at the ends or where the acceleration crosses 0), and the
/// speed at eighths of the span over the feed and the speed cap there (less the rounding of
/// the tangents; with `caps` false only the feed), and the junction with the span before
/// (`in`). <= 0: within.
/// Relative: the check is ratio - 1. The knots are on the LSB grid, k1.v rounded for this
/// span and k0's velocity rounded for it (v0), so this is the span the device runs.
double PieceTimer::violation(const Knot& k0, const Arrival& in, const Knot& k1, std::uint32_t m,
                             const Vec& v0, bool caps) const {
    const double tau = m * tick_;
    const Vec &q0 = k0.q, &q1 = k1.q, &v1 = k1.v;
    double worst = 0;
    constexpr int kSamples = 7;
    Vec at[kSamples] = {};
    static constexpr double kW[kSamples] = {0.125, 0.25, 0.375, 0.5, 0.625, 0.75, 0.875};
    for (std::size_t i = 0; i < axes_; ++i) {
        const double d = q1[i] - q0[i];
        const double a0 = 6 * d / (tau * tau) - (4 * v0[i] + 2 * v1[i]) / tau;
        const double a1 = -6 * d / (tau * tau) + (2 * v0[i] + 4 * v1[i]) / tau;
        worst = std::max(worst, std::max(std::fabs(a0), std::fabs(a1)) / acc_[i]);
        double peak = std::max(std::fabs(v0[i]), std::fabs(v1[i]));
        if (a0 * a1 < 0) {
            const double t = tau * a0 / (a0 - a1);
            peak = std::max(peak, std::fabs(v0[i] + 0.5 * a0 * t));
        }
        worst = std::max(worst, peak / vel_[i]);
        for (int s = 0; s < kSamples;
             ++s) {  // velocity at t = w tau: v0 + a0 w tau + (a1 - a0) w^2 tau / 2
            at[s][i] = v0[i] + tau * (a0 * kW[s] + (a1 - a0) * kW[s] * kW[s] / 2);
        }
    }
    // Speed along the path at every eighth of the span, against the feed and the speed cap
    // where the path profile (constant acceleration) is then.
    const double acc = (k1.speed - k0.speed) / tau, rounding = speed_rounding(tau);
    for (int s = 0; s < kSamples; ++s) {
        const double t = kW[s] * tau;
        const double speed = std::max(0.0, norm(at[s]) - rounding);
        const double cap =
            interpolate(caps_, std::clamp(k0.lambda + k0.speed * t + 0.5 * acc * t * t, k0.lambda,
                                          std::max(k0.lambda, k1.lambda)));
        worst = std::max(worst, speed / feed_);
        if (!caps) continue;
        if (cap > 0)
            worst = std::max(worst, speed / std::sqrt(cap));
        else if (speed > 0)
            worst = std::max(worst, 2.0);
    }
    worst = std::max(worst, junction(in, k0, v0, k1, m));
    return worst - 1;
}

/// Largest distance of the executed cubic from the path at sixths of the span (at every tick
/// across a corner or a curvature jump), measured across the path at the arc length where
/// the cubic's point projects onto the chord. Skipped (0) where neither the curvature it
/// passes (chord^2 kappa / 8 < delta / 64) nor its end tangents can move it off the path: no
/// corner, no swing, no bulge (below).
double PieceTimer::span_deviation(const Knot& k, const Knot& end, std::uint32_t m, const Vec& v0) {
    const double tau = m * tick_;
    const double len = end.lambda - k.lambda;
    double kappa = 0;
    bool corner = false, curvature_step = false;
    for (std::size_t i = interval(k.lambda); i <= piece_.last && g_.lambda[i] <= end.lambda + 1e-12;
         ++i) {
        kappa = std::max(kappa, g_.curvature_norm[i]);
        if (i + 1 <= piece_.last) {
            kappa = std::max(kappa, g_.curvature_norm[i + 1]);
            // The cubic's distance from the path has a kink there, which samples at sixths
            // can straddle.
            curvature_step = curvature_step || curvature_jump(i);
        }
        corner = corner || g_.corner[i] != 0;
    }
    const Vec chord = sub(end.q, k.q);
    const double c2 = dot(chord, chord);
    // A Hermite cubic stays between its ends only while its tangents are at most three
    // chords long: a span from rest with a far faster end velocity (an end point pulled
    // back by an axis with little acceleration) swings out behind its start.
    const double tangent_reach = std::max(norm(v0), norm(end.v)) * tau;
    const bool swings = tangent_reach * tangent_reach > 9 * c2;
    // The cubic leaves its chord by at most 4/27 of each end tangent's part across it (where
    // the Hermite basis of a tangent peaks): a tangent rounded on a far shorter span's scale
    // (a 4-tick span's, carried into a 61-tick one) pointed 12 degrees off a straight line
    // and bulged 17.4 um from it where the curvature alone let the check be skipped.
    const auto bulges = [&] {
        double across = 0;
        for (const Vec* t : {&v0, &end.v}) {
            const double along = c2 > 0 ? dot(*t, chord) / std::sqrt(c2) : 0;
            across += std::sqrt(std::max(0.0, dot(*t, *t) - along * along));
        }
        return 4.0 / 27 * tau * across > 0.25 * delta_;
    };
    if (!corner && !swings && len * len * kappa / 8 < delta_ / 64 && !bulges()) return 0;
    double worst = 0;
    std::size_t h = hint_;
    // At sixths of the span; where it crosses a corner or a curvature step, at every tick as
    // check_plan measures it (a multiple of m, at least 6), on spans of up to 256 ticks
    // (longer ones get 256 even samples): 24 samples on a 61-tick span across a blend missed
    // the tolerance by 1.4 um between them.
    const std::uint32_t per_tick = (6 + m - 1) / m * m;
    const int samples =
        corner || curvature_step ? static_cast<int>(std::min<std::uint32_t>(per_tick, 256)) : 6;
    for (int s = 1; s < samples; ++s) {
        const double w = static_cast<double>(s) / samples, w2 = w * w, w3 = w2 * w;
        const double h00 = 2 * w3 - 3 * w2 + 1, h10 = w3 - 2 * w2 + w, h01 = -2 * w3 + 3 * w2,
                     h11 = w3 - w2;
        Vec x{};
        for (std::size_t i = 0; i < axes_; ++i) {
            x[i] = h00 * k.q[i] + h10 * v0[i] * tau + h01 * end.q[i] + h11 * end.v[i] * tau;
        }
        const double raw = c2 > 0 ? dot(sub(x, k.q), chord) / c2 : w;
        const double along = std::clamp(raw, 0.0, 1.0);
        const PathAt p = path_at(pg_, piece_, k.lambda + along * len, h, false);
        const Vec off = sub(x, p.q);
        // Beyond either end of the chord the cubic has left the span's stretch of path
        // (backwards, or past its end): the whole distance counts, not only the part
        // across the path.
        const bool outside = raw < 0 || raw > 1;
        worst = std::max(worst, outside ? norm(off) : norm(sub(off, scaled(p.t, dot(off, p.t)))));
    }
    return worst;
}

}  // namespace pathstream::host::planner_detail
