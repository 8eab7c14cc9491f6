// Per-axis velocity and acceleration limits, and the exact check of a span against them.
//
// The device refuses any span whose exact cubic (before the core's one rounding) would move an
// axis faster or accelerate it harder than its limit anywhere inside the span. The check is
// exact integer arithmetic: no tolerance, no sampling (docs/device.md).
#pragma once

#include <cstdint>

#include "pathstream/status.hpp"
#include "pathstream/tick_cubic.hpp"

namespace pathstream::device {

/// Highest tick rate the limit arithmetic is proven for (and a sane device accepts).
inline constexpr std::uint32_t kMaxTickHz = 100000;

/// Limits of one axis in LSB per second and LSB per second squared (both >= 1).
struct AxisLimits {
    std::uint32_t max_velocity = 0;      ///< LSB/s
    std::uint32_t max_acceleration = 0;  ///< LSB/s^2
};

/// The device's motion configuration: tick rate and each axis's limits.
template <unsigned Axes>
struct MotionLimits {
    std::uint32_t tick_hz = 0;  ///< 1..kMaxTickHz
    AxisLimits axis[Axes] = {};
};

/// kOk when tick_hz is 1..kMaxTickHz and every limit is >= 1; kBadLimits otherwise.
/// Cost: a loop over the axes. Any context.
template <unsigned Axes>
[[nodiscard]] Status check_limits(const MotionLimits<Axes>& limits) {
    if (limits.tick_hz < 1 || limits.tick_hz > kMaxTickHz) return Status::kBadLimits;
    for (unsigned a = 0; a < Axes; ++a) {
        if (limits.axis[a].max_velocity < 1 || limits.axis[a].max_acceleration < 1) {
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

}  // namespace pathstream::device
