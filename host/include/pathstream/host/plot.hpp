// Plots of an executed path (SVG, optional PNG) and the one-screen text report of a run.
//
// Everything here works on positions sampled once per tick, whatever executed them: the
// simulated device's setpoints and plant positions, or a real device's read-back. Either held
// whole (TickSeries), or seen once each as they come (RunRecorder): then the report's figures
// are computed over every tick as it passes and the plots are drawn from a record of bounded
// size (RunRecord), so that memory does not grow with the run.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "pathstream/host/geometry.hpp"
#include "pathstream/host/isometric.hpp"
#include "pathstream/host/plan.hpp"
#include "pathstream/host/segment_source.hpp"
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

/// What the report needs of the executed ticks, over every one of them (exact: the same
/// numbers from a whole TickSeries and from a RunRecorder that saw its ticks one by one).
struct ExecutedFigures {
    std::size_t axes = 0;
    std::uint64_t ticks = 0;                   ///< ticks in the executed series
    std::uint64_t pen_down_ticks = 0;          ///< of them, with the pen down
    std::uint64_t pen_downs = 0, pen_ups = 0;  ///< pen edges between two ticks
    unsigned half_window = 1;                  ///< Derivatives::half_window
    double acceleration_noise = 0;             ///< Derivatives::acceleration_noise, mm/s^2
    std::vector<double> peak_velocity;         ///< mm/s per axis: largest |v| of Derivatives
    std::vector<double> peak_acceleration;     ///< mm/s^2 per axis: largest |a|
    double peak_speed = 0;                     ///< mm/s: largest Derivatives::speed
};

/// Adds the pen's lowerings, lifts and down ticks of `executed.pen_down` to `f`, and sets
/// f.ticks to its length. O(ticks).
void pen_figures(const TickSeries& executed, ExecutedFigures& f);

/// The figures of a whole series: pen edges and down ticks from its pen_down, the peaks of
/// differentiate(series, profile, half_window).
ExecutedFigures executed_figures(const TickSeries& series, const MachineProfile& profile,
                                 unsigned half_window = 0);

/// One kept point of an executed path (path.svg): axes 0 and 1 in mm, and the pen; in the
/// 3-D view (RunRecord::xyz) the axes named x, y and z.
struct TracePoint {
    double x = 0;
    double y = 0;
    double z = 0;  ///< 0 but in the 3-D view
    bool pen_down = false;
};

/// The path and the tool around a run's worst contour error, in the plane of two axes: what
/// corner.svg zooms into (docs/simulator.md, "Contour error").
struct CornerWindow {
    std::string x_name, y_name;  ///< the axes plotted
    std::vector<Point> path;     ///< the reference polyline (the planned setpoints), mm
    std::vector<Point> tool;     ///< the tool's position, one point per tick, mm
    Point worst_tool;            ///< the tool at the worst tick
    Point worst_path;            ///< the path's point nearest to it (over all axes)
    double error_mm = 0;         ///< the contour error there, over all axes
    double time_s = 0;           ///< when
};

/// A run as the plots need it, of bounded size: its figures, each series' path thinned to
/// at most 8 x `capacity` points at least a distance apart (that grows as needed; pen changes
/// kept), the speed and the accelerations as the minimum and maximum of each of up to
/// `capacity` stretches of time, and up to `capacity` pen-up intervals (ones closer than a gap
/// that grows as needed merged). With capacity 0 nothing is thinned: every tick is kept (what
/// the TickSeries functions draw).
struct RunRecord {
    ExecutedFigures figures;
    double tick_hz = 1000;
    std::size_t axes = 0;
    std::string executed_name = "setpoints";
    std::string plant_name;  ///< the plant series' name
    bool has_plant = false;
    /// The machine's x, y and z axes when it has them (xyz_axes): path.svg is then the
    /// isometric view, and write_plots adds z.svg.
    std::optional<XyzAxes> xyz;
    /// Axes >= 2: axes 0 and 1 of the executed series and of the plant (path.svg); with xyz,
    /// axes x, y and z.
    std::vector<TracePoint> executed_path, plant_path;
    /// Exact bounds over every tick of what the paths hold (finite points only):
    /// [series][0, 1 and, with xyz, 2 for z].
    double lo[2][3] = {}, hi[2][3] = {};
    bool bounded[2] = {false, false};  ///< the series had a finite point
    /// Times (s) and values, in time order, first and last tick included: the path speed,
    /// each axis's acceleration, and the positions ([0] executed, [1] plant) of axis 0 with
    /// one axis, of axis z with xyz.
    std::vector<Point> speed;
    std::vector<std::vector<Point>> acceleration;
    std::vector<Point> position[2];
    /// Pen-up intervals in ticks, [first, end), in order.
    std::vector<std::pair<std::uint64_t, std::uint64_t>> pen_up;
    bool thinned = false;  ///< something was thinned or merged
    /// Set by whoever knows the run's contour error (the simulator's caller): write_plots then
    /// writes corner.svg too.
    std::optional<CornerWindow> corner;
};

/// Builds a RunRecord from ticks seen once each, in order: memory O(capacity), whatever the
/// run's length (plus a window of 2 h + 1 ticks for the differences).
class RunRecorder {
public:
    /// `axes`, `tick_hz`, `quantum_mm`: the executed series' (as TickSeries). `plant`: a
    /// second series comes with every tick (add()'s `plant_mm`). `half_window`: as
    /// differentiate's. `capacity`: the record's size (0: every tick kept); `plots`: false
    /// keeps the figures only.
    RunRecorder(const MachineProfile& profile, std::size_t axes, double tick_hz, double quantum_mm,
                bool plant, std::size_t capacity = kDefaultCapacity, unsigned half_window = 0,
                bool plots = true);
    ~RunRecorder();
    RunRecorder(const RunRecorder&) = delete;
    RunRecorder& operator=(const RunRecorder&) = delete;

    /// The next tick: the executed positions (mm per axis), the plant's when the recorder has
    /// a plant (else ignored, may be null), and the pen.
    void add(const double* executed_mm, const double* plant_mm, bool pen_down);
    /// Room for `ticks` ticks when every tick is kept (capacity 0; else nothing).
    void reserve(std::uint64_t ticks);
    /// After the last tick. Call once.
    RunRecord finish();

    static constexpr std::size_t kDefaultCapacity = 8192;

private:
    struct State;
    std::unique_ptr<State> s_;
};

/// The record of whole series (every tick kept): what the TickSeries plot functions draw.
/// `plant` (optional) must have the ticks and axes of `executed`.
RunRecord record_of(const TickSeries& executed, const TickSeries* plant,
                    const MachineProfile& profile, unsigned half_window = 0,
                    std::size_t capacity = 0);

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

/// corner.svg as text: the window's path (group "path") and tool trace (group "tool") at equal
/// scale, zoomed to a square around the worst point at least 10 times the error across
/// (0.01 mm at least), the worst distance marked (group "worst"), a scale bar of one nice length
/// (1, 2 or 5 x 10^n mm, at most a quarter of the view: group "scale"). +y down unless
/// options.y_up.
std::string corner_svg(const CornerWindow& corner, const Options& options);

/// path.svg as text: the ideal path (Bezier segments sampled densely; pen-down solid, pen-up
/// travel dashed, grey and wide underneath; with layers, each layer's pen-down path in its
/// colour with a legend entry) and the executed positions of `executed` and, if
/// given, `plant` (pen-down solid, pen-up dashed), axes 0 and 1 at equal scale with mm ticks
/// and a legend above the plot. One axis: position against time instead; a machine with x, y
/// and z axes (xyz_axes): the isometric view (isometric_path_svg).
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

/// The same plots from a record (RunRecord), the ideal path read from `path` (rewound and read
/// twice: bounds, then drawing).
std::string path_svg(SegmentSource& path, const RunRecord& record, const MachineProfile& profile,
                     const Options& options);
std::string speed_svg(const RunRecord& record, const MachineProfile& profile,
                      const Options& options);
std::string acceleration_svg(const RunRecord& record, const MachineProfile& profile,
                             const Options& options);

/// path.svg of a record with xyz (what path_svg draws then): the ideal path and the executed
/// motion in 3-D, in the isometric view (isometric(): +x to the lower right, +y to the upper
/// right, +z up, a mm along any axis a mm on the plot), at equal scale. Pen-down (feed) moves
/// solid, pen-up travel (rapids) dashed; the box that holds the path and the motion in thin
/// grey; left of it arrows along +x, +y, +z named by the axes' names (group "axis-arrows"),
/// right of it an upright scale bar (group "scale"), both one nice length in mm (1, 2 or 5 x
/// 10^n, at most a quarter of the largest extent). Groups "ideal-path", "setpoints", "plant",
/// "bounding-box" too. Throws std::invalid_argument without xyz.
std::string isometric_path_svg(SegmentSource& path, const RunRecord& record,
                               const MachineProfile& profile, const Options& options);

/// z.svg of a record with xyz: z against time, the setpoints (what the device is commanded:
/// group "setpoints") and the plant's position (what it executed: group "plant"; without a
/// plant the setpoints are both, which the note says), pen-up (rapid) time shaded. Throws
/// std::invalid_argument without xyz.
std::string z_svg(const RunRecord& record, const MachineProfile& profile, const Options& options);

/// What write_plots wrote.
struct WrittenPlots {
    std::vector<std::string> files;  ///< every file written, SVGs then PNGs
    bool png = false;                ///< PNG copies were written
    std::string note;                ///< why not, when options.png was set but no PNG came
};

/// Writes DIRECTORY/path.svg, speed.svg, acceleration.svg (each atomically: whole or absent),
/// with the machine's x, y and z axes (xyz_axes) path.svg in 3-D and a fourth, z.svg, with
/// a record's corner window corner.svg last,
/// and, when options.png and rsvg-convert is on PATH, a PNG of each. The directory must exist.
/// Throws std::runtime_error naming the file when a file cannot be written or rsvg-convert
/// fails; a missing rsvg-convert is not an error (see WrittenPlots::note).
WrittenPlots write_plots(const std::string& directory, const std::vector<BezierSegment>& path,
                         const TickSeries& executed, const TickSeries* plant,
                         const MachineProfile& profile, const Options& options);

/// write_plots from a record, the ideal path read from `path`. With record.xyz, also z.svg
/// (and z.png).
WrittenPlots write_plots(const std::string& directory, SegmentSource& path, const RunRecord& record,
                         const MachineProfile& profile, const Options& options);

/// Full path of the first executable rsvg-convert on PATH, if any.
std::optional<std::string> find_rsvg_convert();

/// Converts `svg_file` to `png_file` (white background) by running `rsvg` directly (fork and
/// exec, no shell: file names are passed verbatim). The PNG appears atomically. Throws
/// std::runtime_error with rsvg-convert's message on failure.
void svg_to_png(const std::string& rsvg, const std::string& svg_file, const std::string& png_file);

/// Residual vibration of a run: the tool's largest distance from its rest position after
/// each stop of the command (docs/simulator.md, "Residual vibration").
struct ResidualFigures {
    std::uint64_t stops = 0;
    std::uint64_t window_ticks = 0;  ///< ticks of a stop looked at, at most
    double max_mm = 0;               ///< the largest stop's peak
    double rms_mm = 0;               ///< RMS over the stops' peaks
    std::uint64_t max_tick = 0;      ///< where: the tick, the tool and the rest position
    std::vector<double> tool_mm, rest_mm;
};

/// Contour error of a run: the tool's distance from the planned setpoints' polyline
/// (docs/simulator.md, "Contour error").
struct ContourFigures {
    double max_mm = 0;
    double rms_mm = 0;                              ///< over every tick
    std::uint64_t back_ticks = 0, ahead_ticks = 0;  ///< the window of setpoints compared with
    std::uint64_t max_tick = 0;                     ///< where: the tick, the tool, the path's point
    std::vector<double> tool_mm, path_mm;
};

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
    std::string modes;  ///< the report's modes line ("x: 40 Hz zeta 0.05 ..."); empty: none
    /// The report's shaper line ("x: mzv 40 Hz zeta 0.1, 5 taps over 19 ms ..."); empty: none.
    std::string shaper;
    /// Residual vibration and contour error (docs/simulator.md); not measured: not shown.
    bool motion_measured = false;
    ResidualFigures residual;
    ContourFigures contour;
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

/// What the report needs of the plan: a Plan's totals and dwells, or a streamed plan's.
struct PlanFigures {
    double duration = 0;  ///< s
    std::uint64_t total_ticks = 0;
    double path_length = 0;    ///< mm, pen-down
    double travel_length = 0;  ///< mm, pen-up
    std::uint64_t dwell_ticks = 0;
};

/// A plan's figures; dwell_ticks from its pen events.
PlanFigures plan_figures(const Plan& plan, const MachineProfile& profile);

/// The figures the report shows, for text_report and machine-readable output alike.
ReportFigures report_figures(const Plan& plan, const PlanCheck* check,
                             const MachineProfile& profile, const TickSeries& executed,
                             const RunSummary& run);
/// The same from the figures of a plan and of the executed ticks (a streamed run's).
ReportFigures report_figures(const PlanFigures& plan, const PlanCheck* check,
                             const MachineProfile& profile, const ExecutedFigures& executed,
                             const RunSummary& run);

/// The one-screen report: duration, pen-down length and travel, the planner's maximum
/// deviation (`check`, may be null: "not checked"), per axis the peak fraction of the velocity
/// and acceleration limits (planner and executed setpoints) and the following error, ticks,
/// spans, pen switches, underruns, simulated against wall time. Lines <= 80 columns.
std::string text_report(const Plan& plan, const PlanCheck* check, const MachineProfile& profile,
                        const TickSeries& executed, const RunSummary& run);
/// The same from the figures of a plan and of the executed ticks (a streamed run's).
std::string text_report(const PlanFigures& plan, const PlanCheck* check,
                        const MachineProfile& profile, const ExecutedFigures& executed,
                        const RunSummary& run);

}  // namespace pathstream::host::plot
