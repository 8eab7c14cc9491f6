// What a simulated run looks like to the plots and the report: its setpoints and plant positions
// as plot series, its figures as a run summary. Here, above both the simulator (sim/) and the
// plots (host/), so that neither includes the other.
#pragma once

#include "pathstream/host/plot.hpp"
#include "pathstream/sim/device.hpp"

namespace pathstream::host {

/// The setpoints in mm as a plot series ("setpoints", quantum = mm_per_lsb).
plot::TickSeries setpoint_series(const sim::SimulationResult& result);
/// The plant positions as a plot series ("ideal plant" or "servo plant", continuous).
plot::TickSeries plant_series(const sim::SimulationResult& result);
/// The run's figures for plot::text_report.
plot::RunSummary run_summary(const sim::SimulationResult& result);

}  // namespace pathstream::host
