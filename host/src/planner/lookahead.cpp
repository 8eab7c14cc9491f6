// The lookahead: per-node speed caps and the TOPP-RA backward pass (controllable sets), plus
// the TOPP-RA forward pass used as the time-optimal reference.
//
// Along the path with arc length l, speed s = dl/dt and x = s^2, the acceleration of axis i is
// q_i'(l) dds + q_i''(l) x (q' the unit tangent, q'' the curvature vector), and between two
// nodes TOPP-RA takes dds constant, so x is linear in l: dds = (x[k+1] - x[k]) / (2 dl). The
// limit |q_i' dds + q_i'' x| <= a_i at both ends of the interval is linear in (x[k], x[k+1]).
#include "lookahead.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "grid.hpp"
#include "limits.hpp"
#include "lp2.hpp"
#include "lsb_rounding.hpp"
#include "pathstream/host/planner.hpp"
#include "pathstream/machine/machine.hpp"
#include "vec.hpp"

namespace pathstream::host::planner_detail {
namespace {

constexpr double kNoCap = 1e20;  // (mm/s)^2: effectively unlimited, still finite

/// Rows of the interval k..k+1. The path acceleration's coefficient (the unit tangent) is
/// divided by `tangential_margin` (<= 1): the lookahead assumes speed changes cost that much
/// more acceleration than they do, while the curvature terms (the speed cap of a bend) keep
/// the full budget.
std::size_t interval_rows(const Grid& g, std::size_t k, double dl, const Limits& limits,
                          const std::vector<double>& accel_factor, double tangential_margin,
                          LpRow* rows) {
    std::size_t n = 0;
    for (std::size_t i = 0; i < g.axes; ++i) {
        const double a0 = limits.acceleration[i] * accel_factor[k];
        const double a1 = limits.acceleration[i] * accel_factor[k + 1];
        const double g0 = g.tangent[k][i] / tangential_margin, h0 = g.curvature[k][i];
        const double g1 = g.tangent[k + 1][i] / tangential_margin, h1 = g.curvature[k + 1][i];
        rows[n++] = {h0 - g0 / (2 * dl), g0 / (2 * dl), -a0, a0};
        rows[n++] = {-g1 / (2 * dl), h1 + g1 / (2 * dl), -a1, a1};
    }
    return n;
}

/// Largest x at node k for which some path acceleration keeps every axis within its limit.
double acceleration_cap(const Grid& g, std::size_t k, const Limits& limits, double factor,
                        double x_max) {
    LpRow rows[kAxesMax];
    for (std::size_t i = 0; i < g.axes; ++i) {
        const double a = limits.acceleration[i] * factor;
        rows[i] = {g.curvature[k][i], g.tangent[k][i], -a, a};
    }
    return lp_max_x(rows, g.axes, x_max, -kNoCap, kNoCap);
}

}  // namespace

std::vector<double> speed_caps(const PathGrid& pg, const Limits& limits,
                               const MachineProfile& profile, const PlanOptions& options) {
    const Grid& g = pg.grid;
    const double tick = 1.0 / profile.tick_hz;
    const double delta = profile.chord_tolerance;
    const ShaperSpread shaper =
        profile.plan_for_shaper ? profile_shaper_spread(profile) : ShaperSpread{};
    std::vector<double> caps(g.size(), kNoCap);
    for (std::size_t k = 0; k < g.size(); ++k) {
        // The node's regular span: longer where its feed is far below an LSB per span.
        const double span = tick * feed_span_ticks(profile.ticks_per_span, g.feed[k],
                                                   profile.tick_hz, profile.mm_per_lsb);
        double s = g.feed[k] * options.feed_margin;
        for (std::size_t i = 0; i < g.axes; ++i) {
            const double t = std::fabs(g.tangent[k][i]);
            if (t > 0) s = std::min(s, limits.velocity[i] * options.velocity_margin / t);
        }
        // Chord tolerance: the chord between two ticks at speed s on radius rho stays within
        // delta of the arc when s <= (2/T) sqrt(2 rho delta - delta^2) (no cap for rho <= delta).
        const double kappa = norm(g.curvature[k]);
        if (kappa > 0 && 1 / kappa > delta) {
            const double rho = 1 / kappa;
            s = std::min(s, (2 / tick) * std::sqrt(2 * rho * delta - delta * delta));
        }
        // Spans: the cubic through two knots an arc theta apart on radius rho leaves the arc by
        // rho theta^4 / 384; keep that within delta / 2 (with 10 % to spare on theta).
        if (kappa > 0) {
            const double theta = 0.9 * std::pow(192 * delta * kappa, 0.25);
            s = std::min(s, theta / (kappa * span));
        }
        // Corner rule (docs/planner.md): a tangent jump J crossed at speed s changes axis i's
        // velocity by s |J_i|; keep that within one tick of its acceleration (and, for spans of
        // fewer than 4 ticks, within a quarter span of it: the span that crosses the corner
        // turns at up to 4 s |J_i| / T_span), and keep the cut of the corner by that span
        // within 0.45 delta: the cubic through knots on both sides leaves the two straight
        // pieces by up to 0.1407 s T_span |J| (worst with the corner at the span's start,
        // 1/8 mid-span).
        const double jump = norm(g.corner_jump[k]);
        if (jump > 0) {
            const double window = std::min(tick, span / 4);
            for (std::size_t i = 0; i < g.axes; ++i) {
                const double j = std::fabs(g.corner_jump[k][i]);
                if (j > 0) s = std::min(s, limits.acceleration[i] * window / j);
            }
            s = std::min(s, 0.45 * delta / (0.1407 * span * jump));
        }
        // Input shaping (docs/input-shaping.md): the device's shaped command runs inside a bend
        // by about s^2 kappa variance / 2 and cuts a corner crossed at speed s by about
        // s |J| spread / 2; with plan_for_shaper keep each within half the tolerance.
        if (shaper.variance > 0) {
            if (kappa > 0) s = std::min(s, std::sqrt(delta / (kappa * shaper.variance)));
            if (jump > 0) s = std::min(s, delta / (jump * shaper.spread));
        }
        caps[k] = std::min(kNoCap, s * s);
    }
    return caps;
}

void jerk_caps(const PathGrid& pg, const Limits& limits, const MachineProfile& profile,
               std::uint32_t filter_ticks, std::vector<double>& caps) {
    const Grid& g = pg.grid;
    const double span = profile.ticks_per_span / profile.tick_hz;
    const double share = limits.jerk_share;
    const auto cap = [&](std::size_t k, double s) { caps[k] = std::min(caps[k], s * s); };
    // Stops (pieces' ends) are passed at rest: no curvature rule there, and the filter never
    // averages across them.
    std::vector<char> stop(g.size(), 0);
    for (const Piece& piece : pg.pieces) stop[piece.first] = stop[piece.last] = 1;
    for (std::size_t k = 0; k + 1 < g.size(); ++k) {
        // The spline through knots on both sides of a curvature step dk (a joint) leaves the
        // path by about 0.07 dk h^2 (h the span's length, measured): within 0.4 delta.
        const double dk = norm(sub(g.curvature[k + 1], g.curvature[k]));
        if (dk > 0 && !stop[k] && !stop[k + 1] && g.lambda[k + 1] <= g.lambda[k]) {
            const double s = std::sqrt(0.4 * profile.chord_tolerance / (0.07 * dk)) / span;
            cap(k, s);
            cap(k + 1, s);
        }
    }
    for (std::size_t k = 0; k < g.size(); ++k) {
        for (std::size_t i = 0; i < g.axes; ++i) {
            const double j = i < limits.jerk.size() ? limits.jerk[i] : 0.0;
            if (!(j > 0)) continue;
            // A tangent jump J crossed at speed s: the spans around it turn the velocity by
            // s |J_i| within about one span, up and down again.
            const double jump = std::fabs(g.corner_jump[k][i]);
            if (jump > 0) cap(k, share * j * span * span / (2 * jump));
            // Turning the velocity at curvature kappa: its derivative along the tangent, kappa^2
            // s^3 (within the quarter of the limit the filter leaves).
            const double kappa = norm(g.curvature[k]);
            if (kappa > 0 && !stop[k])
                cap(k, std::cbrt((1 - share) * j /
                                 (kappa * kappa * std::fabs(g.tangent[k][i]) + 1e-300)));
            if (k + 1 >= g.size() || stop[k] || stop[k + 1]) continue;
            const double dk = std::fabs(g.curvature[k + 1][i] - g.curvature[k][i]);
            if (!(dk > 0)) continue;
            // A change of curvature by dk over dl at speed s: kappa' s^3 = dk s^3 / dl; where
            // that takes less than a span, a step of dk s^2 in the acceleration, which the spans
            // around it spread over about a span.
            const double dl = g.lambda[k + 1] - g.lambda[k];
            const double step = std::sqrt(share * j * span / (2 * dk));
            const double s = dl > 0 ? std::max(std::cbrt(share * j * dl / dk), step) : step;
            cap(k, s);
            cap(k + 1, s);
        }
    }
    // The filter raises the speed at a dip to the mean over M ticks: every cap must hold over
    // the distance the window covers around it.
    const double reach_time = (filter_ticks + profile.ticks_per_span) / profile.tick_hz;
    // Dips below the speed one tick of acceleration gives (a T: the neighbourhood of a stop,
    // a cusp) erode their surroundings no lower than that: the motion comes to rest there
    // anyway, and the jerk stage's exact check guards what is left.
    double a_min = 1e300;
    for (const double a : limits.acceleration) a_min = std::min(a_min, a);
    const double slowest = a_min / profile.tick_hz * a_min / profile.tick_hz;
    std::vector<double> before = caps;
    for (std::size_t k = 0; k < g.size(); ++k) before[k] = std::max(caps[k], slowest);
    for (const Piece& piece : pg.pieces) {
        for (std::size_t k = piece.first; k <= piece.last; ++k) {
            const double d = reach_time * std::sqrt(std::min(before[k], kNoCap));
            for (std::size_t i = k; i-- > piece.first && g.lambda[k] - g.lambda[i] <= d;)
                caps[k] = std::min(caps[k], before[i]);
            for (std::size_t i = k + 1; i <= piece.last && g.lambda[i] - g.lambda[k] <= d; ++i)
                caps[k] = std::min(caps[k], before[i]);
        }
    }
}

void reserve_for_corners(const PathGrid& pg, const Limits& limits, const std::vector<double>& caps,
                         const MachineProfile& profile, std::vector<double>& factor) {
    const Grid& g = pg.grid;
    for (std::size_t k = 0; k < g.size(); ++k) {
        const double jump = norm(g.corner_jump[k]);
        const double span_time = feed_span_ticks(profile.ticks_per_span, g.feed[k], profile.tick_hz,
                                                 profile.mm_per_lsb) /
                                 profile.tick_hz;
        if (jump <= 0 || span_time <= 0) continue;
        const double v = std::sqrt(caps[k]);
        double share = 0;
        for (std::size_t i = 0; i < g.axes; ++i) {
            share = std::max(share, 4 * v * std::fabs(g.corner_jump[k][i]) /
                                        (span_time * limits.acceleration[i]));
        }
        share = std::min(share, 0.5);
        // Every node within two spans' travel at the corner speed (and at least the neighbours).
        const double reach = 2 * v * span_time;
        for (std::size_t j = k; j-- > 0 && g.lambda[k] - g.lambda[j] <= reach;)
            factor[j] = std::min(factor[j], 1 - share);
        for (std::size_t j = k; j < g.size() && g.lambda[j] - g.lambda[k] <= reach; ++j) {
            factor[j] = std::min(factor[j], 1 - share);
        }
        if (k > 0) factor[k - 1] = std::min(factor[k - 1], 1 - share);
        if (k + 1 < g.size()) factor[k + 1] = std::min(factor[k + 1], 1 - share);
    }
}

std::size_t backward_pass(const PathGrid& pg, const Piece& piece, const Limits& limits,
                          const std::vector<double>& accel_factor, double tangential_margin,
                          const std::vector<double>& caps, double span_time, double end_zone,
                          std::vector<double>& dip, std::vector<double>& beta, std::size_t top,
                          std::size_t unchanged_below) {
    const Grid& g = pg.grid;
    if (beta.size() < g.size()) beta.resize(g.size(), 0);
    if (dip.size() < g.size()) dip.resize(g.size(), kNoCap);
    top = std::min(top, piece.last);
    if (top == piece.last) {
        beta[piece.last] = 0;
        dip[piece.last] = kNoCap;
    }
    LpRow rows[4 * kAxesMax];
    std::size_t lowest = top;
    for (std::size_t k = top; k-- > piece.first;) {
        const double dl = g.lambda[k + 1] - g.lambda[k];
        const double bend = acceleration_cap(g, k, limits, accel_factor[k], caps[k]);
        // A span from speed s can at most stop at its end (constant deceleration s / span_time),
        // so from a knot at speed s, x = s^2 can fall no faster than by 2 s / span_time per mm:
        // a dip in the speed caps (a tight bend, a corner) is approached with beta falling no
        // faster than that at the lower end of each interval (x linear between nodes, as the
        // forward pass interpolates it), 5 % to spare.
        double d = bend;
        // A dip of 0 (a node at rest: the piece's end, or one its retries capped there) is no
        // dip to approach span by span: its slope sqrt(0) would hold beta at 0 over the whole
        // piece before it. The end itself is approached by the landings of the forward pass, and
        // so is a dip at most end_zone (half an LSB) before it: a near-cusp's tip nanometres
        // before a stop, within half an LSB of the end point on the device's grid (its slope held
        // beta at 0.1 mm/s over the 0.27 mm before it, where no whole-tick span could follow).
        if (span_time > 0 && dip[k + 1] > 0 && g.lambda[piece.last] - g.lambda[k + 1] > end_zone) {
            const double below = dip[k + 1];
            d = std::min(d, below + 1.9 * std::sqrt(below) * std::max(dl, 0.0) / span_time);
        }
        double x;
        if (!(dl > 1e-12)) {  // a joint: the speed is the same on both sides
            x = std::min(beta[k + 1], bend);
        } else {
            const std::size_t n =
                interval_rows(g, k, dl, limits, accel_factor, tangential_margin, rows);
            x = lp_max_x(rows, n, caps[k], 0, beta[k + 1]);
        }
        if (span_time > 0) x = std::min(x, d);
        if (k < unchanged_below && x == beta[k] && d == dip[k])
            break;  // nothing below changes either
        beta[k] = x;
        dip[k] = d;
        lowest = k;
    }
    return lowest;
}

double topp_piece_time(const PathGrid& pg, const Piece& piece, const Limits& limits,
                       const std::vector<double>& accel_factor, const std::vector<double>& beta) {
    const Grid& g = pg.grid;
    LpRow rows[4 * kAxesMax];
    double x = 0, time = 0;
    for (std::size_t k = piece.first; k < piece.last; ++k) {
        const double dl = g.lambda[k + 1] - g.lambda[k];
        double y;
        if (!(dl > 1e-12)) {
            y = std::min(x, beta[k + 1]);
        } else {
            const std::size_t n = interval_rows(g, k, dl, limits, accel_factor, 1.0, rows);
            (void)lp_max_y(rows, n, x, 0, beta[k + 1], y);
            const double sum = std::sqrt(x) + std::sqrt(y);
            time += sum > 0 ? 2 * dl / sum : std::numeric_limits<double>::infinity();
        }
        x = y;
    }
    return time;
}

}  // namespace pathstream::host::planner_detail
