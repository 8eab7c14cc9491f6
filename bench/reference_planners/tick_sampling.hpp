// What a reference planner's profile does at the device's tick: its trapezoids sampled every
// 1 / tick_hz seconds, per axis, against the axis limits (exact positions, no LSB rounding,
// as pathstream's exact check of its own cubics).
#pragma once

#include <cstdint>
#include <vector>

#include "line_moves.hpp"

namespace pathstream::bench {

/// Largest per-tick figures of a sampled profile, over all axes and ticks.
struct TickFigures {
    std::uint64_t ticks = 0;  ///< samples taken after the start (the last one at rest)
    /// Largest change of an axis's per-tick velocity from one tick to the next, mm/s
    /// (|p[k+1] - 2 p[k] + p[k-1]| / T), and the limit's own per-tick step a_i T.
    double max_velocity_step = 0;
    double velocity_step_limit = 0;  ///< a_i T of the axis where max_velocity_step was found
    /// The same as a fraction of the axis's acceleration limit (|second difference| / (a_i T^2)).
    double max_acceleration_fraction = 0;
    /// Largest |first difference| / (v_i T): the per-tick velocity over the axis limit.
    double max_velocity_fraction = 0;
    double worst_time = 0;  ///< s, where max_acceleration_fraction was found
    /// Where the sampled motion ended (mm per axis) and how far it is from the last move's end.
    double end_error = 0;
};

/// Samples `plan` at t = k / tick_hz (k = 0 .. ceil(motion time * tick_hz)), the machine
/// holding the last position after the end. O(ticks + moves).
TickFigures sample_at_ticks(const PeerPlan& plan, const host::MachineProfile& profile);

}  // namespace pathstream::bench
