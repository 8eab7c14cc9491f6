// The core's span form as host and device code share it: one span, all axes, its control
// points in LSB, with the core's timing and exact cubic once validated.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "pathstream/basis.hpp"
#include "pathstream/span.hpp"
#include "pathstream/tick_cubic.hpp"
#include "pathstream/units.hpp"

namespace pathstream::host {

/// One span for the core, all axes, with where it came from.
struct CoreSpan {
    Basis basis = Basis::kUniformBSpline;
    std::uint32_t ticks = 1;
    std::vector<std::array<std::int32_t, 4>> control;  ///< per axis: P0..P3 (Hermite P0 P1 T0 T1)
    std::size_t subpath = 0;                           ///< index in Path::subpaths
    bool pen_down = true;                              ///< false for travel between subpaths
    /// The machine functions while it plays (kOutputMachineMask bits: spindle, coolant).
    std::uint8_t machine = 0;
    bool pause_after =
        false;          ///< a programmed pause follows: the device holds at its end (at rest)
    SpanTiming timing;  ///< the core's timing, once validated
    std::vector<TickCubic> cubic;  ///< the core's exact cubic per axis
};

/// The span's Span::outputs: the pen bit and its machine functions. O(1).
inline std::uint8_t span_outputs(const CoreSpan& span) {
    return static_cast<std::uint8_t>((span.pen_down ? kOutputPenDown : 0u) | span.machine);
}

/// The core's exact value of `span` on `axis` at tick k (0..ticks), via Horner. The span must
/// have been validated (uniform_core_spans does); throws std::logic_error otherwise.
Lsb core_value_at(const CoreSpan& span, std::size_t axis, std::uint32_t k);

}  // namespace pathstream::host
