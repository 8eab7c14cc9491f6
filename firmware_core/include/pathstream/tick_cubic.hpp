// A span's cubic on one axis as an exact integer polynomial in the tick index, and its
// correctly rounded Horner evaluation.
//
// With u = k/n and integer coefficients (a, b, c, d) = M * P:
//   p(k) = Q(k) / D,  Q(k) = a k^3 + b n k^2 + c n^2 k + d n^3,  D = scale * n^3.
// Q is an integer for every integer k, so rounding Q/D once gives the exact setpoint.
#pragma once

#include <cstdint>

#include "pathstream/basis.hpp"
#include "pathstream/status.hpp"
#include "pathstream/units.hpp"
#include "pathstream/wide_int.hpp"

namespace pathstream {

/// The timing shared by all axes of one span: its tick count and the common denominator.
struct SpanTiming {
    std::uint32_t ticks = 1;        ///< n, 1..kMaxSpanTicks
    std::uint64_t denominator = 1;  ///< D = scale * n^3 (< 2^51)
};

/// One axis's cubic in the tick domain. Plain value; build it with make_tick_cubic.
struct TickCubic {
    std::int64_t a = 0, b = 0, c = 0, d = 0;  ///< u-domain coefficients times the scale
};

/// Timing for a span of `ticks` ticks in basis `basis`.
/// Returns kTickCountOutOfRange unless 1 <= ticks <= kMaxSpanTicks, kUnknownBasis for an
/// invalid basis. Cost: a few multiplies. Any context.
[[nodiscard]] Status make_span_timing(Basis basis, std::uint32_t ticks, SpanTiming& out);

/// Converts four control values into the axis's tick cubic and proves that the curve stays
/// within kMaxCurveLsb for u in [0, 1], and that the forward differences Delta1(k) (velocity),
/// Delta2(k) (acceleration) and Delta3 (jerk) per tick stay within kMaxDifferenceLsb for every
/// k in 0..n. That is the whole state the differencer holds, up to and including the state at
/// tick n after the last step, so Delta1(n) and Delta2(n) reach one and two ticks past the
/// span's end: a one-tick span whose cubic swings hard just after u = 1 can be rejected
/// though its one real step is small. With today's input ranges the curve bound cannot be
/// exceeded (the hull stays below 2^28.3); it guards the proof should the ranges change.
/// On any error `out` is left untouched. Cost: a few dozen 128-bit operations. Task context.
[[nodiscard]] Status make_tick_cubic(Basis basis, const std::int32_t (&control)[4],
                                     const SpanTiming& timing, TickCubic& out);

/// Exact numerator Q(k) by Horner's rule in 128-bit arithmetic. k may be any value in
/// 0..ticks; the cubic must come from make_tick_cubic (which bounds every intermediate).
Int128 tick_numerator(const TickCubic& cubic, const SpanTiming& timing, std::uint32_t k);

/// The setpoint at tick k: round(Q(k) / D), halves rounded toward +infinity.
/// Returns kTickOutsideSpan for k > ticks (k == ticks gives the span's end point).
/// Cost: Horner plus one 128/64 division (~hundreds of instructions on Cortex-M). Any context.
[[nodiscard]] Status evaluate_at(const TickCubic& cubic, const SpanTiming& timing, std::uint32_t k,
                                 Lsb& out);

}  // namespace pathstream
