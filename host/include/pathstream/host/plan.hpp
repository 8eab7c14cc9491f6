// The planner's result: the spans the device executes, tick by tick, and how they were checked.
#pragma once

#include <cstdint>
#include <vector>

#include "pathstream/host/core_spans.hpp"
#include "pathstream/host/geometry.hpp"
#include "pathstream/machine/machine.hpp"

namespace pathstream::host {

/// The pen changes state at the start of `tick` (the device switches its output then).
struct PenEvent {
    std::uint64_t tick = 0;
    bool down = false;
};

/// A programmed pause (a pen change between layers, G-code M0): the device holds, pen up, at
/// the end of tick `tick - 1` until the operator resumes; subpath `subpath` is drawn next.
struct PlanPause {
    std::uint64_t tick = 0;
    std::size_t subpath = 0;
};

/// What `plan` produces and what every target executes: spans of whole ticks for the core.
struct Plan {
    std::vector<CoreSpan> spans;    ///< consecutive, continuous (each starts where the last ends)
    std::vector<PenEvent> pen;      ///< in tick order; the pen starts up
    std::vector<PlanPause> pauses;  ///< in tick order; the span ending at each has pause_after
    std::uint64_t total_ticks = 0;  ///< sum of span ticks
    double duration = 0;            ///< s = total_ticks / tick_hz
    double path_length = 0;         ///< mm, pen-down length of the geometric path
    double travel_length = 0;       ///< mm, pen-up travel
};

/// Per-tick check of a plan against the machine and the geometry (every tick executed).
struct PlanCheck {
    /// The integer setpoints after the rounding allowance, max over axes and ticks:
    /// (|first difference| - 1 LSB)+ / (v_max T) and (|second difference| - 2 LSB)+ / (a_max T^2).
    /// Coarse (the differences are whole LSB) and never above the exact fractions below, so
    /// reports show those and the raw differences (axis_max_step, axis_max_second_difference).
    double max_velocity_fraction = 0;
    double max_acceleration_fraction = 0;
    std::vector<double> axis_velocity_fraction;      ///< per axis, as above
    std::vector<double> axis_acceleration_fraction;  ///< per axis, as above
    double max_deviation = 0;  ///< mm, worst distance of a pen-down setpoint from the path
    std::uint64_t worst_deviation_tick = 0;
    /// Every fraction <= 1: the per-tick ones after the quantisation allowance, the exact
    /// ones and the span ones (what a device validating each span against the limits checks),
    /// and with a max_jerk the jerk and join acceleration step fractions.
    bool within_limits = false;
    bool drawing_while_pen_moves = false;  ///< true if any tick moves while the pen settles

    // The same fractions without the rounding allowance: `raw` from the integer setpoints,
    // `exact` from the core's exact cubic before its one rounding (docs/planner.md).
    double max_velocity_fraction_raw = 0;
    double max_acceleration_fraction_raw = 0;
    double max_velocity_fraction_exact = 0;
    double max_acceleration_fraction_exact = 0;
    /// Per span, the continuous cubic the core runs (before any rounding): peak |velocity| over
    /// the span and |acceleration| at both ends (it is linear, so they bound it) over the limits,
    /// max over spans and axes. A device that validates every span checks exactly these.
    double max_span_velocity_fraction = 0;
    double max_span_acceleration_fraction = 0;
    /// Per axis: the larger of the exact per-tick and the span fraction.
    std::vector<double> axis_velocity_fraction_exact;
    std::vector<double> axis_acceleration_fraction_exact;
    /// Per axis, the integer setpoints' largest |first difference| (LSB/tick) and |second
    /// difference| (LSB/tick^2) over the ticks examined, and the limits in the same units
    /// (v T / lsb, a T^2 / lsb). Rounding each setpoint once makes a step exceed the exact
    /// cubic's by less than 1 LSB/tick and a second difference by less than 2 LSB/tick^2.
    std::vector<std::int64_t> axis_max_step;
    std::vector<std::int64_t> axis_max_second_difference;
    std::vector<double> axis_velocity_limit_lsb;
    std::vector<double> axis_acceleration_limit_lsb;
    /// Max over moving ticks of the per-tick speed along the path over the requested feed
    /// (pen-down: the subpath's feed; pen-up: travel_feed), after an allowance of
    /// 2 sqrt(axes) LSB per tick for the rounding of setpoints and span end points.
    double max_feed_fraction = 0;
    std::uint64_t ticks_checked = 0;  ///< setpoints examined (the end point included)

    // Jerk, from the spans' exact cubics (docs/planner.md, section 7): the constant third
    // derivative inside each span, and the acceleration step at every join (the plan's start
    // and end, and both sides of a pause, join with rest). J = max_jerk T^3 / lsb LSB/tick^3;
    // a join may step by J * 1 tick. Always measured; part of within_limits only when the
    // profile sets a max_jerk (jerk_limited).
    bool jerk_limited = false;          ///< some axis has a max_jerk
    std::vector<double> axis_jerk_lsb;  ///< per axis, largest |jerk| in a span, LSB/tick^3
    std::vector<double> axis_jerk;      ///< the same in mm/s^3
    std::vector<double> axis_join_acceleration_step_lsb;  ///< largest |step| at a join, LSB/tick^2
    std::vector<double> axis_join_acceleration_step;      ///< the same in mm/s^2
    std::vector<double> axis_jerk_limit_lsb;              ///< J in LSB/tick^3 (0: no limit)
    /// Per axis, axis_jerk_lsb / J and axis_join_acceleration_step_lsb / (J * 1 tick); 0
    /// without a limit on that axis.
    std::vector<double> axis_jerk_fraction_exact;
    std::vector<double> axis_join_acceleration_step_fraction;
    double max_jerk_fraction_exact = 0;              ///< max over the axes
    double max_join_acceleration_step_fraction = 0;  ///< max over the axes
};

}  // namespace pathstream::host
