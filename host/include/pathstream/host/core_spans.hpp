// Turns a geometric path into the core's spans: coordinates quantised to LSB, open ends
// clamped, subpaths joined by straight pen-up travel, every span validated by the core.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "pathstream/basis.hpp"
#include "pathstream/host/path.hpp"
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
    bool pause_after = false;  ///< a programmed pause follows: the device holds at its end (at rest)
    SpanTiming timing;                                 ///< the core's timing, once validated
    std::vector<TickCubic> cubic;                      ///< the core's exact cubic per axis
};

/// Spans of `path` at a uniform `ticks_per_span`, quantised at `mm_per_lsb`.
/// Throws InputError naming `file` and the subpath when a point or a span is outside what the
/// core accepts (the core's own validation decides, with its status text).
std::vector<CoreSpan> uniform_core_spans(const Path& path, const std::string& file,
                                         double mm_per_lsb, std::uint32_t ticks_per_span);

/// The core's exact value of `span` on `axis` at tick k (0..ticks), via Horner. The span must
/// come from uniform_core_spans (which validated it); throws std::logic_error otherwise.
Lsb core_value_at(const CoreSpan& span, std::size_t axis, std::uint32_t k);

}  // namespace pathstream::host
