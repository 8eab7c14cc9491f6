// The device's own moves under a jerk limit: a controlled stop and the move back onto the path
// as short sequences of Hermite spans whose acceleration is continuous within one tick of jerk
// at every join (the move's start and end included) and whose jerk inside each span is within
// the limit. Without a jerk limit the device keeps the single spans of stop_spans.hpp.
//
// Why several spans: a Hermite span's acceleration is linear, so one span cannot start at the
// path's acceleration, decelerate and end at rest with its acceleration back at 0. Two spans
// can for a stop (the end position free), three for a re-entry (both ends fixed): the knots
// between them follow in closed form from those conditions (docs/device.md, "Jerk limit").
#pragma once

#include <cstdint>

#include "pathstream/device/motion_limits.hpp"
#include "pathstream/device/stop_spans.hpp"
#include "pathstream/span.hpp"
#include "pathstream/status.hpp"
#include "pathstream/wide_int.hpp"

namespace pathstream::device {

/// Spans of a jerk-limited stop (2, or 3 with a ramp first) or re-entry (3, or 4 with a ramp
/// last).
inline constexpr unsigned kMaxJerkMoveSpans = 4;

/// A device move of up to kMaxJerkMoveSpans Hermite spans, played in order. Plain value, storage
/// inline.
template <unsigned Axes>
struct JerkMove {
    Span<Axes> span[kMaxJerkMoveSpans] = {};
    unsigned count = 0;
};

/// True when any axis has a jerk limit (then the device's stop and re-entry are JerkMoves).
template <unsigned Axes>
constexpr bool has_jerk_limit(const MotionLimits<Axes>& limits) {
    for (unsigned a = 0; a < Axes; ++a) {
        if (limits.axis[a].max_jerk != 0) return true;
    }
    return false;
}

/// The acceleration at tick k (0..n) of a Hermite span of n ticks with chord C and tangents T0,
/// T1 on one axis, rounded to a multiple of 1/base^2 LSB/tick^2 (halves away from zero): the
/// exact value is ((6C - 4T0 - 2T1)(n - k) + (-6C + 2T0 + 4T1) k) / n^3, whose denominator a
/// long span would take past what check_acceleration_step is proven for. base: the tick count
/// the stop from there is planned on (1..n). Cost: two 128-bit products and a division. Tick
/// interrupt context (a one-off).
inline TickAcceleration acceleration_within_span(std::int32_t chord, std::int32_t start_tangent,
                                                 std::int32_t end_tangent, std::uint32_t n,
                                                 std::uint32_t k, std::uint32_t base) {
    // |6C| <= 1.5 2^30, |4T0 + 2T1| <= 6 2^29: each end's numerator < 2^33, times n <= 2^16.
    const std::int64_t c = chord, t0 = start_tangent, t1 = end_tangent, nn = n, kk = k;
    const std::int64_t at_k =
        (6 * c - 4 * t0 - 2 * t1) * (nn - kk) + (-6 * c + 2 * t0 + 4 * t1) * kk;
    const std::uint64_t base2 = static_cast<std::uint64_t>(base) * base;
    const std::uint64_t cube = static_cast<std::uint64_t>(n) * n * n;  // < 2^49
    // round(|at_k| base^2 / n^3) = floor((2 |at_k| base^2 + n^3) / (2 n^3)); < 2^34 since
    // base <= n.
    const Int128 twice = multiply_unsigned(stop_detail::magnitude64(at_k), 2 * base2);
    const FloorDivision r =
        floor_divide(twice + Int128::from(static_cast<std::int64_t>(cube)), 2 * cube);
    const auto magnitude = static_cast<std::int64_t>(r.quotient.lo);
    return TickAcceleration{at_k < 0 ? -magnitude : magnitude, base2};
}

namespace jerk_detail {

/// round(num / den) for den >= 1, halves away from zero; false when |result| > limit.
inline bool round_quotient(Int128 num, std::uint64_t den, std::int64_t limit, std::int64_t& out) {
    const Int128 m = magnitude(num);
    const FloorDivision q =
        floor_divide(m + m + Int128::from(static_cast<std::int64_t>(den)), 2 * den);
    if (q.quotient.hi != 0 || q.quotient.lo > static_cast<std::uint64_t>(limit)) return false;
    const auto v = static_cast<std::int64_t>(q.quotient.lo);
    out = num.negative() ? -v : v;
    return true;
}

/// `count` empty Hermite spans of `ticks` ticks.
template <unsigned Axes>
void reset(JerkMove<Axes>& move, unsigned count, std::uint32_t ticks) {
    for (unsigned i = 0; i < kMaxJerkMoveSpans; ++i) {
        Span<Axes>& s = move.span[i];
        s = Span<Axes>{};
        s.basis = Basis::kHermite;
        s.ticks = ticks;
    }
    move.count = count;
}

/// Hermite span from p0 over `chord` with tangents t0, t1 on one axis; false when a value
/// leaves the span's ranges.
template <unsigned Axes>
bool set_axis(Span<Axes>& s, unsigned axis, std::int64_t p0, std::int64_t chord, std::int64_t t0,
              std::int64_t t1) {
    const std::int64_t p1 = p0 + chord;
    if (p0 > kMaxPositionLsb || p0 < -kMaxPositionLsb || p1 > kMaxPositionLsb ||
        p1 < -kMaxPositionLsb)
        return false;
    if (t0 > kMaxTangentLsb || t0 < -kMaxTangentLsb || t1 > kMaxTangentLsb || t1 < -kMaxTangentLsb)
        return false;
    s.control[axis][0] = static_cast<std::int32_t>(p0);
    s.control[axis][1] = static_cast<std::int32_t>(p1);
    s.control[axis][2] = static_cast<std::int32_t>(t0);
    s.control[axis][3] = static_cast<std::int32_t>(t1);
    return true;
}

/// The rules of check_move that need only each span's end accelerations, read off its integer
/// Hermite values ((6C - 4T0 - 2T1) / n^2 and (-6C + 2T0 + 4T1) / n^2, exactly the cubic's):
/// both ends within the acceleration limit, the jerk inside the span, every join. A necessary
/// condition of check_move at a fraction of its cost (a few 128-bit products per span and
/// axis, no span validation), so the searches reject most lengths without validating.
template <unsigned Axes>
Status check_move_ends(const JerkMove<Axes>& move, const TickAcceleration (&start)[Axes],
                       const TickAcceleration* end, const MotionLimits<Axes>& limits) {
    const std::uint64_t hz = limits.tick_hz;
    TickAcceleration previous[Axes];
    for (unsigned a = 0; a < Axes; ++a) previous[a] = start[a];
    for (unsigned i = 0; i < move.count; ++i) {
        const Span<Axes>& s = move.span[i];
        const std::uint64_t n = s.ticks, n2 = n * n;
        for (unsigned a = 0; a < Axes; ++a) {
            const AxisLimits& l = limits.axis[a];
            // |6C| < 2^34, |4T0 + 2T1| < 2^34: each numerator < 2^35, over n^2 < 2^33.
            const std::int64_t chord = static_cast<std::int64_t>(s.control[a][1]) - s.control[a][0];
            const std::int64_t t0 = s.control[a][2], t1 = s.control[a][3];
            const TickAcceleration at_start{6 * chord - 4 * t0 - 2 * t1, n2};
            const TickAcceleration at_end{-6 * chord + 2 * t0 + 4 * t1, n2};
            // |N| hz^2 <= A n^2 at both ends (< 2^35 2^34 against < 2^32 2^33).
            const Int128 bound = multiply_unsigned(l.max_acceleration, n2);
            const TickAcceleration ends[2] = {at_start, at_end};
            for (const TickAcceleration& e : ends) {
                if (bound < multiply_unsigned(stop_detail::magnitude64(e.numerator), hz * hz)) {
                    return Status::kAccelerationLimit;
                }
            }
            // Jerk (end - start) / n^3: |end - start| hz^3 (< 2^36 2^51) <= J n^3 (< 2^39 2^48).
            if (l.max_jerk != 0 &&
                multiply_unsigned(static_cast<std::uint64_t>(l.max_jerk) * kJerkUnitLsb, n2) *
                        static_cast<std::int64_t>(n) <
                    multiply_unsigned(
                        stop_detail::magnitude64(at_end.numerator - at_start.numerator),
                        hz * hz * hz)) {
                return Status::kJerkLimit;
            }
            if (Status st = check_acceleration_step(at_start, previous[a], l, limits.tick_hz);
                st != Status::kOk) {
                return st;
            }
            previous[a] = at_end;
        }
    }
    for (unsigned a = 0; a < Axes; ++a) {
        const Status st =
            end == nullptr
                ? check_end_at_rest(previous[a], limits.axis[a], limits.tick_hz)
                : check_acceleration_step(end[a], previous[a], limits.axis[a], limits.tick_hz);
        if (st != Status::kOk) return st;
    }
    return Status::kOk;
}

/// Every span of `move` within the velocity, acceleration and jerk limits, and every join
/// within one tick of jerk: the first span's start against `start`, the last span's end
/// against `end` (nullptr: rest). The status of the first rule broken: the jerk and join
/// rules of check_move_ends first (exactly the cubic's, from the Hermite values), then each
/// span validated and checked against the velocity and acceleration limits.
template <unsigned Axes>
Status check_move(const JerkMove<Axes>& move, const TickAcceleration (&start)[Axes],
                  const TickAcceleration* end, const MotionLimits<Axes>& limits) {
    if (Status s = check_move_ends(move, start, end, limits); s != Status::kOk) return s;
    for (unsigned i = 0; i < move.count; ++i) {
        if (Status s = stop_detail::check_span(move.span[i], limits); s != Status::kOk) return s;
    }
    return Status::kOk;
}

/// `acceleration` moved towards 0 by up to nine tenths of one tick of jerk per axis (the rest
/// is room for the rounding of the spans shaped from it): a step the join rule allows, so an
/// axis whose jerk limit ramps faster than a whole tick can starts from (near) 0.
template <unsigned Axes>
void toward_zero(const TickAcceleration (&acceleration)[Axes], const MotionLimits<Axes>& limits,
                 TickAcceleration (&out)[Axes]) {
    const std::uint64_t hz3 =
        static_cast<std::uint64_t>(limits.tick_hz) * limits.tick_hz * limits.tick_hz;
    for (unsigned a = 0; a < Axes; ++a) {
        const std::uint64_t q = acceleration[a].denominator;
        // 0.9 J Q = 9 max_jerk 100 Q / (10 hz^3): below 2^32 * 2^10 * 2^35.
        const Int128 nine =
            multiply_unsigned(static_cast<std::uint64_t>(limits.axis[a].max_jerk) * 900u, q);
        const FloorDivision step = floor_divide(nine, 10 * hz3);
        const std::int64_t n = acceleration[a].numerator;
        const std::uint64_t mag = stop_detail::magnitude64(n);
        const std::uint64_t cut =
            step.quotient.hi != 0 || step.quotient.lo >= mag ? mag : step.quotient.lo;
        const auto left = static_cast<std::int64_t>(mag - cut);
        out[a] = TickAcceleration{n < 0 ? -left : left, q};
    }
}

/// The end acceleration (numerator over shape.denominator) of the stop's ramp of r ticks on one
/// axis: where `shape` points along the velocity tangent/ticks (speeding up), shape less
/// 0.9 J r against the velocity, but no further than 0.9 of the acceleration limit that way;
/// else 0 (the ramp takes the acceleration to 0). Cost: a few 128-bit products and divisions.
inline std::int64_t ramp_end(const TickAcceleration& shape, std::int32_t tangent, std::uint64_t r,
                             const AxisLimits& limits, std::uint32_t tick_hz) {
    const std::int64_t n = shape.numerator;
    if (tangent == 0 || limits.max_jerk == 0 || (n > 0) != (tangent > 0) || n == 0) return 0;
    const std::uint64_t q = shape.denominator, hz = tick_hz;
    // 0.9 J r Q = 9 max_jerk 100 r Q / (10 hz^3): below 2^32 2^10 2^16 2^35; 0.9 A Q =
    // 9 max_acceleration Q / (10 hz^2): below 2^36 2^35.
    const FloorDivision ramp =
        floor_divide(multiply_unsigned(static_cast<std::uint64_t>(limits.max_jerk) * 900u * r, q),
                     10 * hz * hz * hz);
    const FloorDivision floor =
        floor_divide(multiply_unsigned(static_cast<std::uint64_t>(limits.max_acceleration) * 9u, q),
                     10 * hz * hz);
    // |N| < 2^36 for accelerations within any limit: a cap beyond 2^40 changes nothing.
    constexpr std::uint64_t kNoCap = std::uint64_t{1} << 40;
    const std::uint64_t mag = stop_detail::magnitude64(n);
    const std::uint64_t cap =
        floor.quotient.hi != 0 || floor.quotient.lo > kNoCap ? kNoCap : floor.quotient.lo;
    // Along the velocity: mag - ramp, at least -cap.
    const bool past = ramp.quotient.hi != 0 || ramp.quotient.lo >= mag + cap;
    const std::int64_t along =
        past ? -static_cast<std::int64_t>(cap)
             : static_cast<std::int64_t>(mag) - static_cast<std::int64_t>(ramp.quotient.lo);
    return n > 0 ? along : -along;
}

/// plan_jerk_stop's two spans from the given acceleration (see there).
/// `shape`: the acceleration the spans are shaped from (`acceleration` itself, or 0 where the
/// step from it to 0 is within one tick of jerk); the joins are checked against `acceleration`.
template <unsigned Axes>
Status two_span_stop(const Lsb (&position)[Axes], const std::int32_t (&tangent)[Axes],
                     std::uint32_t ticks, const TickAcceleration (&acceleration)[Axes],
                     const TickAcceleration (&shape)[Axes], const MotionLimits<Axes>& limits,
                     JerkMove<Axes>& out) {
    const auto build = [&](std::uint64_t j, JerkMove<Axes>& move) -> Status {
        const std::uint64_t m = j * ticks;
        if (m > kMaxSpanTicks) return Status::kStopTooLong;
        reset(move, 2, static_cast<std::uint32_t>(m));
        for (unsigned a = 0; a < Axes; ++a) {
            const std::int64_t t0 =
                static_cast<std::int64_t>(tangent[a]) * static_cast<std::int64_t>(j);
            const std::uint64_t q = shape[a].denominator;
            // S = (2 T0 Q + N m^2) / (4 Q): |2 T0 Q| < 2^82, |N m^2| < 2^68.
            const Int128 num = Int128::from(2 * t0) * static_cast<std::int64_t>(q) +
                               Int128::from(shape[a].numerator) * static_cast<std::int64_t>(m * m);
            std::int64_t s = 0, third = 0, s_third = 0;
            if (!round_quotient(num, 4 * q, kMaxTangentLsb, s) ||
                !round_quotient(Int128::from(t0), 3, kMaxTangentLsb, third) ||
                !round_quotient(Int128::from(s), 3, kMaxTangentLsb, s_third)) {
                return Status::kStopTooLong;
            }
            const std::int64_t p0 = position[a], d1 = third + s;
            if (!set_axis(move.span[0], a, p0, d1, t0, s) ||
                !set_axis(move.span[1], a, p0 + d1, s_third, s, 0)) {
                return Status::kStopTooLong;
            }
        }
        return check_move(move, acceleration, nullptr, limits);
    };
    // At least what a constant deceleration at the limit needs (plan_stop's first estimate).
    const std::uint64_t hz2 = static_cast<std::uint64_t>(limits.tick_hz) * limits.tick_hz;
    std::uint64_t first = 1;
    for (unsigned a = 0; a < Axes; ++a) {
        const std::uint64_t per_a = stop_detail::ceil_div(
            stop_detail::magnitude64(tangent[a]) * hz2, limits.axis[a].max_acceleration);
        const std::uint64_t need =
            stop_detail::ceil_div(per_a, static_cast<std::uint64_t>(ticks) * ticks);
        if (need > first) first = need;
    }
    return stop_detail::shortest_passing(first, kMaxSpanTicks / ticks, build, out);
}

/// plan_jerk_reentry's three spans onto the given acceleration (see there).
template <unsigned Axes>
Status three_span_reentry(const Lsb (&from)[Axes], const Lsb (&to)[Axes],
                          const std::int32_t (&tangent)[Axes], std::uint32_t ticks,
                          const TickAcceleration (&acceleration)[Axes],
                          const TickAcceleration (&shape)[Axes], const MotionLimits<Axes>& limits,
                          JerkMove<Axes>& out) {
    const auto build = [&](std::uint64_t j, JerkMove<Axes>& move) -> Status {
        const std::uint64_t m = j * ticks;
        if (m > kMaxSpanTicks) return Status::kStopTooLong;
        reset(move, 3, static_cast<std::uint32_t>(m));
        for (unsigned a = 0; a < Axes; ++a) {
            const std::int64_t tb =
                static_cast<std::int64_t>(tangent[a]) * static_cast<std::int64_t>(j);
            const std::int64_t d = static_cast<std::int64_t>(to[a]) - from[a];
            const std::uint64_t q = shape[a].denominator;
            const Int128 nm2 = Int128::from(shape[a].numerator) * static_cast<std::int64_t>(m * m);
            // S1 = (3 (D - TB) Q + N m^2) / (6 Q); S2 - S1 = (2 TB Q - N m^2) / (4 Q).
            const Int128 n1 = Int128::from(3 * (d - tb)) * static_cast<std::int64_t>(q) + nm2;
            const Int128 n2 = Int128::from(2 * tb) * static_cast<std::int64_t>(q) - nm2;
            std::int64_t s1 = 0, step = 0, d1 = 0, s2_third = 0;
            if (!round_quotient(n1, 6 * q, kMaxTangentLsb, s1) ||
                !round_quotient(n2, 4 * q, kMaxTangentLsb, step)) {
                return Status::kStopTooLong;
            }
            const std::int64_t s2 = s1 + step;
            if (!round_quotient(Int128::from(s1), 3, kMaxTangentLsb, d1) ||
                !round_quotient(Int128::from(s2), 3, kMaxTangentLsb, s2_third)) {
                return Status::kStopTooLong;
            }
            const std::int64_t d2 = s1 + s2_third, d3 = d - d1 - d2;
            const std::int64_t p0 = from[a];
            if (!set_axis(move.span[0], a, p0, d1, 0, s1) ||
                !set_axis(move.span[1], a, p0 + d1, d2, s1, s2) ||
                !set_axis(move.span[2], a, p0 + d1 + d2, d3, s2, tb)) {
                return Status::kStopTooLong;
            }
        }
        TickAcceleration rest[Axes];
        for (unsigned a = 0; a < Axes; ++a) rest[a] = TickAcceleration{};
        return check_move(move, rest, acceleration, limits);
    };
    return stop_detail::shortest_passing(1, kMaxSpanTicks / ticks, build, out);
}

/// One span of r ticks (1..kMaxSpanTicks) that takes the acceleration linearly to about 0 (the
/// rounding of its end point and tangent): forward from `position` with velocity tangent/ticks
/// and acceleration `acceleration` (`forward`), or backward, ending at `position` with that
/// velocity and acceleration and starting at about 0. Its tangent at `position` is the
/// velocity on r ticks, rounded (a join the velocity rule allows: check_join). `other`: the
/// acceleration at its other end, exactly (the cubic's). The span within the limits and its
/// jerk, the join at `position` within one tick of jerk.
template <unsigned Axes>
Status acceleration_ramp(bool forward, const Lsb (&position)[Axes],
                         const std::int32_t (&tangent)[Axes], std::uint32_t ticks, std::uint64_t r,
                         const TickAcceleration (&acceleration)[Axes],
                         const TickAcceleration (&shape)[Axes], const MotionLimits<Axes>& limits,
                         Span<Axes>& ramp, TickAcceleration (&other)[Axes],
                         bool decelerate = false) {
    if (r > kMaxSpanTicks) return Status::kStopTooLong;
    ramp = Span<Axes>{};
    ramp.basis = Basis::kHermite;
    ramp.ticks = static_cast<std::uint32_t>(r);
    for (unsigned a = 0; a < Axes; ++a) {
        std::int64_t t = 0;
        if (!round_quotient(Int128::from(tangent[a]) * static_cast<std::int64_t>(r), ticks,
                            kMaxTangentLsb, t)) {
            return Status::kStopTooLong;
        }
        const std::uint64_t q = shape[a].denominator;
        // `decelerate`: a stop's ramp ends an axis that is speeding up decelerating instead of
        // at 0 (ramp_end): ramped only to 0, such an axis keeps speeding up for the whole ramp,
        // whose length the axis with the slowest ramp sets, and can pass its velocity limit.
        const std::int64_t e = forward && decelerate ? ramp_end(shape[a], tangent[a], r,
                                                                limits.axis[a], limits.tick_hz)
                                                     : 0;
        const Int128 nr2 = Int128::from(shape[a].numerator) * static_cast<std::int64_t>(r * r);
        const Int128 er2 = Int128::from(e) * static_cast<std::int64_t>(r * r);
        // Forward: S = T + (A + E) r^2 / 2 (E the end acceleration), chord (A r^2 + 4 T + 2 S) / 6
        // (= T + (2 A + E) r^2 / 6). Backward: T0 = T - A r^2 / 2, chord (2 T0 + T) / 3.
        const Int128 tq = Int128::from(2 * t) * static_cast<std::int64_t>(q);
        std::int64_t s = 0, chord = 0;
        if (!round_quotient(forward ? tq + nr2 + er2 : tq - nr2, 2 * q, kMaxTangentLsb, s))
            return Status::kStopTooLong;
        const Int128 chord6 = forward
                                  ? nr2 + Int128::from(4 * t + 2 * s) * static_cast<std::int64_t>(q)
                                  : Int128::from(2 * (2 * s + t)) * static_cast<std::int64_t>(q);
        if (!round_quotient(chord6, 6 * q, kMaxTangentLsb, chord)) return Status::kStopTooLong;
        const bool fits =
            forward
                ? set_axis(ramp, a, position[a], chord, t, s)
                : set_axis(ramp, a, static_cast<std::int64_t>(position[a]) - chord, chord, s, t);
        if (!fits) return Status::kStopTooLong;
    }
    ValidatedSpan<Axes> v;
    if (Status st = validate_span(ramp, v); st != Status::kOk) return st;
    for (unsigned a = 0; a < Axes; ++a) {
        const AxisLimits& l = limits.axis[a];
        if (Status st = check_axis_limits(v.cubic[a], v.timing, l, limits.tick_hz);
            st != Status::kOk)
            return st;
        if (Status st = check_axis_jerk(v.cubic[a], v.timing, l, limits.tick_hz); st != Status::kOk)
            return st;
        const std::int32_t own = ramp.control[a][forward ? 2 : 3];
        if (Status st = check_join(forward ? own : tangent[a], forward ? ramp.ticks : ticks,
                                   forward ? tangent[a] : own, forward ? ticks : ramp.ticks, l,
                                   limits.tick_hz);
            st != Status::kOk) {
            return st;
        }
        const TickAcceleration at_position = forward ? start_acceleration(v.cubic[a], v.timing)
                                                     : end_acceleration(v.cubic[a], v.timing);
        if (Status st = check_acceleration_step(at_position, acceleration[a], l, limits.tick_hz);
            st != Status::kOk) {
            return st;
        }
        other[a] = forward ? end_acceleration(v.cubic[a], v.timing)
                           : start_acceleration(v.cubic[a], v.timing);
    }
    return Status::kOk;
}

/// The fallbacks the stop and the re-entry share. `sequence(point, tangent, ticks, check,
/// shape, move)` plans the spans between rest and the path's state at `point` (velocity
/// tangent/ticks, acceleration `check`), shaped from `shape`. Tried: shaped from the
/// acceleration itself; from it moved towards 0 (toward_zero); then with a ramp of the fewest
/// power-of-two ticks that passes, first (`forward`: the stop) or last (the re-entry), the
/// sequence planned from the ramp's other end.
template <unsigned Axes, class Sequence>
Status with_fallbacks(bool forward, const Lsb (&point)[Axes], const std::int32_t (&tangent)[Axes],
                      std::uint32_t ticks, const TickAcceleration (&acceleration)[Axes],
                      const MotionLimits<Axes>& limits, Sequence sequence, JerkMove<Axes>& out) {
    const Status direct = sequence(point, tangent, ticks, acceleration, acceleration, out);
    if (direct == Status::kOk ||
        !(stop_detail::longer_may_pass(direct) || direct == Status::kStopTooLong)) {
        return direct;
    }
    // Shaped from the acceleration less one tick of jerk's step towards 0 (all of it where the
    // jerk limit ramps it faster than a whole tick can).
    TickAcceleration shaped[Axes];
    toward_zero(acceleration, limits, shaped);
    if (sequence(point, tangent, ticks, acceleration, shaped, out) == Status::kOk)
        return Status::kOk;
    JerkMove<Axes> part;
    // A stop's ramp of each length takes the acceleration to 0 first, then (where that fails)
    // takes the axes that are speeding up on to decelerating (acceleration_ramp's `decelerate`).
    for (std::uint64_t r = 1; r <= kMaxSpanTicks; r *= 2) {
        for (int variant = 0; variant < (forward ? 2 : 1); ++variant) {
            Span<Axes> ramp;
            TickAcceleration other[Axes];
            const Status s = acceleration_ramp(forward, point, tangent, ticks, r, acceleration,
                                               shaped, limits, ramp, other, variant == 1);
            if (s != Status::kOk && variant == 0 && !stop_detail::longer_may_pass(s)) return s;
            if (s != Status::kOk) continue;
            Lsb far[Axes];
            std::int32_t far_tangent[Axes];
            for (unsigned a = 0; a < Axes; ++a) {
                far[a] = ramp.control[a][forward ? 1 : 0];
                far_tangent[a] = ramp.control[a][forward ? 3 : 2];
            }
            if (sequence(far, far_tangent, ramp.ticks, other, other, part) != Status::kOk) continue;
            for (unsigned i = 0; i < part.count; ++i) out.span[forward ? i + 1 : i] = part.span[i];
            out.span[forward ? 0 : part.count] = ramp;
            out.count = part.count + 1;
            return Status::kOk;
        }
    }
    return Status::kStopTooLong;
}

}  // namespace jerk_detail

/// A controlled stop under a jerk limit, from `position` where the motion has velocity
/// tangent/ticks LSB per tick and acceleration `acceleration` (LSB/tick^2) per axis. Two spans
/// of m = j * ticks ticks each, T0 = j * tangent (the same velocity, exactly), the acceleration
/// going linearly from the given one to a_mid over the first span and back to 0 over the
/// second, ending at rest: with S the tangent at the middle knot (per m ticks),
///   S = T0 / 2 + A0 m^2 / 4,  P_mid = P0 + T0 / 3 + S,  P_end = P_mid + S / 3
/// (each rounded to a whole LSB), j the smallest for which both spans pass the velocity,
/// acceleration and jerk limits and every join, the start against `acceleration` and the end
/// against rest, is within one tick of jerk. Where no j passes (a long pair keeps the starting
/// acceleration too long: the speed overshoots), a ramp first: one span of r ticks (the fewest
/// power of two that passes, its tangent the velocity on r ticks rounded, a join the velocity
/// rule allows) that takes the acceleration to about 0 at up to the jerk limit, then the two
/// spans from its end. The stop leaves the path along its own curve (the tangent
/// line bent by the starting acceleration), like plan_stop's along the tangent.
/// Errors: kStopTooLong when nothing fits in kMaxSpanTicks ticks per span or the ranges.
/// Cost: up to ~2 log2(j) checks of two spans, times log2(r) with the ramp. Tick interrupt
/// context (a one-off).
template <unsigned Axes>
[[nodiscard]] Status plan_jerk_stop(const Lsb (&position)[Axes],
                                    const std::int32_t (&tangent)[Axes], std::uint32_t ticks,
                                    const TickAcceleration (&acceleration)[Axes],
                                    const MotionLimits<Axes>& limits, JerkMove<Axes>& out) {
    const auto two_spans = [&](const Lsb(&at)[Axes], const std::int32_t(&t)[Axes], std::uint32_t n,
                               const TickAcceleration(&check)[Axes],
                               const TickAcceleration(&shape)[Axes], JerkMove<Axes>& move) {
        return jerk_detail::two_span_stop(at, t, n, check, shape, limits, move);
    };
    return jerk_detail::with_fallbacks(true, position, tangent, ticks, acceleration, limits,
                                       two_spans, out);
}

/// The move from rest at `from` back to `to` under a jerk limit, arriving with velocity
/// tangent/ticks LSB per tick and acceleration `acceleration` (LSB/tick^2) per axis: three
/// spans of m = j * ticks ticks, starting at rest with no acceleration and ending with
/// T = j * tangent (the velocity, exactly) at `to` exactly; with D = to - from, TB = j *
/// tangent and AB the arrival acceleration, the tangents at the two inner knots are
///   S1 = (D - TB) / 2 + AB m^2 / 6,  S2 = S1 + TB / 2 - AB m^2 / 4
/// and the chords S1 / 3, S1 + S2 / 3 and the rest of D (rounded to whole LSB), which makes the
/// acceleration continuous at both inner knots and 0 at the start. j the smallest for which the
/// spans pass the velocity, acceleration and jerk limits and every join (rest at the start,
/// `acceleration` at the end) is within one tick of jerk. Where no j passes, a ramp last: one
/// span of r ticks (as plan_jerk_stop's; it arrives with the velocity on r ticks rounded) that
/// takes the acceleration from about 0 to the arrival's at up to the jerk limit, the three
/// spans leading to its start. Errors: kStopTooLong when nothing
/// fits. Cost: up to ~2 log2(j) checks of three spans, times log2(r) with the ramp. Tick
/// interrupt context (a one-off when a hold resumes) or task (a host's resume).
template <unsigned Axes>
[[nodiscard]] Status plan_jerk_reentry(const Lsb (&from)[Axes], const Lsb (&to)[Axes],
                                       const std::int32_t (&tangent)[Axes], std::uint32_t ticks,
                                       const TickAcceleration (&acceleration)[Axes],
                                       const MotionLimits<Axes>& limits, JerkMove<Axes>& out) {
    const auto three_spans = [&](const Lsb(&at)[Axes], const std::int32_t(&t)[Axes],
                                 std::uint32_t n, const TickAcceleration(&check)[Axes],
                                 const TickAcceleration(&shape)[Axes], JerkMove<Axes>& move) {
        return jerk_detail::three_span_reentry(from, at, t, n, check, shape, limits, move);
    };
    return jerk_detail::with_fallbacks(false, to, tangent, ticks, acceleration, limits, three_spans,
                                       out);
}

/// A pen-down approach under a jerk limit (a host's resume): one span of r ticks, the fewest of
/// min_ticks, 2 min_ticks, 4 min_ticks .. that passes, ending at `to` with velocity
/// tangent/ticks (rounded on r ticks) and acceleration `acceleration` and starting with about
/// none (jerk_detail::acceleration_ramp, backward). `start`: its start acceleration exactly, for
/// the re-entry onto it. Errors: kStopTooLong when none fits in kMaxSpanTicks. Task context.
template <unsigned Axes>
[[nodiscard]] Status plan_jerk_approach(const Lsb (&to)[Axes], const std::int32_t (&tangent)[Axes],
                                        std::uint32_t ticks,
                                        const TickAcceleration (&acceleration)[Axes],
                                        std::uint32_t min_ticks, const MotionLimits<Axes>& limits,
                                        Span<Axes>& out, TickAcceleration (&start)[Axes]) {
    TickAcceleration shaped[Axes];
    jerk_detail::toward_zero(acceleration, limits, shaped);
    for (std::uint64_t r = min_ticks < 1 ? 1 : min_ticks; r <= kMaxSpanTicks; r *= 2) {
        const Status s = jerk_detail::acceleration_ramp(false, to, tangent, ticks, r, acceleration,
                                                        shaped, limits, out, start);
        if (s == Status::kOk || !stop_detail::longer_may_pass(s)) return s;
    }
    return Status::kStopTooLong;
}

}  // namespace pathstream::device
