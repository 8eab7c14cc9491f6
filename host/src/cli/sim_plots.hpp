// What a simulated run looks like to the plots and the report: its setpoints and plant positions
// as plot series, its figures as a run summary. Here, above both the simulator (sim/) and the
// plots (host/), so that neither includes the other.
#pragma once

#include <optional>

#include "pathstream/host/plot.hpp"
#include "pathstream/sim/device.hpp"

namespace pathstream::host {

/// The setpoints in mm as a plot series ("setpoints", quantum = mm_per_lsb).
plot::TickSeries setpoint_series(const sim::SimulationResult& result);
/// The plant positions as a plot series ("ideal plant" or "servo plant", continuous).
plot::TickSeries plant_series(const sim::SimulationResult& result);
/// The run's figures for plot::text_report, residual vibration and contour error included.
plot::RunSummary run_summary(const sim::SimulationResult& result);
/// The path and the tool around the run's worst contour error, in the plane of the profile's
/// x and y (xyz_axes) or else of axes 0 and 1, for corner.svg; none with one axis or no error.
std::optional<plot::CornerWindow> corner_window(const sim::SimulationResult& result,
                                                const MachineProfile& profile);

}  // namespace pathstream::host
