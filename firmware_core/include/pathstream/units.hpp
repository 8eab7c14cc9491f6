// The position unit and the ranges every span is checked against.
#pragma once

#include <cstdint>

namespace pathstream {

/// Position in LSB, the smallest step the machine resolves (the machine profile says how many
/// millimetres one LSB is). Setpoints are whole LSB: the core rounds the exact curve once.
using Lsb = std::int32_t;

/// Control points (and Catmull-Rom/B-spline/Bezier points) must lie in [-kMaxPositionLsb,
/// +kMaxPositionLsb]: 2^27 LSB, i.e. +/-134 m at 1 um per LSB or +/-1.3 m at 10 nm.
inline constexpr std::int64_t kMaxPositionLsb = std::int64_t{1} << 27;

/// Hermite tangents (dp/du over the whole span, LSB; velocity in LSB/tick times the span's
/// tick count) must lie in [-kMaxTangentLsb, +kMaxTangentLsb].
inline constexpr std::int64_t kMaxTangentLsb = std::int64_t{1} << 29;

/// Bound on the curve itself anywhere inside a span. Catmull-Rom and Hermite may overshoot
/// their points; a span whose (conservative) hull reaches past this is rejected.
inline constexpr std::int64_t kMaxCurveLsb = std::int64_t{1} << 29;

/// Bound on each per-tick difference (velocity, acceleration, jerk in LSB per tick^k) inside a
/// span. Keeps every 32-bit quotient of the forward differencer and each sum of two of them
/// inside int32, so the per-tick loop cannot overflow.
inline constexpr std::int64_t kMaxDifferenceLsb = std::int64_t{1} << 30;

/// Longest span: 65,536 ticks (65.5 s at 1 kHz).
inline constexpr std::uint32_t kMaxSpanTicks = 65536;

}  // namespace pathstream
