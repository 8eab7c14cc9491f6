// The plan's setpoints at the bus cycle: the firmware core (SetpointStream) ticked at the
// profile's tick rate, every C-th setpoint kept (C device ticks per bus cycle).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "pathstream/host/core_spans.hpp"

namespace pathstream::host::cia402 {

/// One setpoint per bus cycle, computed as the cycles go (memory independent of plan length).
class CycleSetpoints {
public:
    virtual ~CycleSetpoints() = default;
    /// Writes the next cycle's setpoint (one per axis) to `out`: the setpoints of ticks 0, C,
    /// 2C, ... below the plan's length, then the end point (tick total) once. Returns false
    /// when all were given. Throws std::runtime_error if the core refuses a span.
    virtual bool next(std::int32_t* out) = 0;
    /// Plan ticks covered so far (min(C x calls, total)).
    virtual std::uint64_t ticks() const = 0;
};

/// `spans` (validated core spans, all of `axes` axes) decimated by `ticks_per_cycle` >= 1.
std::unique_ptr<CycleSetpoints> make_cycle_setpoints(const std::vector<CoreSpan>& spans,
                                                     std::size_t axes,
                                                     std::uint32_t ticks_per_cycle);

}  // namespace pathstream::host::cia402
