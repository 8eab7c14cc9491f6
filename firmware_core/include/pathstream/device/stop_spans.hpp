// The device's own spans: a controlled stop from a span boundary or from inside a span, and
// the move back onto the path when motion resumes. Both are Hermite spans checked like any other
// (core validation, exact limit check), so a generated span never exceeds what a host span may do.
#pragma once

#include <cstdint>

#include "pathstream/device/motion_limits.hpp"
#include "pathstream/span.hpp"
#include "pathstream/status.hpp"
#include "pathstream/wide_int.hpp"

namespace pathstream::device {

namespace stop_detail {

template <unsigned Axes>
Status check_span(const Span<Axes>& span, const MotionLimits<Axes>& limits) {
    ValidatedSpan<Axes> v;
    if (Status s = validate_span(span, v); s != Status::kOk) return s;
    for (unsigned a = 0; a < Axes; ++a) {
        if (Status s = check_axis_limits(v.cubic[a], v.timing, limits.axis[a], limits.tick_hz);
            s != Status::kOk) {
            return s;
        }
    }
    return Status::kOk;
}

constexpr std::uint64_t magnitude64(std::int64_t v) {
    return v < 0 ? static_cast<std::uint64_t>(0) - static_cast<std::uint64_t>(v)
                 : static_cast<std::uint64_t>(v);
}

constexpr std::uint64_t ceil_div(std::uint64_t a, std::uint64_t b) {
    return a / b + (a % b != 0 ? 1u : 0u);
}

/// A longer move may pass where this one failed: every limit eases with the length (rounding
/// aside).
constexpr bool longer_may_pass(Status s) {
    return s == Status::kAccelerationLimit || s == Status::kVelocityLimit ||
           s == Status::kJerkLimit || s == Status::kAccelerationStep ||
           s == Status::kDifferenceOutOfRange;
}

/// The smallest multiple j in first..jmax for which build(j, candidate) passes, by doubling
/// from `first` (jmax itself tried last) and then bisection; the passing candidate in `out`.
/// kStopTooLong when none does, or build's status when it is not one a longer move may pass.
template <class Candidate, class Build>
Status shortest_passing(std::uint64_t first, std::uint64_t jmax, Build build, Candidate& out) {
    std::uint64_t bad = 0, good = first < 1 ? 1 : first;
    Candidate candidate;
    Status s = Status::kStopTooLong;
    for (;;) {
        if (good > jmax) {
            if (bad >= jmax) return Status::kStopTooLong;
            good = jmax;
        }
        s = build(good, candidate);
        if (!longer_may_pass(s)) break;
        if (good == jmax) return Status::kStopTooLong;
        bad = good;
        good *= 2;
    }
    if (s != Status::kOk) return s;
    out = candidate;
    while (good - bad > 1) {  // smallest passing j in (bad, good]
        const std::uint64_t mid = bad + (good - bad) / 2;
        if (build(mid, candidate) == Status::kOk) {
            good = mid;
            out = candidate;
        } else {
            bad = mid;
        }
    }
    return Status::kOk;
}

}  // namespace stop_detail

/// Tries of the stop search beyond the first estimate (rounding of odd tangents can push the
/// exact acceleration a hair over; one more multiple of n always fixes it in practice).
inline constexpr unsigned kStopSearchTries = 8;

/// Plans a stop from `position` where the last span (of `ticks` ticks) ended with Hermite
/// tangent `tangent` (velocity tangent/ticks LSB per tick): a span of m = j * ticks ticks with
/// T0 = j * tangent (the same velocity, exactly), T1 = 0 and P1 = P0 + T0/2, i.e. constant
/// deceleration along the tangent line, j the smallest for which the span passes the limits.
/// Errors: kStopTooLong when no such span fits in kMaxSpanTicks ticks or the tangent range.
/// Cost: one estimate plus one or two span validations. Tick interrupt context (a one-off).
template <unsigned Axes>
[[nodiscard]] Status plan_stop(const Lsb (&position)[Axes], const std::int32_t (&tangent)[Axes],
                               std::uint32_t ticks, const MotionLimits<Axes>& limits,
                               Span<Axes>& out) {
    using stop_detail::ceil_div;
    using stop_detail::magnitude64;
    // Deceleration per s^2 is |tangent| hz^2 / (j ticks^2): j >= |tangent| hz^2 / (a_max ticks^2).
    const std::uint64_t hz2 = static_cast<std::uint64_t>(limits.tick_hz) * limits.tick_hz;
    std::uint64_t j = 1;
    for (unsigned a = 0; a < Axes; ++a) {
        const std::uint64_t per_a =
            ceil_div(magnitude64(tangent[a]) * hz2, limits.axis[a].max_acceleration);
        const std::uint64_t need = ceil_div(per_a, static_cast<std::uint64_t>(ticks) * ticks);
        if (need > j) j = need;
    }
    for (unsigned attempt = 0; attempt <= kStopSearchTries; ++attempt, ++j) {
        if (j * ticks > kMaxSpanTicks) return Status::kStopTooLong;
        out = Span<Axes>{};
        out.basis = Basis::kHermite;
        out.ticks = static_cast<std::uint32_t>(j * ticks);
        bool fits = true;
        for (unsigned a = 0; a < Axes; ++a) {
            const std::int64_t t0 =
                static_cast<std::int64_t>(tangent[a]) * static_cast<std::int64_t>(j);
            const std::int64_t p1 = static_cast<std::int64_t>(position[a]) + t0 / 2;
            if (t0 > kMaxTangentLsb || t0 < -kMaxTangentLsb || p1 > kMaxPositionLsb ||
                p1 < -kMaxPositionLsb) {
                fits = false;
                break;
            }
            out.control[a][0] = position[a];
            out.control[a][1] = static_cast<std::int32_t>(p1);
            out.control[a][2] = static_cast<std::int32_t>(t0);
            out.control[a][3] = 0;
        }
        if (!fits) return Status::kStopTooLong;
        const Status s = stop_detail::check_span(out, limits);
        if (s == Status::kOk) return Status::kOk;
        if (s != Status::kAccelerationLimit && s != Status::kVelocityLimit) return s;
    }
    return Status::kStopTooLong;
}

/// Shortest base of a stop from inside a span longer than this: a stop from a long span's
/// interior takes at least this many ticks (64 ms at 1 kHz) unless its velocity needs more,
/// so the rounding of its start tangent stays within 1/128 LSB per tick.
inline constexpr std::uint32_t kMinInSpanStopBase = 64;

/// Where a controlled stop from tick `k` (1 .. n-1) of a Hermite span of `n` ticks starts:
/// the span's velocity there, per axis, as the tangent `tangent` of a span of `base` ticks
/// (velocity tangent/base LSB per tick), for plan_stop. The exact velocity is M/n^3 LSB per
/// tick with M = 6k(n-k)C + (n-k)(n-3k)T0 + k(3k-2n)T1 (C the chord P1 - P0, T0 and T1 the
/// span's tangents: the stamp's); `tangent` is base*M/n^3 rounded to the nearest integer
/// (halves away from zero), within 1/(2 base) LSB per tick of it: the rounding the join
/// check allows a span of `base` ticks. base = n when the span is no longer than the stop
/// needs or than kMinInSpanStopBase, so the stop is planned on the span's own length like a
/// stop at its end (at k = n this is exactly T1 on n ticks); otherwise base = max(m0,
/// kMinInSpanStopBase), m0 the fewest ticks in which every axis can shed its velocity at its
/// max_acceleration, so a long span's stop is not stretched to the span's length.
/// Exact: |M| < 2^63 for every admitted chord, tangent and tick count (proven below); the
/// products and quotients after it are two-word. Errors: kStopTooLong when a tangent leaves
/// +-kMaxTangentLsb. Cost: per axis three 64-bit products, two 128-bit products and two
/// 128-bit divisions (a one-off, like plan_stop). Tick interrupt context.
template <unsigned Axes>
[[nodiscard]] Status velocity_within_span(const std::int32_t (&chord)[Axes],
                                          const std::int32_t (&start_tangent)[Axes],
                                          const std::int32_t (&end_tangent)[Axes], std::uint32_t n,
                                          std::uint32_t k, const MotionLimits<Axes>& limits,
                                          std::int32_t (&tangent)[Axes], std::uint32_t& base) {
    using stop_detail::magnitude64;
    // |6k(n-k)C| <= 1.5 n^2 2^28 and |(n-k)(n-3k)T0|, |k(3k-2n)T1| <= n^2 2^29 with n <= 2^16,
    // |C| <= 2^28, |T| <= 2^29: |M| <= 5.5 * 2^60 < 2^63.
    static_assert(kMaxSpanTicks <= (1u << 16) && kMaxTangentLsb <= (std::int64_t{1} << 29) &&
                  2 * kMaxPositionLsb <= (std::int64_t{1} << 28));
    const std::int64_t nn = n, kk = k;
    const std::uint64_t cube = static_cast<std::uint64_t>(n) * n * n;  // < 2^49
    const std::uint64_t hz2 = static_cast<std::uint64_t>(limits.tick_hz) * limits.tick_hz;
    std::int64_t m[Axes];
    std::uint64_t need = 1;  // m0: ticks the stop needs at the axes' max_acceleration
    for (unsigned a = 0; a < Axes; ++a) {
        m[a] = 6 * kk * (nn - kk) * chord[a] + (nn - kk) * (nn - 3 * kk) * start_tangent[a] +
               kk * (3 * kk - 2 * nn) * end_tangent[a];
        // ceil(|M| hz^2 / (n^3 a_max)): the deceleration |v| hz^2 / ticks within a_max.
        const FloorDivision per_cube =
            floor_divide(multiply_unsigned(magnitude64(m[a]), hz2), cube);
        if (per_cube.quotient.hi != 0) {
            need = kMaxSpanTicks + 1u;
            continue;
        }
        const std::uint64_t q = per_cube.quotient.lo + (per_cube.remainder != 0 ? 1u : 0u);
        const std::uint64_t amax = limits.axis[a].max_acceleration;
        const std::uint64_t ticks = q / amax + (q % amax != 0 ? 1u : 0u);
        if (ticks > need) need = ticks;
    }
    base = n;
    if (n > kMinInSpanStopBase && need < n) {
        base = need > kMinInSpanStopBase ? static_cast<std::uint32_t>(need) : kMinInSpanStopBase;
    }
    for (unsigned a = 0; a < Axes; ++a) {
        // round(base M / n^3) = floor((2 base |M| + n^3) / (2 n^3)), signed like M.
        const Int128 twice =
            multiply_unsigned(magnitude64(m[a]), 2u * static_cast<std::uint64_t>(base));
        const FloorDivision r =
            floor_divide(twice + Int128::from(static_cast<std::int64_t>(cube)), 2 * cube);
        if (r.quotient.hi != 0 || r.quotient.lo > static_cast<std::uint64_t>(kMaxTangentLsb)) {
            return Status::kStopTooLong;
        }
        const std::int64_t t = static_cast<std::int64_t>(r.quotient.lo);
        tangent[a] = static_cast<std::int32_t>(m[a] < 0 ? -t : t);
    }
    return Status::kOk;
}

/// Plans the move from rest at `from` back to `to`, arriving with the velocity of a span of
/// `ticks` ticks that ended with tangent `tangent` there: a Hermite span of m = j * ticks ticks
/// (T0 = 0, T1 = j * tangent, exact velocity), j the smallest passing the limits (doubling,
/// then bisection). Errors: kStopTooLong when none fits. Cost: up to ~2 log2(j) span
/// validations (tens of thousands of instructions), a one-off when a hold resumes. The
/// device runs it in the tick that applies the resume; a port with a tight tick budget can
/// lengthen that tick's deadline or plan it in a task.
template <unsigned Axes>
[[nodiscard]] Status plan_reentry(const Lsb (&from)[Axes], const Lsb (&to)[Axes],
                                  const std::int32_t (&tangent)[Axes], std::uint32_t ticks,
                                  const MotionLimits<Axes>& limits, Span<Axes>& out) {
    auto build = [&](std::uint64_t j, Span<Axes>& s) -> Status {
        if (j * ticks > kMaxSpanTicks) return Status::kStopTooLong;
        s = Span<Axes>{};
        s.basis = Basis::kHermite;
        s.ticks = static_cast<std::uint32_t>(j * ticks);
        for (unsigned a = 0; a < Axes; ++a) {
            const std::int64_t t1 =
                static_cast<std::int64_t>(tangent[a]) * static_cast<std::int64_t>(j);
            if (t1 > kMaxTangentLsb || t1 < -kMaxTangentLsb) return Status::kStopTooLong;
            s.control[a][0] = from[a];
            s.control[a][1] = to[a];
            s.control[a][2] = 0;
            s.control[a][3] = static_cast<std::int32_t>(t1);
        }
        return stop_detail::check_span(s, limits);
    };
    // build refuses j * ticks > kMaxSpanTicks, so jmax = kMaxSpanTicks bounds nothing it accepts.
    return stop_detail::shortest_passing(1, kMaxSpanTicks, build, out);
}

}  // namespace pathstream::device
