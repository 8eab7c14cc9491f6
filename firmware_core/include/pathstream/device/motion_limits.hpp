// Per-axis velocity and acceleration limits, and the exact check of a span against them.
//
// The device refuses any span whose exact cubic (before the core's one rounding) would move an
// axis faster or accelerate it harder than its limit anywhere inside the span. The check is
// exact integer arithmetic: no tolerance, no sampling (docs/device.md).
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

/// Limits of one axis in LSB per second and LSB per second squared (both >= 1), and its
/// travel (the work area's soft limits, LSB; the default is the whole position range).
struct AxisLimits {
    std::uint32_t max_velocity = 0;      ///< LSB/s
    std::uint32_t max_acceleration = 0;  ///< LSB/s^2
    std::int32_t min_position = -static_cast<std::int32_t>(kMaxPositionLsb);
    std::int32_t max_position = static_cast<std::int32_t>(kMaxPositionLsb);
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

/// kOk when tick_hz is kMinTickHz..kMaxTickHz, every limit is >= 1 and pen_down_ticks is at most
/// kMaxPenDownTicks; kBadLimits otherwise. Cost: a loop over the axes. Any context.
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

}  // namespace pathstream::device
