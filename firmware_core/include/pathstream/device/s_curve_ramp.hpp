// The jerk-limited ramp of a device's own rest-to-rest move (AxisMove under a jerk limit):
// Hermite spans of n ticks whose acceleration is linear inside each span and continuous at
// every knot, rising from rest to the cruise tangent and, played backwards, falling to rest.
//
// Units: a knot's acceleration as A = a n^2 (a in LSB/tick^2: the second derivative per span^2),
// tangents per span (velocity * n). Every A is a multiple of 6, so that the tangents
// T(i+1) = T(i) + (A(i) + A(i+1)) / 2 and the chords T(i) + (2 A(i) + A(i+1)) / 6 are exact
// integers: the spans are exactly the designed cubics, with no rounding anywhere. The ramp ends
// on the cruise tangent C exactly because the interior knots' A sum to C.
#pragma once

#include <cstdint>

namespace pathstream::device {

/// Knots 0..spans of a ramp from rest (A = 0, T = 0) to tangent `cruise` with A = 0 again:
/// the interior knots rise by at most `step` from one knot to the next up to `peak`, stay there,
/// and fall back, with at most one extra knot inserted on each side (the remainder that makes
/// the interior sum exactly the cruise tangent). Plain value, no storage beyond these fields.
struct SCurveRamp {
    std::int64_t step = 6;        ///< largest change of A between knots (jerk * n^3), multiple of 6
    std::int64_t peak = 6;        ///< largest A (acceleration * n^2), multiple of 6
    std::int64_t levels = 0;      ///< rising knots min(j * step, peak), j = 1..levels (and falling)
    std::int64_t plateau = 0;     ///< knots at peak between the rising and the falling ones
    std::int64_t extra_up = 0;    ///< a knot inserted among the rising ones (0: none)
    std::int64_t extra_down = 0;  ///< a knot inserted among the falling ones (0: none)
    std::uint32_t spans = 0;      ///< spans of the ramp (knots 0..spans)

    /// `spans` saturates here.
    static constexpr std::int64_t kMaxSpans = 0x7fffffff;

    /// Sets the knots for `cruise` (a multiple of 6, 6 .. 2^50; step and peak set, multiples of
    /// 6, 6 <= step <= peak <= step * 2^20, so that no product here leaves 64 bits). Cost: a
    /// bisection over the levels. Any context.
    void plan(std::int64_t cruise) {
        // Rising knots up to peak: L of them, the last one peak itself.
        const std::int64_t to_peak = (peak + step - 1) / step;
        // Both ramps at full height: 2 (step (L - 1) L / 2 + peak).
        const std::int64_t full = step * (to_peak - 1) * to_peak + 2 * peak;
        extra_up = extra_down = plateau = 0;
        if (cruise >= full) {
            levels = to_peak;
            plateau = (cruise - full) / peak;
            extra_up = (cruise - full) % peak;  // below peak: it fits among the rising knots
        } else {
            // A triangle: the most levels k (below to_peak) with 2 step (1 + .. + k) <= cruise,
            // the rest r < 2 (k + 1) step split into two knots of at most (k + 1) step each.
            std::int64_t lo = 0, hi = to_peak - 1;
            while (lo < hi) {
                const std::int64_t mid = (lo + hi + 1) / 2;
                if (step * mid * (mid + 1) <= cruise) {
                    lo = mid;
                } else {
                    hi = mid - 1;
                }
            }
            levels = lo;
            const std::int64_t rest = cruise - step * lo * (lo + 1);
            extra_up = rest / 12 * 6;
            extra_down = rest - extra_up;
        }
        // Saturated: a plateau of 2^31 knots and more is no ramp anyone plays.
        const std::int64_t count =
            2 * levels + plateau + (extra_up != 0 ? 1 : 0) + (extra_down != 0 ? 1 : 0) + 1;
        spans = count < kMaxSpans ? static_cast<std::uint32_t>(count)
                                  : static_cast<std::uint32_t>(kMaxSpans);
    }

    /// A (acceleration * n^2) at knot i (0..spans; 0 at both ends). Cost: a few divisions.
    std::int64_t at(std::uint32_t i) const {
        if (i == 0 || i >= spans) return 0;
        std::int64_t k = static_cast<std::int64_t>(i) - 1;  // interior index
        const std::int64_t rising = levels + (extra_up != 0 ? 1 : 0);
        if (k < rising) {
            if (extra_up == 0) return level(k);
            // The extra knot sits after the rising knots below it.
            const std::int64_t below = below_count(extra_up);
            if (k < below) return level(k);
            if (k == below) return extra_up;
            return level(k - 1);
        }
        k -= rising;
        if (k < plateau) return peak;
        k -= plateau;
        // Falling: level(levels - 1 - j) for j = 0.., with extra_down after those above it.
        if (extra_down == 0) return level(levels - 1 - k);
        const std::int64_t above = levels - at_most_count(extra_down);
        if (k < above) return level(levels - 1 - k);
        if (k == above) return extra_down;
        return level(levels - k);
    }

private:
    // The j-th rising knot (0-based): min((j + 1) step, peak).
    std::int64_t level(std::int64_t j) const {
        const std::int64_t v = (j + 1) * step;
        return v < peak ? v : peak;
    }
    // Rising knots strictly below v.
    std::int64_t below_count(std::int64_t v) const {
        std::int64_t n = (v - 1) / step;
        if (n > levels) n = levels;
        while (n > 0 && level(n - 1) >= v) --n;
        return n;
    }
    // Rising knots at most v.
    std::int64_t at_most_count(std::int64_t v) const {
        std::int64_t n = v / step;
        if (n > levels) n = levels;
        while (n > 0 && level(n - 1) > v) --n;
        return n;
    }
};

}  // namespace pathstream::device
