// Plays spans through the firmware core exactly as a device does, tick by tick.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "pathstream/host/core_spans.hpp"
#include "pathstream/units.hpp"

namespace pathstream::host {

/// One executed tick: its index, the span that supplied it, and the setpoint of every axis.
struct PlayedTick {
    std::uint64_t tick = 0;
    std::size_t span = 0;  ///< index into the span list
    std::uint32_t tick_in_span = 0;
    const Lsb* setpoint = nullptr;  ///< `axes` values, valid during the callback only
    bool pen_down = false;          ///< the core's outputs for this tick (kOutputPenDown)
};

/// Pushes `spans` into a SetpointStream (starting at the first span's tick-0 value) whenever
/// it has room and calls `on_tick` for every tick until the queue runs dry, then once more for
/// the end point (the last span's tick n, `tick_in_span == ticks`). Checks every setpoint
/// against the core's Horner value of its span. Throws std::runtime_error if the core refuses
/// a span (e.g. kDiscontinuousSpan) or the two evaluations ever disagree.
/// Returns the number of calls made. Cost: one core tick and one Horner evaluation per axis
/// per tick.
std::uint64_t play_through_core(const std::vector<CoreSpan>& spans, std::size_t axes,
                                const std::function<void(const PlayedTick&)>& on_tick);

}  // namespace pathstream::host
