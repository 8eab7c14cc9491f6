// Knots landed where the speed must be low for a moment only: on a crossed corner, whose
// speed cap holds at one point, and on a dip of beta (a curvature peak inside a blend, a
// curvature step). Regular spans would pass such a point mid-span and have to be slow for the
// whole span; a knot on it is slow at the point itself, and the span leaving it may raise its
// acceleration across the rest of the bend (leave_dip).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "forward_pass.hpp"
#include "piece_timer.hpp"
#include "vec.hpp"

namespace pathstream::host::planner_detail {

/// A span that ends exactly on the next crossed corner, when the corner's speed limit binds
/// and the regular span would run past it: a span of m <= ticks_per_span ticks (the fewest
/// that work) with the constant path acceleration that lands on the corner at a speed under
/// beta there. The knot on the corner moves along the bisector of the two tangents (the
/// velocity stays continuous; both spans leave the straight pieces by about 4/27 of their
/// length times half the turn, checked as every span). So the corner limits the speed at a
/// point, not over a whole span. Returns the ticks (0: no such span, take a regular one).
std::uint32_t PieceTimer::corner_landing(const Knot& k, Knot& out) {
    const double tau_n = n_ * tick_;
    const double reach =
        std::min(k.speed * tau_n + 0.5 * acc_norm_ * tau_n * tau_n, feed_reach(k, 1));
    std::size_t c = 0;
    bool found = false;
    for (std::size_t i = interval(k.lambda); i <= piece_.last && g_.lambda[i] <= k.lambda + reach;
         ++i) {
        if (g_.lambda[i] > k.lambda + 1e-9 && g_.lambda[i] < end_lambda_ - 1e-9 &&
            i + 1 <= piece_.last && g_.lambda[i + 1] == g_.lambda[i] && g_.corner[i] != 0) {
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
std::uint32_t PieceTimer::dip_landing(const Knot& k, Knot& out) {
    constexpr std::uint32_t kSpansAhead = 3;
    const double tau_n = n_ * tick_, horizon = kSpansAhead * tau_n;
    const double reach = std::min(k.speed * horizon + 0.5 * acc_norm_ * horizon * horizon,
                                  feed_reach(k, kSpansAhead));
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
        const bool step_up = curvature_jump(i) && g_.curvature_norm[i + 1] > g_.curvature_norm[i] &&
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
    const std::uint32_t ticks =
        approach(k, c, dir, beta_[c], kSpansAhead, direct_ticks, direct, out);
    on_dip_ = ticks != 0 && out.lambda == g_.lambda[c];  // landed (an approach span ends before it)
    return ticks;
}

/// Leaving a dip: the curve ahead holds the path acceleration down only while it lasts, so
/// the span across it may accelerate less at its start and more at its end (the path
/// acceleration linear in time, A + J (t - tau/2), within the limits checked on the executed
/// span). The span with the highest end speed among J = 0 (a regular span) and four J > 0,
/// each with the largest A >= 0 under beta and within the limits. Returns its ticks (0: none).
std::uint32_t PieceTimer::leave_dip(const Knot& k, Knot& out) {
    Knot best;
    const bool have = step(k, n_, best);
    if (!rise_across(k, 0, have, best)) return 0;
    out = best;
    return n_;
}

/// The first span of the fewest ticks j + m that reach node c at speed^2 xc along dir: one
/// constant path acceleration over j <= spans_ahead * ticks_per_span ticks (taken now for at
/// most ticks_per_span of them; the rest is solved again at the next knot), then a landing
/// span of m <= ticks_per_span ticks (land_on_corner; `direct`, of `direct_ticks` ticks, is
/// the landing from k itself, 0 for none). Where j fits in one span the landing after it is
/// checked now. Returns the ticks of the span taken (0: none).
std::uint32_t PieceTimer::approach(const Knot& k, std::size_t c, const Vec& dir, double xc,
                                   std::uint32_t spans_ahead, std::uint32_t direct_ticks,
                                   const Knot& direct, Knot& out) {
    const double d_all = g_.lambda[c] - k.lambda, vt = std::sqrt(xc);
    const Arrival saved = arrival_;
    // (spans_ahead + 1) n^2 pairs at most: the same for spans up to 128 ticks, bounded for
    // the longer spans a profile may ask for.
    std::uint32_t pairs = 0;
    constexpr std::uint32_t kMaxPairs = 65536;
    for (std::uint32_t total = 1; total <= (spans_ahead + 1) * n_ && pairs < kMaxPairs; ++total) {
        if (total == direct_ticks) {
            out = direct;
            return total;
        }
        for (std::uint32_t j = std::min(spans_ahead * n_, total - 1); j >= 1 && total - j <= n_;
             --j) {
            ++pairs;
            const double tj = j * tick_, tm = (total - j) * tick_;
            const double a =
                (d_all - k.speed * tj - (k.speed + vt) * tm / 2) / (tj * tj / 2 + tj * tm / 2);
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
std::uint32_t PieceTimer::land_on_corner(const Knot& k, std::size_t c, const Vec& dir, double xc,
                                         Knot& out, std::uint32_t m_lo, std::uint32_t m_hi) {
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

/// True when a joint whose curvature jumps (a blend's end) lies between arc lengths l0 and l1
/// (searched from node `from`, or from l0's interval): the dips the rising spans and the
/// landings on local minima are for. On smooth curves they cost planning time (a tenth more
/// on a 10,000-segment random walk) for a few milliseconds of motion either way.
bool PieceTimer::steps_between(double l0, double l1, std::size_t from) const {
    std::size_t i = from == static_cast<std::size_t>(-1) ? interval(l0) : from;
    for (std::size_t j = i; j < piece_.last && g_.lambda[j] <= l1; ++j) {
        if (g_.lambda[j] >= l0 && curvature_jump(j)) return true;
    }
    for (std::size_t j = i; j-- > piece_.first && g_.lambda[j] >= l0;) {
        if (curvature_jump(j)) return true;
    }
    return false;
}

}  // namespace pathstream::host::planner_detail
