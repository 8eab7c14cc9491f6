// The forward pass in whole ticks: from rest at the start of a piece, one span of
// ticks_per_span ticks at a time, each with constant acceleration along the path, as fast as
// the executed Hermite span allows and never above the lookahead's controllable speed (beta);
// then a final span of at most ticks_per_span ticks (alone, or with the span before it chosen
// for it) that ends at rest exactly at the piece's end. What is checked is the cubic the
// device will run between two knots (positions and velocities at both ends), not the
// continuous profile, so acceleration switches inside a span cannot overshoot the limits.
#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "internal.hpp"

namespace pathstream::host::planner_detail {
namespace {

class PieceTimer {
public:
    PieceTimer(const PathGrid& pg, const Piece& piece, const Limits& limits,
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
          n_(profile.ticks_per_span),
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
    }

    PieceMotion run(const Vec& start_q, PieceMotion* resume, double resume_lambda, bool short_spans) {
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
        if (at_feed > 0 && at_feed < 1e6) out.spans.reserve(static_cast<std::size_t>(1.25 * at_feed) + 8);
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
            if (ticks == 0 || (!(next.lambda > k.lambda) && next.speed <= 0 && k.speed <= 0) || stalled > 256) {
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

private:
    /// Ticks of the rest-to-rest span from q to the end (zero tangents: peak acceleration
    /// 6 d / tau^2 and peak velocity 1.5 d / tau per axis), the fewest within the limits and the
    /// feed; 0 when q is the end already.
    std::uint32_t creep_ticks(const Vec& q) const {
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

    /// A point as a span carries it: on the LSB grid, rounded as the emitter rounds it.
    Vec grid_point(const Vec& q) const { return on_lsb_grid(q, lsb_, axes_); }

    /// The velocity a span of m ticks carries for v: its tangent dp/du = v m T / lsb rounded to
    /// a whole LSB, as the emitter rounds it.
    Vec span_velocity(const Vec& v, std::uint32_t m) const {
        const double scale = tangent_scale(m, tick_hz_, lsb_);
        Vec r{};
        for (std::size_t i = 0; i < axes_; ++i)
            r[i] = static_cast<double>(scaled_tangent_lsb(v[i], scale)) / scale;
        return r;
    }

    /// The end point and end velocity of a span of m ticks from k0 (start velocity v0) moved to
    /// the LSB grid: rounded to nearest, unless that puts an axis over its limits (rounding
    /// moves the end accelerations by up to 9 / m^2 LSB/tick^2), in which case the point and
    /// the tangent may each move one LSB further: the nearest combination within the limits,
    /// else the least violating one (the caller's search then backs off).
    void fit_end(const Knot& k0, const Vec& v0, Knot& k1, std::uint32_t m) const {
        const double tau = m * tick_, scale = tangent_scale(m, tick_hz_, lsb_);
        for (std::size_t i = 0; i < axes_; ++i) {
            // In LSB: a0 m^2 = 6 dP - 4 T0 - 2 T1, a1 m^2 = -6 dP + 2 T0 + 4 T1, p'(u) = T.
            const double lim_a = acc_[i] * tau * tau / lsb_, lim_v = vel_[i] * scale;
            const double p0 = std::round(k0.q[i] / lsb_);
            const double t0 = static_cast<double>(scaled_tangent_lsb(v0[i], scale));
            const double p = std::round(k1.q[i] / lsb_);
            const double t = static_cast<double>(scaled_tangent_lsb(k1.v[i], scale));
            const auto cost = [&](double p1, double t1) {
                const double a0 = 6 * (p1 - p0) - 4 * t0 - 2 * t1, a1 = -6 * (p1 - p0) + 2 * t0 + 4 * t1;
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

    /// The span that arrived at a knot: where it started and its ticks (0: none, at rest).
    struct Arrival {
        Knot from;
        std::uint32_t ticks = 0;
    };

    /// Where the tick count changes at a moving knot, the two spans' tangents are rounded on
    /// different scales and the velocity jumps by up to 1/2 LSB per tick of the shorter one:
    /// the second difference of the exact cubic across the knot (tick before, knot, tick
    /// after) over each axis's limit. 0 where the tick count does not change (then it is a
    /// weighted mean of the two spans' accelerations, which are checked).
    double junction(const Arrival& in, const Knot& k0, const Vec& v0, const Knot& k1, std::uint32_t m) const {
        if (in.ticks == 0 || in.ticks == m) return 0;
        const double tp = in.ticks * tick_, tau = m * tick_;
        const Vec va = span_velocity(in.from.v, in.ticks);
        double worst = 0;
        for (std::size_t i = 0; i < axes_; ++i) {
            const double before = hermite(in.from.q[i] - k0.q[i], 0, va[i] * tp, k0.v[i] * tp, 1 - 1.0 / in.ticks);
            const double after = hermite(0, k1.q[i] - k0.q[i], v0[i] * tau, k1.v[i] * tau, 1.0 / m);
            worst = std::max(worst, std::fabs(before + after) / (tick_ * tick_ * acc_[i]));
        }
        return worst;
    }

    Knot end_knot() const {
        Knot e;
        e.lambda = end_lambda_;
        e.q = end_q_;
        return e;
    }

    /// The last two spans at once, when the end is near: a span of m ticks (ticks_per_span / 2
    /// to ticks_per_span) with constant path acceleration A, then a final span of f ticks
    /// (1..ticks_per_span) to rest at the end, the fewest m + f first (a shorter first span
    /// lands at a whole tick where the regular one cannot: the sharp polyline's 1,000 stops
    /// needed 250 retries with m fixed, 93 with it free). Along the path both spans' end
    /// accelerations are affine in A, so for each (m, f) the A that keep them within the path
    /// acceleration limit L (the smallest a_i / |t_i| at the end) form an exact interval; its
    /// middle, then its ends, are checked on the executed spans. Returns f (0: none), the knot
    /// between the two spans and m (`first_ticks`).
    std::uint32_t land(const Knot& k, Knot& mid, std::uint32_t& first_ticks) {
        const double tau_n = n_ * tick_;
        const double d = end_lambda_ - k.lambda, v = k.speed;
        // Reachable only if the end is within two spans at the current speed plus full
        // acceleration; cheap test first.
        if (d > v * 2 * tau_n + acc_norm_ * 2 * tau_n * tau_n) return 0;
        std::size_t h = hint_;
        const double lim = path_acceleration_limit(path_at(pg_, piece_, end_lambda_, h).t);
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
                // Final span along the path: a0 = 6 d'/tf^2 - 4 V'/tf, a1 = -6 d'/tf^2 + 2 V'/tf.
                const double base = 6 * (d - v * tau) / (tf * tf);
                const double a0c = base - 4 * v / tf,
                             a0s = -(3 * tau * tau / (tf * tf) + 4 * tau / tf);
                const double a1c = -base + 2 * v / tf,
                             a1s = 3 * tau * tau / (tf * tf) + 2 * tau / tf;
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
                    Candidate c = evaluate(k, a, m);
                    // A knot on the end point: moving, the final span would leave it and come back
                    // (a stop with a wiggle of an LSB); at rest, it would only wait there.
                    if (c.f > 0 || c.end.q == end_q_ || !finish_ok(c.end, Arrival{k, m}, f))
                        continue;
                    mid = c.end;
                    first_ticks = m;
                    return f;
                }
            }
        }
        return 0;
    }

    /// Node index of the interval holding lambda (lambda[i] <= lambda < lambda[i+1]).
    /// The lookups come in runs near each other: a short walk from the last answer first, a
    /// binary search when that does not reach.
    std::size_t interval(double lambda) const {
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

    double interpolate(const std::vector<double>& v, double lambda) const {
        const std::size_t i = interval(lambda);
        const double l0 = g_.lambda[i], l1 = g_.lambda[i + 1];
        if (!(l1 > l0)) return std::min(v[i], v[i + 1]);
        const double w = std::clamp((lambda - l0) / (l1 - l0), 0.0, 1.0);
        return (1 - w) * v[i] + w * v[i + 1];
    }

    /// The largest path acceleration the axes allow along unit tangent t (no curvature): the
    /// smallest a_i / |t_i|.
    double path_acceleration_limit(const Vec& t) const {
        double lim = acc_norm_;
        for (std::size_t i = 0; i < axes_; ++i) {
            if (std::fabs(t[i]) > 1e-12) lim = std::min(lim, acc_[i] / std::fabs(t[i]));
        }
        return lim;
    }

    /// Nodes i and i + 1 are the two sides of a joint whose curvature jumps by more than a
    /// factor of 2 (a blend's ends, a line meeting an arc).
    bool curvature_jump(std::size_t i) const {
        const double before = g_.curvature_norm[i], after = g_.curvature_norm[i + 1];
        return g_.lambda[i + 1] == g_.lambda[i] && std::max(before, after) > 2 * std::min(before, after) + 1e-9;
    }

    /// The lookahead's bound on x = s^2 at arc length l: beta interpolated linearly in x, as
    /// TOPP-RA's constant path acceleration between nodes has it.
    double beta_at(double l) const { return interpolate(beta_, l); }

    /// True when a joint whose curvature jumps (a blend's end) lies between arc lengths l0 and l1
    /// (searched from node `from`, or from l0's interval): the dips the rising spans and the
    /// landings on local minima are for. On smooth curves they cost planning time (a tenth more
    /// on a 10,000-segment random walk) for a few milliseconds of motion either way.
    bool steps_between(double l0, double l1,
                       std::size_t from = static_cast<std::size_t>(-1)) const {
        std::size_t i = from == static_cast<std::size_t>(-1) ? interval(l0) : from;
        for (std::size_t j = i; j < piece_.last && g_.lambda[j] <= l1; ++j) {
            if (g_.lambda[j] >= l0 && curvature_jump(j)) return true;
        }
        for (std::size_t j = i; j-- > piece_.first && g_.lambda[j] >= l0;) {
            if (curvature_jump(j)) return true;
        }
        return false;
    }

    /// True when constant path acceleration A for tau seconds from k keeps x = s^2 under the
    /// lookahead at every node passed and at the end (x and beta are both linear in between).
    bool under_beta(const Knot& k, double a, double tau) const {
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

    /// Largest A in [a_lo, a_hi] keeping the speed under beta, or false if even a_lo fails.
    bool max_under_beta(const Knot& k, double tau, double a_lo, double a_hi, double& a) const {
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
    double solve_under_beta(const Knot& k, double tau, double a_lo, double a_hi) const {
        const double s = k.speed, x0 = s * s, tau2 = tau * tau;
        const auto a_at = [&](double l) { return 2 * (l - k.lambda - s * tau) / tau2; };
        const double top = std::min(a_hi, a_at(end_lambda_ + 1e-12));
        double best = a_lo, cap = top;
        const std::size_t first = interval(k.lambda);
        for (std::size_t j = first; j < piece_.last; ++j) {
            const double lj = g_.lambda[j], lj1 = g_.lambda[j + 1];
            if (j > first && lj > k.lambda) cap = std::min(cap, (beta_[j] * (1 + 1e-9) + 1e-12 - x0) / (2 * (lj - k.lambda)));
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
            if (seg_hi >= top) break;
        }
        return best;
    }

    /// How far the Hermite span between two knots over tau seconds exceeds the limits: max over
    /// axes of |acceleration| / limit (exact: it is linear in a cubic, so its ends bound it) and
    /// peak |velocity| / limit (exact: at the ends or where the acceleration crosses 0), and the
    /// speed at eighths of the span over the feed and the speed cap there (less the rounding of
    /// the tangents; with `caps` false only the feed), and the junction with the span before
    /// (`in`). <= 0: within.
    /// Relative: the check is ratio - 1. The knots are on the LSB grid, k1.v rounded for this
    /// span; k0's velocity is rounded for it here, so this is the span the device runs.
    double violation(const Knot& k0, const Arrival& in, const Knot& k1, std::uint32_t m, bool caps = true) const {
        return violation(k0, in, k1, m, span_velocity(k0.v, m), caps);
    }
    /// The same with k0's velocity already rounded for this span (v0 = span_velocity(k0.v, m)).
    double violation(const Knot& k0, const Arrival& in, const Knot& k1, std::uint32_t m,
                     const Vec& v0, bool caps = true) const {
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
            for (int s = 0; s < kSamples; ++s) {  // velocity at t = w tau: v0 + a0 w tau + (a1 - a0) w^2 tau / 2
                at[s][i] = v0[i] + tau * (a0 * kW[s] + (a1 - a0) * kW[s] * kW[s] / 2);
            }
        }
        // Speed along the path at every eighth of the span, against the feed and the speed cap
        // where the path profile (constant acceleration) is then.
        const double acc = (k1.speed - k0.speed) / tau, rounding = root_axes_ * lsb_ / tau;
        for (int s = 0; s < kSamples; ++s) {
            const double t = kW[s] * tau;
            const double speed = std::max(0.0, norm(at[s]) - rounding);
            const double cap = interpolate(caps_, std::clamp(k0.lambda + k0.speed * t + 0.5 * acc * t * t,
                                                             k0.lambda, std::max(k0.lambda, k1.lambda)));
            worst = std::max(worst, speed / feed_);
            if (!caps) continue;
            if (cap > 0) worst = std::max(worst, speed / std::sqrt(cap));
            else if (speed > 0) worst = std::max(worst, 2.0);
        }
        worst = std::max(worst, junction(in, k0, v0, k1, m));
        return worst - 1;
    }

    struct Candidate {
        double a = 0;
        Knot end;
        double f = 0;
    };

    /// The span of tau seconds from k with constant path acceleration a: end speed
    /// V1 = V0 + a tau at arc length l1 = l0 + V0 tau + a tau^2 / 2 + offset. The end
    /// accelerations of the executed cubic are very sensitive to the end point (6 / tau^2 per
    /// mm), so a small offset along the path (at most a tenth of a full-acceleration span's
    /// distance, typically micrometres) lets them absorb what a constant path acceleration gets
    /// wrong where the curvature changes along the span: the offset nearest 0 that the
    /// linearised end accelerations allow. f <= 0 means the span is within the limits and its
    /// end under beta.
    Candidate evaluate(const Knot& k, double a, std::uint32_t m, double jerk = 0) {
        const double tau = m * tick_;
        const Vec v0 = span_velocity(k.v, m);
        Candidate c;
        c.a = a;
        c.end.speed = std::max(0.0, k.speed + a * tau);
        const double l1 =
            std::min(end_lambda_, k.lambda + k.speed * tau + 0.5 * a * tau * tau - jerk * tau * tau * tau / 12);
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

    /// Largest distance of the executed cubic from the path at sixths of the span (at every tick
    /// across a corner or a curvature jump), measured across the path at the arc length where
    /// the cubic's point projects onto the chord. Skipped (0) where neither the curvature it
    /// passes (chord^2 kappa / 8 < delta / 64) nor its end tangents can move it off the path: no
    /// corner, no swing, no bulge (below).
    double span_deviation(const Knot& k, const Knot& end, std::uint32_t m) {
        return span_deviation(k, end, m, span_velocity(k.v, m));
    }
    /// The same with k's velocity already rounded for this span (v0 = span_velocity(k.v, m)).
    double span_deviation(const Knot& k, const Knot& end, std::uint32_t m, const Vec& v0) {
        const double tau = m * tick_;
        const double len = end.lambda - k.lambda;
        double kappa = 0;
        bool corner = false, curvature_step = false;
        for (std::size_t i = interval(k.lambda); i <= piece_.last && g_.lambda[i] <= end.lambda + 1e-12; ++i) {
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
            const double h00 = 2 * w3 - 3 * w2 + 1, h10 = w3 - 2 * w2 + w, h01 = -2 * w3 + 3 * w2, h11 = w3 - w2;
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

    /// A span that ends exactly on the next crossed corner, when the corner's speed limit binds
    /// and the regular span would run past it: a span of m <= ticks_per_span ticks (the fewest
    /// that work) with the constant path acceleration that lands on the corner at a speed under
    /// beta there. The knot on the corner moves along the bisector of the two tangents (the
    /// velocity stays continuous; both spans leave the straight pieces by about 4/27 of their
    /// length times half the turn, checked as every span). So the corner limits the speed at a
    /// point, not over a whole span. Returns the ticks (0: no such span, take a regular one).
    std::uint32_t corner_landing(const Knot& k, Knot& out) {
        const double tau_n = n_ * tick_;
        const double reach = k.speed * tau_n + 0.5 * acc_norm_ * tau_n * tau_n;
        std::size_t c = 0;
        bool found = false;
        for (std::size_t i = interval(k.lambda); i <= piece_.last && g_.lambda[i] <= k.lambda + reach; ++i) {
            if (g_.lambda[i] > k.lambda + 1e-9 && g_.lambda[i] < end_lambda_ - 1e-9 && i + 1 <= piece_.last &&
                g_.lambda[i + 1] == g_.lambda[i] && g_.corner[i] != 0) {
                c = i;
                found = true;
                break;
            }
        }
        if (!found) return 0;
        const double lc = g_.lambda[c];
        const double xc = std::min(beta_[c], beta_[c + 1]);
        // Only where the corner slows the motion down.
        if (!(xc < 0.81 * std::max(k.speed * k.speed, beta_at(k.lambda)))) return 0;
        // The regular span stops short of the corner: take it.
        double a_hi;
        if (max_under_beta(k, tau_n, -k.speed / tau_n, acc_norm_, a_hi) &&
            k.lambda + k.speed * tau_n + 0.5 * a_hi * tau_n * tau_n < lc - 1e-9) {
            return 0;
        }
        Vec dir = sub(Vec(g_.tangent[c + 1]), scaled(Vec(g_.tangent[c]), -1.0));
        const double dn = norm(dir);
        if (!(dn > 1e-9)) return 0;
        dir = scaled(dir, 1 / dn);
        if (const std::uint32_t m = land_on_corner(k, c, dir, xc, out)) {
            on_dip_ = true;  // the span leaving the turn may raise its acceleration too (leave_dip)
            return m;
        }
        // Too near (or too fast) to land from here: a regular span of fewer ticks first, from
        // whose end the landing works (the landing itself is taken at the next knot).
        // Two spans, j then m ticks, the first with the constant path acceleration that lets the
        // second (also of constant acceleration) arrive at the corner speed: fewest ticks first.
        if (const std::uint32_t j = approach(k, c, dir, xc, 1, 0, Knot{}, out)) return j;
        const Arrival saved = arrival_;
        for (std::uint32_t j = n_; j >= 1; --j) {
            Knot mid;
            if (!step(k, j, mid) || !(mid.lambda < lc - 1e-9)) continue;
            arrival_ = Arrival{k, j};
            Knot e;
            const std::uint32_t m = land_on_corner(mid, c, dir, xc, e);
            arrival_ = saved;
            if (m > 0) {
                out = mid;
                return j;
            }
        }
        return 0;
    }

    /// A knot on the next dip of beta (a local minimum near a curvature jump, where a blend's
    /// curvature peaks; or a joint where the curvature steps up, beta is under the cap and rises
    /// after it: the start of a corner blend, a line entering an arc) at beta's speed there,
    /// reached by constant-acceleration spans within three regular spans (approach): the fewest
    /// ticks first, so the dip is reached as early as possible.
    /// Returns the ticks of the span taken now (0: no dip or no such approach).
    std::uint32_t dip_landing(const Knot& k, Knot& out) {
        constexpr std::uint32_t kSpansAhead = 3;
        const double tau_n = n_ * tick_, horizon = kSpansAhead * tau_n;
        const double reach = k.speed * horizon + 0.5 * acc_norm_ * horizon * horizon;
        std::size_t c = 0;
        bool found = false;
        for (std::size_t i = std::max(interval(k.lambda), piece_.first + 1);
             i + 2 <= piece_.last && g_.lambda[i] <= k.lambda + reach; ++i) {
            // A local minimum of beta (inside a blend, where its curvature peaks), or a joint where
            // the curvature steps up (a blend's start, a line entering an arc) and beta rises
            // after it: landing where beta keeps falling would leave the next spans on its
            // boundary with no room to follow it in whole ticks.
            const bool inside =
                g_.lambda[i] > k.lambda + 1e-9 && g_.lambda[i] < end_lambda_ - 1e-9 && beta_[i] > 0;
            const bool local_min = inside && !jerk_limited_ && beta_[i] < beta_[i - 1] &&
                                   beta_[i] < beta_[i + 1] && g_.lambda[i] > g_.lambda[i - 1] &&
                                   g_.lambda[i + 1] > g_.lambda[i] &&
                                   steps_between(g_.lambda[i] - reach, g_.lambda[i] + reach, i);
            const bool step_up = curvature_jump(i) &&
                                 g_.curvature_norm[i + 1] > g_.curvature_norm[i] &&
                                 beta_[i] < beta_[i - 1] && beta_[i] <= beta_[i + 1] &&
                                 beta_[i + 1] < beta_[i + 2] && beta_[i] < caps_[i];
            if (inside && (local_min || step_up)) {
                c = i;
                found = true;
                break;
            }
        }
        if (!found) return 0;
        const Vec dir(g_.tangent[c]);
        Knot direct;
        const std::uint32_t direct_ticks = land_on_corner(k, c, dir, beta_[c], direct);
        const std::uint32_t ticks = approach(k, c, dir, beta_[c], kSpansAhead, direct_ticks, direct, out);
        on_dip_ = ticks != 0 && out.lambda == g_.lambda[c];  // landed (an approach span ends before it)
        return ticks;
    }

    /// Leaving a dip: the curve ahead holds the path acceleration down only while it lasts, so
    /// the span across it may accelerate less at its start and more at its end (the path
    /// acceleration linear in time, A + J (t - tau/2), within the limits checked on the executed
    /// span). The span with the highest end speed among J = 0 (a regular span) and four J > 0,
    /// each with the largest A >= 0 under beta and within the limits. Returns its ticks (0: none).
    std::uint32_t leave_dip(const Knot& k, Knot& out) {
        Knot best;
        const bool have = step(k, n_, best);
        if (!rise_across(k, 0, have, best)) return 0;
        out = best;
        return n_;
    }

    /// Replaces `best` (a span of ticks_per_span ticks from k, if `have`) by a span whose path
    /// acceleration rises linearly, A + J (t - tau/2) with A >= -brake times the path
    /// acceleration limit, where one ends faster. Returns whether there is a span at all.
    bool rise_across(const Knot& k, double brake, bool have, Knot& best) {
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

    /// True when the path profile s(t) = V0 + (A - J tau/2) t + J t^2/2 stays non-negative and
    /// its s^2 under beta at every node passed and at the end.
    bool jerk_under_beta(const Knot& k, double a, double jerk, double tau) const {
        const double a0 = a - 0.5 * jerk * tau;
        const auto speed = [&](double t) { return k.speed + a0 * t + 0.5 * jerk * t * t; };
        const auto dist = [&](double t) { return k.speed * t + 0.5 * a0 * t * t + jerk * t * t * t / 6; };
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

    /// The first span of the fewest ticks j + m that reach node c at speed^2 xc along dir: one
    /// constant path acceleration over j <= spans_ahead * ticks_per_span ticks (taken now for at
    /// most ticks_per_span of them; the rest is solved again at the next knot), then a landing
    /// span of m <= ticks_per_span ticks (land_on_corner; `direct`, of `direct_ticks` ticks, is
    /// the landing from k itself, 0 for none). Where j fits in one span the landing after it is
    /// checked now. Returns the ticks of the span taken (0: none).
    std::uint32_t approach(const Knot& k, std::size_t c, const Vec& dir, double xc, std::uint32_t spans_ahead,
                           std::uint32_t direct_ticks, const Knot& direct, Knot& out) {
        const double d_all = g_.lambda[c] - k.lambda, vt = std::sqrt(xc);
        const Arrival saved = arrival_;
        // (spans_ahead + 1) n^2 pairs at most: the same for spans up to 128 ticks, bounded for
        // the longer spans a profile may ask for.
        std::uint32_t pairs = 0;
        constexpr std::uint32_t kMaxPairs = 65536;
        for (std::uint32_t total = 1; total <= (spans_ahead + 1) * n_ && pairs < kMaxPairs;
             ++total) {
            if (total == direct_ticks) {
                out = direct;
                return total;
            }
            for (std::uint32_t j = std::min(spans_ahead * n_, total - 1); j >= 1 && total - j <= n_; --j) {
                ++pairs;
                const double tj = j * tick_, tm = (total - j) * tick_;
                const double a = (d_all - k.speed * tj - (k.speed + vt) * tm / 2) / (tj * tj / 2 + tj * tm / 2);
                if (k.speed + a * tj < 0 || std::fabs(a) > 1.5 * acc_norm_) continue;
                const std::uint32_t now_ticks = std::min(j, n_);
                if (!under_beta(k, a, now_ticks * tick_)) continue;
                Candidate c1 = evaluate(k, a, now_ticks);
                if (c1.f > 0 || !(c1.end.lambda < g_.lambda[c] - 1e-9)) continue;
                if (j > n_) {
                    out = c1.end;
                    return now_ticks;
                }
                arrival_ = Arrival{k, j};
                Knot e;
                // The landing of the m = total - j ticks this total stands for (trying every m
                // made each knot cost O(ticks^3) spans: minutes for one 28-tick path).
                const std::uint32_t m = land_on_corner(c1.end, c, dir, xc, e, total - j, total - j);
                arrival_ = saved;
                if (m > 0) {
                    out = c1.end;
                    return j;
                }
            }
        }
        return 0;
    }

    /// One span from k that ends exactly on corner node c (velocity along dir, speed^2 <= xc):
    /// the fewest ticks from m_lo to m_hi (0: ticks_per_span) that work. Its speed is the
    /// constant-acceleration one, or xc where that is faster (then the cubic is not of constant
    /// path acceleration; it is checked as is).
    std::uint32_t land_on_corner(const Knot& k, std::size_t c, const Vec& dir, double xc, Knot& out,
                                 std::uint32_t m_lo = 1, std::uint32_t m_hi = 0) {
        const double lc = g_.lambda[c], d = lc - k.lambda;
        for (std::uint32_t m = m_lo; m <= (m_hi == 0 ? n_ : m_hi); ++m) {
            const double tau = m * tick_;
            double v1 = 2 * d / tau - k.speed;
            if (v1 < 0) break;
            if (v1 * v1 > xc) {
                v1 = std::sqrt(xc);
            } else {
                const double a = (v1 - k.speed) / tau;
                if (std::fabs(a) > 1.5 * acc_norm_ || !under_beta(k, a, tau)) continue;
            }
            Knot e;
            e.lambda = lc;
            e.speed = v1;
            e.q = g_.q[c];
            e.v = scaled(dir, v1);
            const Vec v0 = span_velocity(k.v, m);
            fit_end(k, v0, e, m);
            double f = violation(k, arrival_, e, m, v0);
            if (f > 0) continue;
            f = std::max(f, span_deviation(k, e, m, v0) / deviation_limit_ - 1);
            if (f > 0) continue;
            out = e;
            return m;
        }
        return 0;
    }

    /// Curvature vector at arc length l, interpolated between grid nodes.
    Vec curvature_at(double l) const {
        const std::size_t i = interval(l);
        const double l0 = g_.lambda[i], l1 = g_.lambda[i + 1];
        const double w = l1 > l0 ? std::clamp((l - l0) / (l1 - l0), 0.0, 1.0) : 1.0;
        Vec r{};
        for (std::size_t a = 0; a < kAxesMax; ++a) r[a] = (1 - w) * g_.curvature[i][a] + w * g_.curvature[i + 1][a];
        return r;
    }

    /// The feasible end of [lo, hi] (lo within the limits, hi not): regula falsi (Illinois) on
    /// the violation, to 1e-4 of the acceleration limit (a finer one bought no measurable
    /// motion time). Spans of m ticks with the path acceleration's slope `jerk` (evaluate).
    Candidate boundary(const Knot& k, Candidate lo, Candidate hi, std::uint32_t m, double jerk) {
        int side = 0;
        double flo = lo.f, fhi = hi.f;
        for (int it = 0; it < 40 && hi.a - lo.a > 1e-4 * acc_norm_; ++it) {
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

    /// One span of m ticks from k: the largest constant path acceleration (end speed) under
    /// beta whose executed span, with its end point moved by the allowed offset (evaluate), is
    /// within the limits.
    bool step(const Knot& k, std::uint32_t m, Knot& next) {
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

    /// Hermite value at theta in [0, 1] on one axis (positions p0, p1, tangents m0, m1 per span).
    static double hermite(double p0, double p1, double m0, double m1, double t) {
        const double t2 = t * t, t3 = t2 * t;
        return (2 * t3 - 3 * t2 + 1) * p0 + (t3 - 2 * t2 + t) * m0 + (-2 * t3 + 3 * t2) * p1 + (t3 - t2) * m1;
    }

    /// True when the final span of `ticks` ticks from k to rest at the end is within the limits
    /// and never passes the end point at a tick.
    bool finish_ok(const Knot& k, const Arrival& in, std::uint32_t ticks) {
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
                const double x = (2 * w2 * w - 3 * w2 + 1) * k.q[i] + (w2 * w - 2 * w2 + w) * v0[i] * tau +
                                 (-2 * w2 * w + 3 * w2) * end_q_[i];
                const double v = ((6 * w2 - 6 * w) * k.q[i] + (3 * w2 - 4 * w + 1) * v0[i] * tau +
                                  (-6 * w2 + 6 * w) * end_q_[i]) / tau;
                along += (x - k.q[i]) * chord[i];
                speed2 += v * v;
            }
            const double l = k.lambda + d * std::clamp(along / c2, 0.0, 1.0);
            const double speed = std::max(0.0, std::sqrt(speed2) - root_axes_ * lsb_ / tau);
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

    /// Ticks of a final span from k to rest at the piece's end, or 0 if none of at most
    /// ticks_per_span ticks is within the limits from here.
    std::uint32_t finish(const Knot& k) {
        const double d = end_lambda_ - k.lambda;
        double lo_f, hi_f;
        if (d > (k.speed * tick_ + acc_norm_ * tick_ * tick_) * n_ * n_) return 0;  // far away
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
            while (stride > 1 && best > lo && best + stride > t + 1 && finish_ok(k, arrival_, best - 1)) --best;
            return best;
        }
        return 0;
    }

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
    std::size_t hint_ = 0;
    mutable std::size_t interval_hint_ = 0;  ///< interval()'s last answer
};

}  // namespace

PieceMotion forward_pass(const PathGrid& g, const Piece& piece, const Limits& limits,
                         const std::vector<double>& caps, const std::vector<double>& beta,
                         const MachineProfile& profile, const PlanOptions& options, const Vec& start_q,
                         PieceMotion* resume, double resume_lambda, bool short_spans) {
    PieceTimer timer(g, piece, limits, caps, beta, profile, options);
    return timer.run(start_q, resume, resume_lambda, short_spans);
}

}  // namespace pathstream::host::planner_detail
