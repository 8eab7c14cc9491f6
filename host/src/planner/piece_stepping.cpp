// The forward pass in whole ticks: from rest at the start of a piece, one span of
// ticks_per_span ticks at a time, each with constant acceleration along the path, as fast as
// the executed Hermite span allows and never above the lookahead's controllable speed (beta);
// then a final span of at most ticks_per_span ticks (alone, or with the span before it chosen
// for it) that ends at rest exactly at the piece's end. What is checked is the cubic the
// device will run between two knots (positions and velocities at both ends), not the
// continuous profile, so acceleration switches inside a span cannot overshoot the limits.
//
// This file holds the loop over knots (run) and the regular span's search (step, boundary,
// evaluate), which the landings, the final spans and rise_across call back into.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "forward_pass.hpp"
#include "grid.hpp"
#include "limits.hpp"
#include "lsb_rounding.hpp"
#include "pathstream/host/planner.hpp"
#include "pathstream/machine/machine.hpp"
#include "piece_timer.hpp"
#include "vec.hpp"

namespace pathstream::host::planner_detail {

PieceTimer::PieceTimer(const PathGrid& pg, const Piece& piece, const Limits& limits,
                       const std::vector<double>& caps, const std::vector<double>& beta,
                       const MachineProfile& profile, const PlanOptions& options)
    : pg_(pg),
      g_(pg.grid),
      piece_(piece),
      caps_(caps),
      beta_(beta),
      axes_(pg.grid.axes),
      tick_(1.0 / profile.tick_hz),
      tick_hz_(profile.tick_hz),
      // Longer where the piece's feed is far below an LSB per span (feed_span_ticks).
      n_(feed_span_ticks(profile.ticks_per_span, piece.feed, profile.tick_hz, profile.mm_per_lsb)),
      jerk_limited_(limits.has_jerk()) {
    // The spans are checked exactly as the device will run them (end points and tangents
    // rounded to LSB), against the limits less a hair for the double arithmetic.
    constexpr double kExact = 1 - 1e-9;
    for (std::size_t i = 0; i < axes_; ++i) {
        acc_[i] = limits.acceleration[i] * options.acceleration_margin * kExact;
        vel_[i] = limits.velocity[i] * options.velocity_margin * kExact;
        acc_norm_ += acc_[i] * acc_[i];
    }
    lsb_ = profile.mm_per_lsb;
    root_axes_ = std::sqrt(static_cast<double>(axes_));
    acc_norm_ = std::sqrt(acc_norm_);
    feed_ = piece.feed * options.feed_margin;
    delta_ = profile.chord_tolerance;
    // Knots sit on the LSB grid, up to 1.5 LSB per axis off the path after a repair.
    deviation_limit_ = 0.5 * delta_ + root_axes_ * lsb_;
    end_lambda_ = g_.lambda[piece.last];
    end_q_ = grid_point(g_.q[piece.last]);
    // The final interval. Between nodes beta is linear in arc length (TOPP-RA's constant path
    // acceleration), and in the interval that ends at rest that is a constant deceleration
    // across the whole interval: where stopping takes far less (a slow feed, 1 mm/min, stops
    // within nanometres; the interval may be 0.5 mm long), the motion crawled to the end at
    // a speed falling with the square root of the distance left, up to the interval's time
    // at the feed lost at every stop (17 % of a 0.6 mm line's). There, s^2 may also be what
    // braking at half the acceleration along the path stops from at the end (less what the
    // curvature of the interval takes at the interval's beta), up to that beta: the final
    // spans are checked against the limits as every span is.
    std::size_t i = piece.last;
    while (i > piece.first && !(g_.lambda[i - 1] < end_lambda_)) --i;
    if (i > piece.first) {
        const std::size_t a = i - 1, b = piece.last;
        const double x = std::min(beta_[a], caps_[b]), dl = end_lambda_ - g_.lambda[a];
        double u = acc_norm_;
        for (std::size_t ax = 0; ax < axes_; ++ax) {
            const double kappa =
                std::max(std::fabs(g_.curvature[a][ax]), std::fabs(g_.curvature[b][ax]));
            u = std::min(u, 0.5 * acc_[ax] - kappa * x);
        }
        // Only where the linear beta brakes at under a quarter of that: elsewhere the
        // interval's stop is as the lookahead planned it.
        if (u > 0 && x > 0 && 2 * u * dl >= 4 * x) {
            stop_from_ = g_.lambda[a];
            stop_decel_ = u;
            stop_x_ = x;
        }
    }
}

PieceMotion PieceTimer::run(const Vec& start_q, PieceMotion* resume, double resume_lambda,
                            bool short_spans) {
    PieceMotion out;
    Knot k;
    k.lambda = g_.lambda[piece_.first];
    k.q = start_q;
    out.start = k;
    arrival_ = Arrival{};
    if (piece_.first == piece_.last || !(end_lambda_ - k.lambda > 1e-12)) return out;
    // A piece no longer than the chord tolerance (a cusp's tip, a loop of a few LSB, points
    // an LSB apart) is below what speed caps and spans of whole ticks can resolve: one span
    // from rest to rest along its chord stays within the tolerance of it.
    if (end_lambda_ - k.lambda <= delta_) {
        if (const std::uint32_t m = creep_ticks(k.q); m > 0) out.spans.push_back({m, end_knot()});
        return out;
    }
    // Spans never go faster than the feed: the piece needs at least length / (feed tau) of
    // them; reserving a quarter more spares most of the vector's regrowth and copies.
    const double at_feed = (end_lambda_ - k.lambda) / (feed_ * n_ * tick_);
    if (at_feed > 0 && at_feed < 1e6)
        out.spans.reserve(static_cast<std::size_t>(1.25 * at_feed) + 8);
    const auto advance = [&](const MotionSpan& s) {
        out.spans.push_back(s);
        arrival_ = Arrival{k, s.ticks};
        k = s.end;
    };
    if (resume != nullptr) {
        // Keep the knots (and the spans ending there) before resume_lambda: the attempt's
        // spans are taken over and cut, not copied, so a retry costs what it replans.
        std::vector<MotionSpan>& kept = resume->spans;
        const auto cut = std::partition_point(kept.begin(), kept.end(), [&](const MotionSpan& s) {
            return s.end.lambda < resume_lambda && s.end.lambda < end_lambda_;
        });
        kept.erase(cut, kept.end());
        out.spans = std::move(kept);
        if (!out.spans.empty()) {
            const std::size_t n = out.spans.size();
            arrival_ = Arrival{n >= 2 ? out.spans[n - 2].end : out.start, out.spans[n - 1].ticks};
            k = out.spans[n - 1].end;
        }
    }
    const std::size_t limit = 50'000'000;
    std::size_t stalled = 0;
    std::uint32_t first_ticks = n_;
    while (out.spans.size() < limit) {
        if (const std::uint32_t f = finish(k); f > 0) {
            out.spans.push_back({f, end_knot()});
            return out;
        }
        if (Knot mid; const std::uint32_t f = land(k, mid, first_ticks)) {
            out.spans.push_back({first_ticks, mid});
            out.spans.push_back({f, end_knot()});
            return out;
        }
        Knot next;
        const bool leaving_dip = on_dip_;
        on_dip_ = false;
        std::uint32_t ticks = corner_landing(k, next);
        if (ticks == 0) ticks = dip_landing(k, next);
        if (ticks == 0 && leaving_dip) ticks = leave_dip(k, next);
        const bool regular = ticks == 0;
        for (std::uint32_t m = n_; m >= (short_spans ? 1u : n_) && ticks == 0; --m) {
            if (step(k, m, next)) ticks = m;
        }
        // A regular span across a curvature jump that slows down to its end where beta there
        // allows more (x under 0.9 beta) was held down by a dip it passes (one no knot landed
        // on) and kept braking after it: its path acceleration may rise along it, with a mean
        // A >= -0.85 L (-0.5 L to -L were within 0.07 s of each other on the bench's corner
        // paths; the executed span is checked as every span is).
        if (regular && !jerk_limited_ && ticks == n_ && next.speed < k.speed &&
            next.speed * next.speed < 0.9 * beta_at(next.lambda) &&
            steps_between(k.lambda, next.lambda)) {
            (void)rise_across(k, 0.85, true, next);
        }
        // A run of spans that leave the point on the LSB grid where it is makes no progress
        // the device could see (creeping towards a stop in ever smaller steps): stuck.
        stalled = next.q == k.q ? stalled + 1 : 0;
        if (ticks == 0 || (!(next.lambda > k.lambda) && next.speed <= 0 && k.speed <= 0) ||
            stalled > 256) {
            out.ok = false;
            out.fail_lambda = k.lambda;
            out.fail_speed = k.speed;
            return out;
        }
        advance({ticks, next});
    }
    out.ok = false;
    out.fail_lambda = k.lambda;
    out.fail_speed = k.speed;
    return out;
}

/// One span of m ticks from k: the largest constant path acceleration (end speed) under
/// beta whose executed span, with its end point moved by the allowed offset (evaluate), is
/// within the limits.
bool PieceTimer::step(const Knot& k, std::uint32_t m, Knot& next) {
    const double tau = m * tick_;
    const double a_lo = -k.speed / tau;
    double a_hi;
    if (!max_under_beta(k, tau, a_lo, acc_norm_, a_hi)) return false;
    Candidate hi = evaluate(k, a_hi, m);
    if (hi.f <= 0) {
        next = hi.end;
        return true;
    }
    // No feasible span accelerates harder than the axes allow: search from there.
    const double a_floor = std::min(a_hi, std::max(a_lo, -1.5 * acc_norm_));
    Candidate lo = evaluate(k, a_floor, m);
    if (lo.f > 0) {
        // The violation is (nearly) a maximum of affine functions of the acceleration, so
        // convex: golden-section search for its minimum, a feasible span if any exists.
        constexpr double kGolden = 0.6180339887498949;
        double x0 = a_floor, x3 = a_hi;
        double x1 = x3 - kGolden * (x3 - x0), x2 = x0 + kGolden * (x3 - x0);
        Candidate c1 = evaluate(k, x1, m), c2 = evaluate(k, x2, m);
        Candidate c3 = hi;  // at x3: over the limits, like every point the search dropped
        for (int it = 0; it < 48 && c1.f > 0 && c2.f > 0; ++it) {
            if (c1.f <= c2.f) {
                x3 = x2;
                c3 = c2;
                x2 = x1;
                c2 = c1;
                x1 = x3 - kGolden * (x3 - x0);
                c1 = evaluate(k, x1, m);
            } else {
                x0 = x1;
                x1 = x2;
                c1 = c2;
                x2 = x0 + kGolden * (x3 - x0);
                c2 = evaluate(k, x2, m);
            }
        }
        if (c1.f > 0 && c2.f > 0) return false;
        // The boundary lies between the highest feasible point (x1 < x2) and the nearest
        // infeasible one above it, a bracket the search has already narrowed.
        if (c2.f <= 0) {
            lo = c2;
            hi = c3;
        } else {
            lo = c1;
            hi = c2;
        }
    }
    next = boundary(k, lo, hi, m, 0).end;
    return true;
}

/// The feasible end of [lo, hi] (lo within the limits, hi not): regula falsi (Illinois) on
/// the violation, to 1e-4 of the acceleration limit (a finer one bought no measurable
/// motion time), or to 1e-3 of the speed over the span where that is finer: at a feed far
/// below what the acceleration reaches in one span (1 mm/min at 3000 mm/s^2, 0.48 s spans)
/// the whole bracket from stopping to cruising is under 1e-4 of the limit, and the search
/// stopped the motion wherever the cruise's rounding onto the LSB grid failed a check.
/// Spans of m ticks with the path acceleration's slope `jerk` (evaluate).
PieceTimer::Candidate PieceTimer::boundary(const Knot& k, Candidate lo, Candidate hi,
                                           std::uint32_t m, double jerk) {
    int side = 0;
    double flo = lo.f, fhi = hi.f;
    const double tol = std::min(1e-4 * acc_norm_, 1e-3 * std::max(k.speed, feed_) / (m * tick_));
    for (int it = 0; it < 40 && hi.a - lo.a > tol; ++it) {
        double a = lo.a - flo * (hi.a - lo.a) / (fhi - flo);
        if (!(a > lo.a && a < hi.a)) a = 0.5 * (lo.a + hi.a);
        Candidate c = evaluate(k, a, m, jerk);
        if (c.f <= 0) {
            lo = c;
            flo = c.f;
            if (side == -1) fhi *= 0.5;
            side = -1;
        } else {
            hi = c;
            fhi = c.f;
            if (side == +1) flo *= 0.5;
            side = +1;
        }
    }
    return lo;
}

/// The span of tau seconds from k with constant path acceleration a: end speed
/// V1 = V0 + a tau at arc length l1 = l0 + V0 tau + a tau^2 / 2 + offset. The end
/// accelerations of the executed cubic are very sensitive to the end point (6 / tau^2 per
/// mm), so a small offset along the path (at most a tenth of a full-acceleration span's
/// distance, typically micrometres) lets them absorb what a constant path acceleration gets
/// wrong where the curvature changes along the span: the offset nearest 0 that the
/// linearised end accelerations allow. f <= 0 means the span is within the limits and its
/// end under beta.
PieceTimer::Candidate PieceTimer::evaluate(const Knot& k, double a, std::uint32_t m, double jerk) {
    const double tau = m * tick_;
    const Vec v0 = span_velocity(k.v, m);
    Candidate c;
    c.a = a;
    c.end.speed = std::max(0.0, k.speed + a * tau);
    const double l1 = std::min(
        end_lambda_, k.lambda + k.speed * tau + 0.5 * a * tau * tau - jerk * tau * tau * tau / 12);
    c.end.lambda = l1;
    PathAt p = path_at(pg_, piece_, l1, hint_);
    const double v1 = c.end.speed;
    // d(a0)/d(offset) and d(a1)/d(offset) per axis: the end point moves along the tangent,
    // the end velocity turns with the curvature.
    const Vec kappa = curvature_at(l1);
    double off_lo = -0.1 * acc_norm_ * tau * tau, off_hi = -off_lo;
    off_lo = std::max(off_lo, k.lambda - l1);
    off_hi = std::min(off_hi, end_lambda_ - l1);
    for (std::size_t i = 0; i < axes_ && off_lo <= off_hi; ++i) {
        const double d = p.q[i] - k.q[i];
        const double a0 = 6 * d / (tau * tau) - (4 * v0[i] + 2 * v1 * p.t[i]) / tau;
        const double a1 = -6 * d / (tau * tau) + (2 * v0[i] + 4 * v1 * p.t[i]) / tau;
        const double s0 = 6 * p.t[i] / (tau * tau) - 2 * v1 * kappa[i] / tau;
        const double s1 = -6 * p.t[i] / (tau * tau) + 4 * v1 * kappa[i] / tau;
        for (const auto& [val, slope] : {std::pair{a0, s0}, std::pair{a1, s1}}) {
            if (std::fabs(slope) < 1e-300) continue;
            double x = (-acc_[i] - val) / slope, y = (acc_[i] - val) / slope;
            if (x > y) std::swap(x, y);
            off_lo = std::max(off_lo, x);
            off_hi = std::min(off_hi, y);
        }
    }
    if (off_lo <= off_hi && !(off_lo <= 0 && off_hi >= 0)) {
        // Nearest to 0, a tenth of the window inside it (the linearisation is not exact).
        const double w = 0.1 * (off_hi - off_lo);
        const double off = off_lo > 0 ? off_lo + w : off_hi - w;
        c.end.lambda = std::clamp(l1 + off, k.lambda, end_lambda_);
        p = path_at(pg_, piece_, c.end.lambda, hint_);
    }
    c.end.q = p.q;
    c.end.v = scaled(p.t, v1);
    fit_end(k, v0, c.end, m);
    c.f = violation(k, arrival_, c.end, m, v0);
    c.f = std::max(c.f, span_deviation(k, c.end, m, v0) / deviation_limit_ - 1);
    const double b1 = beta_at(c.end.lambda);
    if (v1 * v1 > b1 * (1 + 1e-6) + 1e-9) c.f = std::max(c.f, 1e-3);
    return c;
}

PieceMotion forward_pass(const PathGrid& g, const Piece& piece, const Limits& limits,
                         const std::vector<double>& caps, const std::vector<double>& beta,
                         const MachineProfile& profile, const PlanOptions& options,
                         const Vec& start_q, PieceMotion* resume, double resume_lambda,
                         bool short_spans) {
    PieceTimer timer(g, piece, limits, caps, beta, profile, options);
    return timer.run(start_q, resume, resume_lambda, short_spans);
}

}  // namespace pathstream::host::planner_detail
