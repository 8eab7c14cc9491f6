// The device's own spans: a controlled stop from a span boundary, and the move back onto the
// path when motion resumes. Both are Hermite spans checked like any other (core validation,
// exact limit check), so a generated span never exceeds what a host span may do.
#pragma once

#include <cstdint>

#include "pathstream/device/motion_limits.hpp"
#include "pathstream/span.hpp"
#include "pathstream/status.hpp"

namespace pathstream::device {

namespace stop_detail {

template <unsigned Axes>
Status check_span(const Span<Axes>& span, const MotionLimits<Axes>& limits) {
    ValidatedSpan<Axes> v;
    if (Status s = validate_span(span, v); s != Status::kOk) return s;
    for (unsigned a = 0; a < Axes; ++a) {
        if (Status s = check_axis_limits(v.cubic[a], v.timing, limits.axis[a], limits.tick_hz); s != Status::kOk) {
            return s;
        }
    }
    return Status::kOk;
}

constexpr std::uint64_t magnitude64(std::int64_t v) {
    return v < 0 ? static_cast<std::uint64_t>(0) - static_cast<std::uint64_t>(v) : static_cast<std::uint64_t>(v);
}

constexpr std::uint64_t ceil_div(std::uint64_t a, std::uint64_t b) { return a / b + (a % b != 0 ? 1u : 0u); }

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
[[nodiscard]] Status plan_stop(const Lsb (&position)[Axes], const std::int32_t (&tangent)[Axes], std::uint32_t ticks,
                               const MotionLimits<Axes>& limits, Span<Axes>& out) {
    using stop_detail::ceil_div;
    using stop_detail::magnitude64;
    // Deceleration per s^2 is |tangent| hz^2 / (j ticks^2): j >= |tangent| hz^2 / (a_max ticks^2).
    const std::uint64_t hz2 = static_cast<std::uint64_t>(limits.tick_hz) * limits.tick_hz;
    std::uint64_t j = 1;
    for (unsigned a = 0; a < Axes; ++a) {
        const std::uint64_t per_a = ceil_div(magnitude64(tangent[a]) * hz2, limits.axis[a].max_acceleration);
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
            const std::int64_t t0 = static_cast<std::int64_t>(tangent[a]) * static_cast<std::int64_t>(j);
            const std::int64_t p1 = static_cast<std::int64_t>(position[a]) + t0 / 2;
            if (t0 > kMaxTangentLsb || t0 < -kMaxTangentLsb || p1 > kMaxPositionLsb || p1 < -kMaxPositionLsb) {
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

/// Plans the move from rest at `from` back to `to`, arriving with the velocity of a span of
/// `ticks` ticks that ended with tangent `tangent` there: a Hermite span of m = j * ticks ticks
/// (T0 = 0, T1 = j * tangent, exact velocity), j the smallest passing the limits (doubling,
/// then bisection). Errors: kStopTooLong when none fits. Cost: up to ~2 log2(j) span
/// validations (tens of thousands of instructions), a one-off when a hold resumes. The
/// device runs it in the tick that applies the resume; a port with a tight tick budget can
/// lengthen that tick's deadline or plan it in a task.
template <unsigned Axes>
[[nodiscard]] Status plan_reentry(const Lsb (&from)[Axes], const Lsb (&to)[Axes], const std::int32_t (&tangent)[Axes],
                                  std::uint32_t ticks, const MotionLimits<Axes>& limits, Span<Axes>& out) {
    auto build = [&](std::uint64_t j, Span<Axes>& s) -> Status {
        if (j * ticks > kMaxSpanTicks) return Status::kStopTooLong;
        s = Span<Axes>{};
        s.basis = Basis::kHermite;
        s.ticks = static_cast<std::uint32_t>(j * ticks);
        for (unsigned a = 0; a < Axes; ++a) {
            const std::int64_t t1 = static_cast<std::int64_t>(tangent[a]) * static_cast<std::int64_t>(j);
            if (t1 > kMaxTangentLsb || t1 < -kMaxTangentLsb) return Status::kStopTooLong;
            s.control[a][0] = from[a];
            s.control[a][1] = to[a];
            s.control[a][2] = 0;
            s.control[a][3] = static_cast<std::int32_t>(t1);
        }
        return stop_detail::check_span(s, limits);
    };
    std::uint64_t bad = 0;  // largest j known to fail (0: none tried)
    std::uint64_t good = 1;
    Span<Axes> candidate;
    Status s = build(good, candidate);
    while (s == Status::kAccelerationLimit || s == Status::kVelocityLimit || s == Status::kDifferenceOutOfRange) {
        bad = good;
        good *= 2;
        s = build(good, candidate);
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

}  // namespace pathstream::device
