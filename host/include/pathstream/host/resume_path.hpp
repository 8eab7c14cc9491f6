// The way back onto the drawing after an interrupted job: the spans a resume streams to a
// device that rests off the path (after a stop, a fault reset, a device restart or a host
// crash). Apart from the journal's files, which only record where the job stands.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "pathstream/host/job_journal.hpp"
#include "pathstream/machine/device_setup.hpp"
#include "pathstream/units.hpp"

namespace pathstream::host {

/// The job's spans from span `first` on (the first one not executed to its end), entered from
/// rest at `rest`: a re-entry span (the core's plan_reentry, pen up) that arrives at span
/// `first`'s start with its start velocity, and, when that span draws and `limits` has a
/// pen-down delay, a straight approach along its start tangent lasting at least that delay,
/// with the pen down, so the pen touches where the span starts. Under a jerk limit (any
/// `limits.max_jerk`) the acceleration stays continuous within one tick of jerk as well: the
/// re-entry is plan_jerk_reentry's three or four spans, and the approach a span of at least
/// the delay that ends with the span's start velocity and acceleration and starts with about
/// none (a ramp, slightly curved where that acceleration is not along the tangent). Re-entry
/// spans of `job` itself are skipped. Every span before span `first` carries its machine
/// functions (spindle, coolant); when its spindle runs, still spans at `rest` lasting
/// `spin_up_ticks` (the profile's spindle spin-up) come first, so the tool meets the work at
/// speed. Throws std::invalid_argument when `first` is past the end and std::range_error when
/// no re-entry fits the limits.
JobSpans resume_from(const JobSpans& job, std::size_t first, const std::vector<Lsb>& rest,
                     const DeviceLimitsLsb& limits, std::uint64_t spin_up_ticks = 0);

}  // namespace pathstream::host
