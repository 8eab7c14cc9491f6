// The machine's work area (the profile's per-axis "travel"): a path that leaves it is refused
// before anything is planned or sent, naming the subpath, the point and the file position; a
// plan is checked with the device's own proof, so a device never refuses a span mid-job.
#pragma once

#include <string>
#include <vector>

#include "pathstream/host/geometry.hpp"
#include "pathstream/host/path.hpp"
#include "pathstream/host/plan.hpp"
#include "pathstream/machine/machine.hpp"

namespace pathstream::host {

/// check_work_area for one segment (nothing for pen-up travel): for readers that visit the
/// segments one at a time (for_each_bezier_segment) and keep none.
void check_segment_work_area(const BezierSegment& segment, const Path& path,
                             const MachineProfile& profile, const std::string& file);

/// Throws InputError "FILE:LINE:COL: subpath K leaves the work area: ..." for the first
/// pen-down segment of `segments` whose curve (its exact extremes per axis, not its control
/// points) goes beyond an axis's travel by more than 1 nm. `path` gives the subpaths'
/// locations, `file` names the input. Axes without travel are not checked. Cost: one
/// quadratic per segment and axis.
void check_work_area(const std::vector<BezierSegment>& segments, const Path& path,
                     const MachineProfile& profile, const std::string& file);

/// check_plan_travel for one span (`index` counts from 0, for the message), as a streamed
/// plan comes out.
void check_span_travel(const CoreSpan& span, std::size_t index, const Path& path,
                       const MachineProfile& profile, const std::string& file);

/// Throws InputError naming the subpath when a planned span could leave an axis's travel by
/// the device's proof (device::check_axis_travel on the span's exact cubic): the spans follow
/// the path within the chord tolerance, so a path that runs along the very edge can be inside
/// while a span is not. Axes without travel are not checked.
void check_plan_travel(const Plan& plan, const Path& path, const MachineProfile& profile,
                       const std::string& file);

}  // namespace pathstream::host
