// Per-axis velocity, acceleration and jerk limits, and the exact checks of a span against them.
//
// The device refuses any span whose exact cubic (before the core's one rounding) would move an
// axis faster, accelerate it harder or change its acceleration faster than its limit anywhere
// inside the span, and any join where the velocity or (with a jerk limit) the acceleration
// steps by more than one tick's worth. The checks are exact integer arithmetic: no tolerance,
// no sampling (docs/device.md).
#pragma once

#include <cstdint>

#include "pathstream/status.hpp"
#include "pathstream/tick_cubic.hpp"
#include "pathstream/units.hpp"

namespace pathstream::device {

/// Highest tick rate the limit arithmetic is proven for (and a sane device accepts).
inline constexpr std::uint32_t kMaxTickHz = 100000;
/// Lowest tick rate a device accepts: the machine profile's lower bound too, so a device
/// never runs a rate no profile can describe.
inline constexpr std::uint32_t kMinTickHz = 10;

/// The unit of AxisLimits::max_jerk: 100 LSB/s^3. A 32-bit count of it spans 100 ..
/// 4.3e11 LSB/s^3, i.e. 1e3 mm/s^3 at 10 um per LSB (1e5 LSB/s^3, 1,000 units: 0.1 %
/// steps) up to 1e7 mm/s^3 at 0.1 um per LSB (1e11 LSB/s^3), and fits the two registers and
/// one CAN item every other limit takes.
inline constexpr std::uint32_t kJerkUnitLsb = 100;

/// Limits of one axis in LSB per second and LSB per second squared (both >= 1), its jerk
/// limit (0: none), and its travel (the work area's soft limits, LSB; the default is the whole
/// position range).
struct AxisLimits {
    std::uint32_t max_velocity = 0;      ///< LSB/s
    std::uint32_t max_acceleration = 0;  ///< LSB/s^2
    std::int32_t min_position = -static_cast<std::int32_t>(kMaxPositionLsb);
    std::int32_t max_position = static_cast<std::int32_t>(kMaxPositionLsb);
    /// In kJerkUnitLsb (100 LSB/s^3); 0: no jerk limit (no jerk check inside a span, and the
    /// acceleration may step at a join, as without the field).
    std::uint32_t max_jerk = 0;
};

/// The device's motion configuration: tick rate, each axis's limits, and the pen-down delay
/// the device allows for when it brings the pen back onto the paper after a re-entry.
template <unsigned Axes>
struct MotionLimits {
    std::uint32_t tick_hz = 0;  ///< kMinTickHz..kMaxTickHz
    AxisLimits axis[Axes] = {};
    /// Ticks from switching the pen output on to the pen touching (0..kMaxPenDownTicks): a
    /// re-entry onto a pen-down span switches the pen on this many ticks before it reaches
    /// the boundary, so the pen lands there (docs/device.md, "Pen").
    std::uint32_t pen_down_ticks = 0;
};

/// Longest pen-down delay, in ticks: what one 16-bit Modbus register holds.
inline constexpr std::uint32_t kMaxPenDownTicks = 65535;

/// kOk when tick_hz is kMinTickHz..kMaxTickHz, every velocity and acceleration limit is >= 1,
/// pen_down_ticks is at most kMaxPenDownTicks and the travel is a range within the position
/// range; kBadLimits otherwise. Every max_jerk is valid (0: none; the jerk arithmetic is
/// proven for the whole 32-bit range). Cost: a loop over the axes. Any context.
template <unsigned Axes>
[[nodiscard]] Status check_limits(const MotionLimits<Axes>& limits) {
    if (limits.tick_hz < kMinTickHz || limits.tick_hz > kMaxTickHz) return Status::kBadLimits;
    if (limits.pen_down_ticks > kMaxPenDownTicks) return Status::kBadLimits;
    for (unsigned a = 0; a < Axes; ++a) {
        const AxisLimits& l = limits.axis[a];
        if (l.max_velocity < 1 || l.max_acceleration < 1) return Status::kBadLimits;
        if (l.min_position >= l.max_position || l.min_position < -kMaxPositionLsb ||
            l.max_position > kMaxPositionLsb) {
            return Status::kBadLimits;
        }
    }
    return Status::kOk;
}

/// Checks one axis's exact cubic (from make_tick_cubic) over u in [0, 1]: |velocity| <=
/// max_velocity everywhere (ends and the interior extremum of the quadratic derivative) and
/// |acceleration| <= max_acceleration at both ends (acceleration of a cubic is linear, so the
/// ends bound it). Returns kOk, kVelocityLimit or kAccelerationLimit. `tick_hz` must be
/// 1..kMaxTickHz. Cost: about ten 128-bit products (~hundreds of instructions on Cortex-M4).
/// Task context.
[[nodiscard]] Status check_axis_limits(const TickCubic& cubic, const SpanTiming& timing,
                                       const AxisLimits& limits, std::uint32_t tick_hz);

/// Checks that one axis's exact cubic stays within its travel [min_position, max_position]
/// for u in [0, 1], by proof: its four Bernstein (Bezier) coefficients lie within it, and the
/// curve lies within their hull. Exact integer arithmetic, no tolerance; conservative only
/// where a control value pokes out while the curve turns back inside (a span grazing the
/// edge). Returns kOk or kOutsideTravel. Cost: a few 128-bit products. Task context.
[[nodiscard]] Status check_axis_travel(const TickCubic& cubic, const SpanTiming& timing,
                                       const AxisLimits& limits);

/// Checks one axis at the join of two Hermite spans: a span of `ticks` ticks starting with
/// tangent `start_tangent` may follow one of `previous_ticks` ticks that ended with tangent
/// `previous_end_tangent` (0 and any tick count for rest) when the velocities differ by at
/// most one tick of max_acceleration plus the rounding of the two integer tangents (half a
/// unit each, i.e. 1/(2n) LSB per tick):
///   2 |T0 n' - T1' n| hz^2 <= 2 a_max n n' + (n + n') hz^2.
/// Returns kOk or kVelocityStep. Exact (two-word integers). `tick_hz` 1..kMaxTickHz, tick
/// counts 1..kMaxSpanTicks, tangents within kMaxTangentLsb. Cost: a few 128-bit products.
/// Task context.
[[nodiscard]] Status check_join(std::int32_t start_tangent, std::uint32_t ticks,
                                std::int32_t previous_end_tangent, std::uint32_t previous_ticks,
                                const AxisLimits& limits, std::uint32_t tick_hz);

/// One axis's acceleration at a span's start or end in LSB/tick^2, as an exact fraction
/// numerator / denominator (denominator = scale * n^2 >= 1). Rest is {0, 1}. Plain value.
struct TickAcceleration {
    std::int64_t numerator = 0;     ///< |.| < 2^36 for any cubic make_tick_cubic accepts
    std::uint64_t denominator = 1;  ///< < 2^35
};

/// The acceleration of an axis's exact cubic (from make_tick_cubic) at u = 0: 2b / (s n^2).
/// For a Hermite span, (6(P1 - P0) - 4 T0 - 2 T1) / n^2. Cost: a few multiplies. Any context.
TickAcceleration start_acceleration(const TickCubic& cubic, const SpanTiming& timing);

/// The acceleration at u = 1: (6a + 2b) / (s n^2); for a Hermite span,
/// (-6(P1 - P0) + 2 T0 + 4 T1) / n^2. Cost: a few multiplies. Any context.
TickAcceleration end_acceleration(const TickCubic& cubic, const SpanTiming& timing);

/// The acceleration at the end of a Hermite span of n ticks with chord C = P1 - P0 and
/// tangents T0, T1 on one axis: (-6C + 2T0 + 4T1) / n^2 LSB/tick^2, the same fraction as
/// end_acceleration of the span's cubic. |C| <= 2^28, |T| <= kMaxTangentLsb, n 1..kMaxSpanTicks.
/// Cost: a few multiplies. Any context.
TickAcceleration hermite_end_acceleration(std::int32_t chord, std::int32_t start_tangent,
                                          std::int32_t end_tangent, std::uint32_t n);

/// Checks one axis's exact cubic against its jerk limit J = max_jerk * kJerkUnitLsb / hz^3
/// LSB/tick^3: the cubic's third derivative is the constant 6a / (s n^3) LSB/tick^3 (for a
/// Hermite span 6(2 P0 - 2 P1 + T0 + T1) / n^3), and |6a| hz^3 <= J' D with J' the limit in
/// LSB/s^3 is checked exactly. kOk without a jerk limit (max_jerk 0), else kOk or kJerkLimit.
/// `tick_hz` 1..kMaxTickHz. Cost: two 128-bit products. Task context.
[[nodiscard]] Status check_axis_jerk(const TickCubic& cubic, const SpanTiming& timing,
                                     const AxisLimits& limits, std::uint32_t tick_hz);

/// Checks one axis at a join: the acceleration at the next span's start (`start`) may differ
/// from the previous span's end (`previous_end`; {0, 1} for rest: a job's first span, after a
/// pause, a job end or a queue drop) by at most one tick of jerk, J * 1 tick =
/// max_jerk * kJerkUnitLsb / hz^3 LSB/tick^2:
///   |N Q' - N' Q| hz^3 <= max_jerk * kJerkUnitLsb * Q Q'
/// (N/Q and N'/Q' the two fractions; spans of different lengths compare exactly). kOk without
/// a jerk limit, else kOk or kAccelerationStep. Exact (two-word integers: every product stays
/// below 2^123). `tick_hz` 1..kMaxTickHz. Cost: a few 128-bit products. Task context.
[[nodiscard]] Status check_acceleration_step(const TickAcceleration& start,
                                             const TickAcceleration& previous_end,
                                             const AxisLimits& limits, std::uint32_t tick_hz);

/// Checks that a span may end at rest (a job end, a pause): its end acceleration is within
/// one tick of jerk of 0 (check_acceleration_step against rest). kOk without a jerk limit,
/// else kOk or kAccelerationStep. Cost and context as check_acceleration_step.
[[nodiscard]] Status check_end_at_rest(const TickAcceleration& end, const AxisLimits& limits,
                                       std::uint32_t tick_hz);

}  // namespace pathstream::device
