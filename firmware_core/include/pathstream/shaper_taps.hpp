// An input shaper as the device runs it: a few taps, each a delay in whole ticks and a weight
// that is an exact fraction of kShaperWeightOne. The host designs the taps (ZV, ZVD, MZV, EI,
// ...); the device only checks them and sums.
#pragma once

#include <cstdint>

#include "pathstream/status.hpp"

namespace pathstream {

/// Weights are numerators over 2^kShaperWeightBits: a shaped setpoint is an integer sum shifted
/// once, and a weight's rounding is below 2^-17 of the motion (far below any mode's residual).
inline constexpr unsigned kShaperWeightBits = 16;
/// The denominator of every weight: the weights of one axis sum to exactly this.
inline constexpr std::uint32_t kShaperWeightOne = std::uint32_t{1} << kShaperWeightBits;
/// Most taps one axis may have: a 3-hump EI shaper's five impulses, each split over two ticks
/// where it falls between them, is nine.
inline constexpr std::uint32_t kMaxShaperTaps = 10;

/// One impulse of a shaper on the tick grid. Plain value.
struct ShaperTap {
    std::uint32_t delay = 0;   ///< ticks after the input: 0..history - 1
    std::uint32_t weight = 0;  ///< numerator over kShaperWeightOne: 1..kShaperWeightOne
};

/// kOk when `count` is 0 (no shaping) or 1..kMaxShaperTaps taps have strictly increasing
/// delays below `history_ticks`, every weight is at least 1, and the weights sum to exactly
/// kShaperWeightOne; kBadShaper otherwise. Positive weights summing to one are what make the
/// shaped motion a weighted average of delayed copies of the command, so it never moves
/// faster, accelerates harder or jerks more than the command, and never leaves the span of the
/// positions the command went through. Cost: a loop over the taps. Any context.
[[nodiscard]] Status check_shaper_taps(const ShaperTap* taps, std::uint32_t count,
                                       std::uint32_t history_ticks);

}  // namespace pathstream
