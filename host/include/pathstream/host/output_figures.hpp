// What a plan does with the machine functions (spindle, coolant), counted span by span for
// the plan and sim summaries.
#pragma once

#include <cstddef>
#include <cstdint>

#include "pathstream/machine/core_span.hpp"
#include "pathstream/span.hpp"

namespace pathstream::host {

/// Ticks with the spindle and with any coolant on, and the spindle's starts (off to on, or a
/// reversal), over the spans added in plan order. Plain value; add() is O(1).
struct OutputFigures {
    std::uint64_t spindle_ticks = 0;
    std::uint64_t coolant_ticks = 0;
    std::size_t spindle_starts = 0;
    std::uint8_t last = 0;  ///< the machine functions of the last span added

    void add(const CoreSpan& s) {
        const bool on = (s.machine & kOutputSpindle) != 0;
        if (on &&
            ((last & kOutputSpindle) == 0 || ((s.machine ^ last) & kOutputSpindleReverse) != 0)) {
            ++spindle_starts;
        }
        if (on) spindle_ticks += s.ticks;
        if ((s.machine & (kOutputMist | kOutputFlood)) != 0) coolant_ticks += s.ticks;
        last = s.machine;
    }
    bool any() const { return spindle_ticks > 0 || coolant_ticks > 0; }
};

}  // namespace pathstream::host
