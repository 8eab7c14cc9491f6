// The jerk stage (docs/planner.md §12): the second-order motion of each piece, retimed by a box
// filter of its path parameter, sampled on the LSB grid, with integer tangents chosen so that
// every span and every join meets the jerk limits exactly.
#include "jerk.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <sstream>
#include <vector>

#include "emit.hpp"
#include "forward_pass.hpp"
#include "grid.hpp"
#include "limits.hpp"
#include "pathstream/host/planner.hpp"
#include "pathstream/machine/machine.hpp"
#include "pathstream/units.hpp"
#include "piece.hpp"
#include "vec.hpp"

namespace pathstream::host::planner_detail {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr std::size_t kSplineReach = 14;   // knots each side the spline tangent looks at
constexpr std::size_t kBacktrack = 8;      // knots whose tangents stay open to backtracking
constexpr std::int64_t kTangentReach = 3;  // candidates: the rounded target +- this
constexpr int kStepBudget = 200000;        // backtracking steps per choice

// Hermite basis integrated from 0 to u (for the box filter's integral of lambda).
double i00(double u) {
    return u * u * u * u / 2 - u * u * u + u;
}
double i10(double u) {
    return u * u * u * u / 4 - 2 * u * u * u / 3 + u * u / 2;
}
double i01(double u) {
    return -u * u * u * u / 2 + u * u * u;
}
double i11(double u) {
    return u * u * u * u / 4 - u * u * u / 3;
}

// Jerk limit in LSB/tick^3 (infinity without one).
double jerk_lsb(const AxisLimits& a, const MachineProfile& p) {
    const double t = 1 / p.tick_hz;
    return a.max_jerk > 0 ? a.max_jerk * t * t * t / p.mm_per_lsb : kInf;
}

}  // namespace

std::uint32_t jerk_span_ticks(const MachineProfile& p, std::uint32_t ticks) {
    double j = kInf;
    for (const auto& a : p.axes) j = std::min(j, jerk_lsb(a, p));
    if (!std::isfinite(j)) return ticks;
    double n = ticks;
    n = std::max(n, std::ceil(std::sqrt(8 / j) - 1e-9));
    n = std::max(n, std::ceil(std::cbrt(120 / j) - 1e-9));
    return static_cast<std::uint32_t>(std::min<double>(n, kMaxSpanTicks));
}

JerkSetup jerk_setup(const MachineProfile& p, const Limits& limits) {
    JerkSetup s;
    s.span_ticks = p.ticks_per_span;
    s.jerk_lsb.fill(kInf);
    double ratio = 0;  // largest a / j, s (the machine's a: replans lower the acceleration, not M)
    for (std::size_t i = 0; i < p.axes.size(); ++i) {
        s.jerk_lsb[i] = jerk_lsb(p.axes[i], p);
        if (p.axes[i].max_jerk > 0) {
            s.active = true;
            ratio = std::max(ratio, p.axes[i].max_acceleration / p.axes[i].max_jerk);
        }
    }
    if (!s.active) return s;
    // A box filter of M ticks turns path accelerations within +-A into path jerk within 2 A / M.
    const double m = std::ceil(2 * ratio * p.tick_hz / limits.jerk_share - 1e-9);
    // At least two spans: a filter shorter than the knots' spacing leaves stops that the
    // spline through the knots cannot follow without overshooting them.
    s.filter_ticks = static_cast<std::uint32_t>(std::clamp(m, 2.0 * p.ticks_per_span, 1e9));
    return s;
}

JerkStage::JerkStage(const MachineProfile& profile, const JerkSetup& setup, std::size_t axes)
    : profile_(profile), setup_(setup), axes_(axes) {
    const double t = 1 / profile.tick_hz;
    for (std::size_t i = 0; i < axes; ++i) {
        vlim_[i] = profile.axes[i].max_velocity * t / profile.mm_per_lsb;
        alim_[i] = profile.axes[i].max_acceleration * t * t / profile.mm_per_lsb;
    }
}

void JerkStage::piece_begin(double lambda, std::size_t subpath, bool pen_down,
                            const SpanEmitter& emitter) {
    in_piece_ = true;
    subpath_ = subpath;
    pen_down_ = pen_down;
    raw_.clear();
    raw_end_ = 0;
    l_start_ = l_end_ = lambda;
    ended_ = false;
    last_knot_ = 0;
    knots_.clear();
    knot_base_ = 0;
    JKnot k0;
    k0.p = emitter.position();
    k0.lambda = lambda;
    knots_.push_back(k0);
    targets_ = 0;
    final_ = 0;
    prev_a_ = emitter.last_end_acceleration();
    prev_n_ = emitter.last_ticks();
    hint_ = 0;
}

void JerkStage::rebase(double lambda) {
    if (!in_piece_) return;
    const double last = raw_.empty() ? l_start_ : raw_.back().l1;
    const double d = lambda - last;
    for (RawSpan& r : raw_) {
        r.l0 += d;
        r.l1 += d;
    }
    l_start_ += d;
    l_end_ += d;
    for (JKnot& k : knots_) k.lambda += d;
    hint_ = 0;
}

// Lambda of the second-order motion at time t (ticks from the piece's start).
double JerkStage::raw_lambda(double t) const {
    if (raw_.empty()) return ended_ && t >= static_cast<double>(raw_end_) ? l_end_ : l_start_;
    if (t <= static_cast<double>(raw_.front().t0)) return raw_.front().l0;
    for (const RawSpan& r : raw_) {
        if (t <= static_cast<double>(r.t0 + r.m)) {
            const double u = std::clamp((t - static_cast<double>(r.t0)) / r.m, 0.0, 1.0);
            return (2 * u * u * u - 3 * u * u + 1) * r.l0 + (u * u * u - 2 * u * u + u) * r.d0 +
                   (-2 * u * u * u + 3 * u * u) * r.l1 + (u * u * u - u * u) * r.d1;
        }
    }
    return raw_.back().l1;
}

// The box filter: the mean of lambda over the M ticks before t, integrated exactly (lambda is
// the second-order motion's Hermite cubic per span, at rest before and after the piece).
double JerkStage::filtered(std::int64_t t) const {
    const double m = setup_.filter_ticks;
    const double lo = static_cast<double>(t) - m, hi = static_cast<double>(t);
    const double ref = raw_lambda(hi);
    double sum = 0;
    const double start =
        raw_.empty() ? static_cast<double>(raw_end_) : static_cast<double>(raw_.front().t0);
    if (lo < start) sum += (std::min(hi, start) - lo) * (l_start_ - ref);
    if (hi > static_cast<double>(raw_end_))
        sum += (hi - std::max(lo, static_cast<double>(raw_end_))) * (l_end_ - ref);
    for (const RawSpan& r : raw_) {
        const double a = std::max(lo, static_cast<double>(r.t0)),
                     b = std::min(hi, static_cast<double>(r.t0 + r.m));
        if (!(b > a)) continue;
        const double ua = (a - static_cast<double>(r.t0)) / r.m,
                     ub = (b - static_cast<double>(r.t0)) / r.m;
        sum += r.m * ((r.l0 - ref) * (i00(ub) - i00(ua)) + r.d0 * (i10(ub) - i10(ua)) +
                      (r.l1 - ref) * (i01(ub) - i01(ua)) + r.d1 * (i11(ub) - i11(ua)));
    }
    return ref + sum / m;
}

std::int64_t JerkStage::p_at(std::size_t axis, std::int64_t k) const {
    if (k <= 0) return p0_[axis];
    const std::size_t i =
        std::max(static_cast<std::size_t>(k), knot_base_);  // pruned: weight < 1e-8
    if (ended_ && i >= last_knot_) return knot(last_knot_).p[axis];
    return knot(i).p[axis];
}

void JerkStage::add_knots(const PathGrid& pg, const Piece& piece) {
    const std::int64_t n = setup_.span_ticks;
    for (;;) {
        const std::size_t k = knot_base_ + knots_.size();
        const std::int64_t t = static_cast<std::int64_t>(k) * n;
        if (ended_ ? k > last_knot_ : t > raw_end_) break;
        JKnot kn;
        const auto point = [&](std::int64_t tick, double& lambda) {
            if (ended_ && tick >= raw_end_ + setup_.filter_ticks) {
                lambda = l_end_;
                PathAt at;
                at.q = end_q_;
                return at;
            }
            lambda = filtered(tick);
            return path_at(pg, piece, lambda, hint_);
        };
        // The path where the span ending here should be at its quarters (for the deviation).
        for (std::size_t i = 0; i < kQuarters && k > 0; ++i) {
            double unused = 0;
            const PathAt at = point(t - n + quarter_tick(i), unused);
            kn.between[i] = at.q;
            kn.between_t[i] = at.t;
        }
        const Vec q = point(t, kn.lambda).q;
        for (std::size_t a = 0; a < axes_; ++a) {
            kn.p[a] = ended_ && t >= raw_end_ + setup_.filter_ticks
                          ? end_p_[a]
                          : std::llround(q[a] / profile_.mm_per_lsb);
        }
        knots_.push_back(kn);
    }
    // Raw spans the filter no longer reaches.
    const std::int64_t next = static_cast<std::int64_t>(knot_base_ + knots_.size()) * n;
    while (raw_.size() > 1 && raw_.front().t0 + raw_.front().m + setup_.filter_ticks + n + 1 < next)
        raw_.pop_front();
}

// Target tangents: those of the interpolating C2 cubic spline through the knots (the piece at
// rest before and after), T_{k-1} + 4 T_k + T_{k+1} = 3 (P_{k+1} - P_{k-1}), solved by its
// decaying inverse: T_k = sum_j rho^|j| / (2 sqrt 3) * 3 (P_{k+j+1} - P_{k+j-1}), rho = sqrt 3 - 2.
void JerkStage::add_targets() {
    const double rho = std::sqrt(3.0) - 2, c0 = 1 / (2 * std::sqrt(3.0));
    const std::size_t have = knot_base_ + knots_.size();
    for (;;) {
        const std::size_t k = targets_;
        if (ended_ ? k > last_knot_ : k + kSplineReach + 1 >= have) break;
        JKnot& kn = knot(k);
        for (std::size_t a = 0; a < axes_; ++a) {
            double sum = 0;
            for (std::int64_t j = -static_cast<std::int64_t>(kSplineReach);
                 j <= static_cast<std::int64_t>(kSplineReach); ++j) {
                const std::int64_t i = static_cast<std::int64_t>(k) + j;
                const double wj = c0 * std::pow(rho, static_cast<double>(std::llabs(j)));
                sum += wj * 3 * static_cast<double>(p_at(a, i + 1) - p_at(a, i - 1));
            }
            kn.target[a] = (k == 0 || (ended_ && k == last_knot_)) ? 0.0 : sum;
        }
        ++targets_;
    }
}

// Whether knot k's tangent (already set) meets, with those before it: the join at knot k - 1,
// the span from k - 1 to k (jerk, acceleration at both ends, peak velocity), and at the
// piece's last knot its end at rest (|a| within half the limit, so that the next piece's start
// has room).
bool JerkStage::valid(std::size_t a, std::size_t k, bool end) const {
    const double n = setup_.span_ticks, n2 = n * n;
    const double j = setup_.jerk_lsb[a];
    const std::size_t i = k - 1;
    const std::int64_t p0 = p_at(a, static_cast<std::int64_t>(i)),
                       p1 = p_at(a, static_cast<std::int64_t>(k));
    const std::int64_t t0 = knot(i).t[a], t1 = knot(k).t[a];
    const std::int64_t dp = p1 - p0;
    const double a0 = static_cast<double>(6 * dp - 4 * t0 - 2 * t1),
                 a1 = static_cast<double>(-6 * dp + 2 * t0 + 4 * t1);
    if (std::isfinite(j)) {
        if (i == 0) {
            const long double m2 = static_cast<long double>(prev_n_) * prev_n_;
            const long double step = std::fabs(static_cast<long double>(a0) * m2 -
                                               static_cast<long double>(prev_a_[a]) * n2);
            if (step > static_cast<long double>(j) * n2 * m2) return reject(0);
        } else {
            const std::int64_t pm = p_at(a, static_cast<std::int64_t>(i) - 1);
            const std::int64_t tm = knot(i - 1).t[a];
            const double r = static_cast<double>(6 * (p1 - pm) - 2 * (tm + 4 * t0 + t1));
            if (std::fabs(r) > j * n2) return reject(0);
        }
        if (std::fabs(static_cast<double>(6 * (-2 * dp + t0 + t1))) > j * n2 * n) return reject(1);
        if (end && std::fabs(a1) > 0.5 * j * n2) return reject(2);
    }
    if (std::fabs(a0) > alim_[a] * n2 || std::fabs(a1) > alim_[a] * n2) return reject(3);
    const auto v = [&](double u) {
        return std::fabs(static_cast<double>(t0) + a0 * u + (a1 - a0) * u * u / 2);
    };
    double peak = std::max(std::fabs(static_cast<double>(t0)), std::fabs(static_cast<double>(t1)));
    if (a0 * a1 < 0) peak = std::max(peak, v(a0 / (a0 - a1)));
    return peak <= vlim_[a] * n || reject(4);
}

// Tangents of knots from..to on one axis: each the nearest integer to its target that keeps
// every rule, backtracking over earlier choices (the plain C2 recurrence is unstable; steering
// within the tolerance is not). `end`: `to` is the piece's last knot, at rest.
bool JerkStage::choose_axis(std::size_t a, std::size_t from, std::size_t to, bool end) {
    struct Frame {
        std::int64_t base = 0;
        int tried = 0;
    };
    std::vector<Frame> stack(to - from + 1);
    const int per = 2 * static_cast<int>(kTangentReach) + 1;
    // Candidate c of a knot: the rounded target, then alternately below and above.
    const auto candidate = [&](std::size_t k, int c) {
        const double target = knot(k).target[a];
        const std::int64_t r = std::llround(target);
        const std::int64_t d = (c + 1) / 2;
        const bool below = (c % 2 == 1) == (target < static_cast<double>(r));
        return c == 0 ? r : (below ? r - d : r + d);
    };
    std::size_t k = from;
    int steps = 0;
    stack[0].tried = 0;
    while (true) {
        if (++steps > kStepBudget) return false;
        Frame& f = stack[k - from];
        const bool last = end && k == to;
        const int limit = last ? 1 : per;
        bool ok = false;
        while (f.tried < limit) {
            knot(k).t[a] = last ? 0 : candidate(k, f.tried);
            ++f.tried;
            if (valid(a, k, last)) {
                ok = true;
                break;
            }
        }
        if (ok) {
            if (k == to) return true;
            ++k;
            stack[k - from].tried = 0;
        } else {
            if (k == from) return false;
            --k;
        }
    }
}

bool JerkStage::choose_and_emit(bool end, const PathGrid& pg, const Piece& piece, double run_offset,
                                SpanEmitter& emitter) {
    add_targets();
    if (targets_ == 0) return true;
    const std::size_t to = targets_ - 1;
    if (to <= final_) return true;
    for (std::size_t a = 0; a < axes_; ++a) {
        rejected_.fill(0);
        if (!choose_axis(a, final_ + 1, to, end)) {
            failure_.failed = true;
            failure_.axis = a;
            const auto most =
                std::max_element(rejected_.begin(), rejected_.end()) - rejected_.begin();
            failure_.velocity = most == 4;
            failure_.rule = static_cast<int>(most);
            failure_.where = where(pg, piece, knot(final_).lambda, run_offset);
            return false;
        }
    }
    const std::size_t commit = end ? to : (to > kBacktrack ? to - kBacktrack : 0);
    for (std::size_t k = final_ + 1; k <= commit; ++k) {
        check_deviation(k, pg, piece, run_offset);
        emitter.motion_lsb(knot(k).p, knot(k - 1).t, knot(k).t, setup_.span_ticks, subpath_,
                           pen_down_);
        final_ = k;
    }
    // Knots neither the targets nor the backtracking reach again.
    const std::size_t keep = std::min(
        final_ > 0 ? final_ - 1 : 0, targets_ > kSplineReach + 1 ? targets_ - kSplineReach - 1 : 0);
    while (knot_base_ < keep && knots_.size() > 1) {
        knots_.pop_front();
        ++knot_base_;
    }
    return true;
}

// The span ending at knot k against the path where the filtered motion is at its quarters,
// across the path's tangent: within the chord tolerance (plus sqrt(axes) LSB) of the
// path as planned, else PlanError. check_plan measures every tick against the path as given.
void JerkStage::check_deviation(std::size_t k, const PathGrid& pg, const Piece& piece,
                                double run_offset) const {
    const JKnot& a = knot(k - 1);
    const JKnot& b = knot(k);
    const double lsb = profile_.mm_per_lsb;
    // check_plan's bound, delta + 1.5 sqrt(axes) LSB, less the setpoints' rounding.
    const double allowed = profile_.chord_tolerance + std::sqrt(static_cast<double>(axes_)) * lsb;
    for (std::size_t i = 0; i < kQuarters; ++i) {
        const std::int64_t n = setup_.span_ticks;
        const double u = static_cast<double>(quarter_tick(i)) / static_cast<double>(n);
        const double h00 = 2 * u * u * u - 3 * u * u + 1, h10 = u * u * u - 2 * u * u + u;
        const double h01 = -2 * u * u * u + 3 * u * u, h11 = u * u * u - u * u;
        // Across the path's tangent there (the timing may differ along it by micrometres).
        Vec d{};
        for (std::size_t x = 0; x < axes_; ++x) {
            const double p =
                (h00 * static_cast<double>(a.p[x]) + h10 * static_cast<double>(a.t[x]) +
                 h01 * static_cast<double>(b.p[x]) + h11 * static_cast<double>(b.t[x])) *
                lsb;
            d[x] = p - b.between[i][x];
        }
        // Where the timing differs by more than 20 um the tangent's line is no longer the path
        // (0.2 um off at a 1 mm radius): that quarter is left to check_plan.
        const double along = dot(d, b.between_t[i]);
        if (std::fabs(along) > 0.02) continue;
        const double d2 = std::max(0.0, dot(d, d) - along * along);
        if (std::sqrt(d2) > allowed) {
            std::ostringstream m;
            m << "cannot plan " << where(pg, piece, b.lambda, run_offset)
              << " within the jerk limit: a span leaves the path by " << std::sqrt(d2)
              << " mm, over the chord tolerance (a curvature step too sharp for the spans; "
                 "a larger max_jerk or chord_tolerance)";
            throw PlanError(m.str());
        }
    }
}

bool JerkStage::raw_span(const Knot& from, const MotionSpan& span, const PathGrid& pg,
                         const Piece& piece, double run_offset, SpanEmitter& emitter) {
    RawSpan r;
    r.t0 = raw_end_;
    r.m = span.ticks;
    r.l0 = from.lambda;
    r.l1 = span.end.lambda;
    r.d0 = from.speed * span.ticks / profile_.tick_hz;
    r.d1 = span.end.speed * span.ticks / profile_.tick_hz;
    if (raw_.empty()) {
        l_start_ = from.lambda;
        for (std::size_t a = 0; a < axes_; ++a) p0_[a] = knot(0).p[a];
    }
    raw_.push_back(r);
    raw_end_ += span.ticks;
    l_end_ = span.end.lambda;
    add_knots(pg, piece);
    return choose_and_emit(false, pg, piece, run_offset, emitter);
}

bool JerkStage::piece_end(const Vec& end_q, const PathGrid& pg, const Piece& piece,
                          double run_offset, SpanEmitter& emitter) {
    in_piece_ = false;
    if (raw_.empty()) return true;  // no motion
    for (std::size_t a = 0; a < axes_; ++a)
        end_p_[a] = std::llround(end_q[a] / profile_.mm_per_lsb);
    end_q_ = end_q;
    ended_ = true;
    const std::int64_t n = setup_.span_ticks;
    last_knot_ = static_cast<std::size_t>((raw_end_ + setup_.filter_ticks + n - 1) / n);
    last_knot_ = std::max(last_knot_, final_ + 1);
    add_knots(pg, piece);
    // At rest a few knots later when the last ones cannot meet the rules as they are.
    for (int extra = 0;; ++extra) {
        if (choose_and_emit(true, pg, piece, run_offset, emitter)) break;
        if (extra >= 3) return false;
        failure_ = JerkFailure{};
        JKnot kn;
        kn.lambda = l_end_;
        for (std::size_t a = 0; a < axes_; ++a) kn.p[a] = end_p_[a];
        kn.between.fill(end_q_);
        kn.between_t.fill(Vec{});
        knots_.push_back(kn);
        ++last_knot_;
        targets_ = std::max(std::min(targets_, last_knot_ - 3), final_ + 1);
    }
    added_ticks_ +=
        static_cast<std::uint64_t>(static_cast<std::int64_t>(last_knot_) * n - raw_end_);
    return true;
}

}  // namespace pathstream::host::planner_detail
