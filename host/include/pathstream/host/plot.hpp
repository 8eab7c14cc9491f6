// Plots of an executed path (SVG, optional PNG) and the one-screen text report of a run.
//
// Everything here works on positions sampled once per tick (TickSeries), whatever executed
// them: the simulated device's setpoints and plant positions, or a real device's read-back.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "pathstream/host/geometry.hpp"
#include "pathstream/host/plan.hpp"
#include "pathstream/machine/machine.hpp"

namespace pathstream::host::plot {

/// Positions sampled once per tick: row k is tick k (time k / tick_hz).
struct TickSeries {
    std::string name;  ///< legend label: "setpoints", "servo plant"
    double tick_hz = 1000;
    std::size_t axes = 0;
    double quantum_mm = 0;               ///< resolution of the values (mm per LSB for setpoints;
                                         ///< 0: continuous); sizes the differencing window
    std::vector<double> position;        ///< mm, row-major: position[k * axes + axis]
    std::vector<std::uint8_t> pen_down;  ///< per tick: 1 while the pen is down

    std::size_t ticks() const { return axes == 0 ? 0 : position.size() / axes; }
    double at(std::size_t tick, std::size_t axis) const { return position[tick * axes + axis]; }
};

/// Velocities and accelerations of a TickSeries by central differences over +/-h ticks:
///   v(k) = (p[k+h] - p[k-h]) / (2 h T),   a(k) = (p[k+h] - 2 p[k] + p[k-h]) / (h T)^2.
/// Both are exact for a cubic in time (the core's spans) away from span joins; h > 1 divides
/// the setpoints' rounding noise (a: up to 2 quantum / (h T)^2) by h^2. Edges use the nearest
/// interior value (v: a one-sided difference).
struct Derivatives {
    unsigned half_window = 1;          ///< h, ticks
    double acceleration_noise = 0;     ///< mm/s^2: bound on a's rounding noise, 2 q / (h T)^2
    std::vector<double> velocity;      ///< mm/s, row-major like TickSeries::position
    std::vector<double> acceleration;  ///< mm/s^2, row-major
    std::vector<double> speed;         ///< mm/s, |v| over all axes, per tick
};

/// `half_window` 0 picks h automatically: the smallest h whose acceleration noise bound is at
/// most 5 % of the smallest axis acceleration limit (h = 1 for continuous series), at most 64.
Derivatives differentiate(const TickSeries& series, const MachineProfile& profile,
                          unsigned half_window = 0);

/// A plot point (data units).
struct Point {
    double x = 0;
    double y = 0;
};

/// Keeps a long series drawable: the samples of each of `columns` equal x-intervals of
/// [x_min, x_max] are reduced to their minimum and maximum, in their original order, so every
/// peak survives; the first and the last sample are always kept. Series of at most
/// 2 * columns samples come back whole. `x` must be ascending; NaN y samples are dropped.
std::vector<Point> decimate_min_max(const std::vector<double>& x, const std::vector<double>& y,
                                    double x_min, double x_max, std::size_t columns);

/// Plot settings.
struct Options {
    unsigned width_px = 960;         ///< SVG width; heights follow
    bool y_up = false;               ///< path.svg: false draws +y downwards, like SVG input and
                                     ///< most plotters' machine coordinates; true flips it
    unsigned half_window_ticks = 0;  ///< differencing half window (0: automatic)
    bool png = true;                 ///< also write PNG copies when rsvg-convert is found
    std::string title;               ///< shown on every plot (e.g. the input file name)
    /// The drawing's layers (Path::layers' names) and each subpath's layer (by
    /// BezierSegment::subpath): path.svg draws each layer's pen-down path in its own colour,
    /// the layer's own when its name is one ("#rrggbb"). Empty: one colour.
    std::vector<std::string> layers;
    std::vector<std::size_t> subpath_layers;
};

/// path.svg as text: the ideal path (Bezier segments sampled densely; pen-down solid, pen-up
/// travel dashed, grey and wide underneath; with layers, each layer's pen-down path in its
/// colour with a legend entry) and the executed positions of `executed` and, if
/// given, `plant` (pen-down solid, pen-up dashed), axes 0 and 1 at equal scale with mm ticks
/// and a legend above the plot. One axis: position against time instead.
/// Series are SVG groups with ids "ideal-path", "setpoints" (executed) and "plant".
std::string path_svg(const std::vector<BezierSegment>& path, const TickSeries& executed,
                     const TickSeries* plant, const MachineProfile& profile,
                     const Options& options);

/// speed.svg as text: path speed |v| of `executed` against time (group "speed"), the feed and
/// travel feed (lines "feed", "travel-feed") and each axis' velocity limit (group
/// "velocity-limits"); pen-up intervals shaded.
std::string speed_svg(const TickSeries& executed, const MachineProfile& profile,
                      const Options& options);

/// acceleration.svg as text: each axis' acceleration against time (groups
/// "acceleration-<axis name>") with its +/- limit (group "acceleration-limits").
std::string acceleration_svg(const TickSeries& executed, const MachineProfile& profile,
                             const Options& options);

/// What write_plots wrote.
struct WrittenPlots {
    std::vector<std::string> files;  ///< every file written, SVGs then PNGs
    bool png = false;                ///< PNG copies were written
    std::string note;                ///< why not, when options.png was set but no PNG came
};

/// Writes DIRECTORY/path.svg, speed.svg, acceleration.svg (each atomically: whole or absent)
/// and, when options.png and rsvg-convert is on PATH, a PNG of each. The directory must exist.
/// Throws std::runtime_error naming the file when a file cannot be written or rsvg-convert
/// fails; a missing rsvg-convert is not an error (see WrittenPlots::note).
WrittenPlots write_plots(const std::string& directory, const std::vector<BezierSegment>& path,
                         const TickSeries& executed, const TickSeries* plant,
                         const MachineProfile& profile, const Options& options);

/// Full path of the first executable rsvg-convert on PATH, if any.
std::optional<std::string> find_rsvg_convert();

/// Converts `svg_file` to `png_file` (white background) by running `rsvg` directly (fork and
/// exec, no shell: file names are passed verbatim). The PNG appears atomically. Throws
/// std::runtime_error with rsvg-convert's message on failure.
void svg_to_png(const std::string& rsvg, const std::string& svg_file, const std::string& png_file);

/// What the executing target measured, for the report.
struct RunSummary {
    std::string target = "simulated device";
    std::string plant = "ideal";  ///< plant description
    std::uint64_t ticks = 0;      ///< ticks run (the end point included)
    std::uint64_t spans = 0;      ///< spans pushed to the device
    std::uint64_t pen_switches = 0;
    std::uint64_t underruns = 0;   ///< idle ticks before the plan finished
    std::uint64_t late_ticks = 0;  ///< real-time pacing: ticks past their slot
    bool realtime = false;
    double simulated_seconds = 0;
    double wall_seconds = 0;
    std::vector<double> max_following_error_mm;  ///< per axis; empty: not measured (ideal)
    std::vector<double> rms_following_error_mm;  ///< per axis
};

/// One axis of the report's table: peaks against the limits three ways, following error.
struct AxisFigures {
    std::string name;
    bool checked = false;                ///< the planner check's figures (cubic, setpoints) are set
    double velocity_fraction_cubic = 0;  ///< exact cubic peak / max velocity
    double acceleration_fraction_cubic = 0;  ///< exact cubic peak / max acceleration
    std::int64_t max_step = 0;               ///< LSB/tick, integer setpoints
    double velocity_limit_lsb = 0;           ///< LSB/tick
    std::int64_t max_second_difference = 0;  ///< LSB/tick^2, integer setpoints
    double acceleration_limit_lsb = 0;       ///< LSB/tick^2
    double executed_velocity = 0;            ///< mm/s, peak of the executed series
    double executed_acceleration = 0;        ///< mm/s^2, peak of the executed series
    double max_velocity = 0;                 ///< mm/s, the profile's limit (0: none)
    double max_acceleration = 0;             ///< mm/s^2, the profile's limit (0: none)
    bool following = false;                  ///< following error measured (servo plant)
    double max_following_error_mm = 0;
    double rms_following_error_mm = 0;
    bool has_rms = false;  ///< rms_following_error_mm is set
};

/// Every figure of the one-screen report, before formatting (text_report prints these).
struct ReportFigures {
    double duration = 0;  ///< s, planned
    std::uint64_t pen_downs = 0, pen_ups = 0;
    std::uint64_t pen_down_ticks = 0;        ///< executed ticks with the pen down
    std::uint64_t executed_ticks = 0;        ///< ticks in the executed series
    std::uint64_t dwell_ticks = 0;           ///< ticks the plan holds still while the pen moves
    double velocity_fraction_cubic = 0;      ///< max over axes of the exact cubic's peak
    double acceleration_fraction_cubic = 0;  ///< max over axes of the exact cubic's peak
    unsigned executed_half_window = 1;       ///< ticks, the executed differences' h
    double executed_acceleration_noise = 0;  ///< mm/s^2, their rounding noise bound
    std::vector<AxisFigures> axes;
};

/// The figures the report shows, for text_report and machine-readable output alike.
ReportFigures report_figures(const Plan& plan, const PlanCheck* check,
                             const MachineProfile& profile, const TickSeries& executed,
                             const RunSummary& run);

/// The one-screen report: duration, pen-down length and travel, the planner's maximum
/// deviation (`check`, may be null: "not checked"), per axis the peak fraction of the velocity
/// and acceleration limits (planner and executed setpoints) and the following error, ticks,
/// spans, pen switches, underruns, simulated against wall time. Lines <= 80 columns.
std::string text_report(const Plan& plan, const PlanCheck* check, const MachineProfile& profile,
                        const TickSeries& executed, const RunSummary& run);

}  // namespace pathstream::host::plot
