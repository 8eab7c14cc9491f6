#include "sim_command.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <thread>

#include "mode_option.hpp"
#include "pathstream/host/events.hpp"
#include "pathstream/host/job_estimate.hpp"
#include "pathstream/host/layers.hpp"
#include "pathstream/host/output_figures.hpp"
#include "pathstream/host/planner.hpp"
#include "pathstream/host/planning_thread.hpp"
#include "pathstream/host/plot.hpp"
#include "pathstream/host/progress.hpp"
#include "pathstream/host/segment_source.hpp"
#include "pathstream/host/work_area.hpp"
#include "pathstream/machine/exit_codes.hpp"
#include "pathstream/sim/device.hpp"
#include "plan_command.hpp"
#include "shaper_option.hpp"
#include "sim_plots.hpp"

namespace pathstream::host {

void add_sim_command(CLI::App& app, SimCommandOptions& o) {
    CLI::App* cmd = app.add_subcommand(
        "sim",
        "Plan the path and run it on the simulated plotter (the firmware core on a simulated HAL): "
        "plots and a one-screen report");
    add_path_options(*cmd, o.path);
    cmd->add_option("--machine,-m", o.machine, "machine profile (JSON, docs/formats.md)")
        ->required()
        ->check(CLI::ExistingFile);
    cmd->add_option("--plot", o.plot_dir,
                    "directory for path/speed/acceleration plots, and z with x, y, z axes (SVG, "
                    "and PNG with rsvg-convert)");
    cmd->add_flag("--realtime", o.realtime,
                  "pace the device at its real tick rate (default: as fast as possible)");
    cmd->add_option("--plant", o.plant,
                    "axis model: ideal (position = setpoint) or servo (2nd order)")
        ->capture_default_str()
        ->check(CLI::IsMember({"ideal", "servo"}));
    cmd->add_option("--bandwidth", o.bandwidth_hz, "servo bandwidth, Hz")
        ->capture_default_str()
        ->check(CLI::Range(0.1, 10000.0));
    cmd->add_option("--damping", o.damping, "servo damping ratio")
        ->capture_default_str()
        ->check(CLI::Range(0.05, 20.0));
    cmd->add_option("--mode", o.modes,
                    "a resonant mode of an axis, AXIS:FREQ_HZ:DAMPING (e.g. x:40:0.05; "
                    "repeatable, up to 4 an axis; replaces the profile's \"resonance\" for that "
                    "axis; servo plant only)")
        ->check(CLI::Validator(
            [](std::string& text) -> std::string {
                try {
                    parse_mode_option(text);
                } catch (const std::invalid_argument& e) {
                    return e.what();
                }
                return "";
            },
            "AXIS:FREQ_HZ:DAMPING"));
    cmd->add_option("--shaper", o.shapers,
                    "the device's input shaper on an axis, AXIS:TYPE:FREQ_HZ[:DAMPING] (e.g. "
                    "x:mzv:40; types zv, zvd, mzv, ei, 2hump_ei, 3hump_ei; damping 0.1 if not "
                    "given), AXIS:none, or none for every axis; repeatable, in order, over the "
                    "profile's \"input_shaper\" (docs/input-shaping.md)")
        ->check(CLI::Validator(
            [](std::string& text) -> std::string {
                try {
                    parse_shaper_option(text);
                } catch (const std::invalid_argument& e) {
                    return e.what();
                }
                return "";
            },
            "AXIS:TYPE:FREQ_HZ[:DAMPING]"));
    cmd->add_flag("--y-up", o.y_up,
                  "draw path.svg with +y upwards (default: downwards, like SVG and most "
                  "plotters; the 3-D view has z up)");
    cmd->add_flag("--json", o.json, "print the report as one JSON document on standard output");
    cmd->add_option(
        "--events", o.events,
        "write the run's events as NDJSON to this file (docs/events.md); -: standard output, the "
        "text report then goes to standard error");
    cmd->add_option("--events-rate", o.events_rate,
                    "progress events per second of simulated time, at most (with --events)")
        ->capture_default_str()
        ->check(CLI::Range(0.1, 1000.0));
    cmd->add_flag("--plan-first", o.plan_first,
                  "plan the whole job before running it and keep every tick for the report and "
                  "plots (default: plan as the device runs, memory bounded; docs/cli.md)");
    cmd->callback([&o] {
        if (o.plant == "ideal" && !o.modes.empty()) {
            throw CLI::ValidationError("--mode",
                                       "resonant modes need the servo plant: --plant ideal "
                                       "follows the setpoints exactly");
        }
        if (o.json && o.events == "-") {
            throw CLI::ValidationError("--events",
                                       "-: the standard output carries the --json document");
        }
    });
}

namespace {

using Json = nlohmann::ordered_json;

/// A fraction of a limit, or null when there is no limit to compare with.
Json fraction_of(double value, double limit) {
    return limit > 0 ? Json(value / limit) : Json(nullptr);
}

/// One axis of the report's table: cubic, setpoints and executed peaks, following error.
Json axis_json(const plot::AxisFigures& x) {
    Json j;
    j["velocity_fraction_cubic"] = x.checked ? Json(x.velocity_fraction_cubic) : Json(nullptr);
    j["max_step_lsb_per_tick"] = x.checked ? Json(x.max_step) : Json(nullptr);
    j["velocity_limit_lsb_per_tick"] = x.checked ? Json(x.velocity_limit_lsb) : Json(nullptr);
    j["velocity_fraction_executed"] = fraction_of(x.executed_velocity, x.max_velocity);
    j["executed_velocity_mm_per_s"] = x.executed_velocity;
    j["acceleration_fraction_cubic"] =
        x.checked ? Json(x.acceleration_fraction_cubic) : Json(nullptr);
    j["max_second_difference_lsb_per_tick2"] =
        x.checked ? Json(x.max_second_difference) : Json(nullptr);
    j["acceleration_limit_lsb_per_tick2"] =
        x.checked ? Json(x.acceleration_limit_lsb) : Json(nullptr);
    j["acceleration_fraction_executed"] = fraction_of(x.executed_acceleration, x.max_acceleration);
    j["executed_acceleration_mm_per_s2"] = x.executed_acceleration;
    // Not measured: the ideal plant's position is the setpoint, its error 0 (as the text says).
    j["max_following_error_mm"] = x.following ? x.max_following_error_mm : 0.0;
    j["rms_following_error_mm"] = x.has_rms ? x.rms_following_error_mm : 0.0;
    return j;
}

/// What the report of a run needs, whichever way it was planned and recorded.
struct SimRun {
    PlannedJob job;                ///< path, machine, the plan's totals (its spans: --plan-first)
    plot::PlanFigures plan;        ///< the plan's totals and dwells
    sim::SimulationResult result;  ///< the device's counters (every tick: --plan-first)
    plot::RunRecord record;        ///< the executed ticks' figures, and the plots' record
    /// The device's input shapers per axis and their taps, for the text and JSON reports.
    std::vector<std::optional<ShaperSpec>> shapers;
    std::vector<std::vector<ShaperTap>> shaper_taps;
};

/// The machine and plant lines of the report.
void machine_json(const SimCommandOptions& o, const SimRun& s, const plot::RunSummary& run,
                  Json& j) {
    const PlannedJob& job = s.job;
    j["target"] = run.target;
    j["file"] = path_display_name(o.path.file);
    j["machine"] = {{"file", o.machine},
                    {"axes", job.machine.axes.size()},
                    {"tick_hz", job.machine.tick_hz},
                    {"mm_per_lsb", job.machine.mm_per_lsb}};
    j["plant"] = {{"model", o.plant}, {"description", run.plant}};
    if (o.plant == "servo") {
        j["plant"]["bandwidth_hz"] = o.bandwidth_hz;
        j["plant"]["damping"] = o.damping;
        Json modes = Json::object();
        const auto& per_axis = s.result.modes;
        for (std::size_t a = 0; a < per_axis.size() && a < job.machine.axes.size(); ++a) {
            if (per_axis[a].empty()) continue;
            Json list = Json::array();
            for (const sim::ResonantMode& m : per_axis[a])
                list.push_back({{"frequency_hz", m.frequency_hz}, {"damping", m.damping}});
            modes[job.machine.axes[a].name] = list;
        }
        j["plant"]["modes"] = modes;
    }
    // The device's input shapers by axis name (docs/input-shaping.md); {} without one.
    Json shapers = Json::object();
    const auto& specs = s.shapers;
    const auto& taps = s.shaper_taps;
    for (std::size_t a = 0; a < specs.size() && a < job.machine.axes.size(); ++a) {
        if (!specs[a]) continue;
        shapers[job.machine.axes[a].name] = {
            {"type", shaper_type_name(specs[a]->type)},
            {"frequency_hz", specs[a]->frequency_hz},
            {"damping", specs[a]->damping},
            {"taps", taps[a].size()},
            {"duration_s", shaper_duration(taps[a], job.machine.tick_hz)}};
    }
    j["input_shaper"] = shapers;
    // What the shapers cut off corners: the shaped command's distance from the planned path.
    j["shaped_command_deviation_mm"] = s.result.shaped_command.max_mm;
}

/// A position by axis name.
Json position_json(const std::vector<double>& mm, const MachineProfile& profile) {
    Json j = Json::object();
    for (std::size_t a = 0; a < mm.size() && a < profile.axes.size(); ++a)
        j[profile.axes[a].name] = mm[a];
    return j;
}

/// Residual vibration and contour error: max, RMS and where (docs/simulator.md).
void motion_json(const plot::RunSummary& run, const MachineProfile& profile, Json& j) {
    const plot::ResidualFigures& v = run.residual;
    const auto where = [&](std::uint64_t tick) {
        return Json{{"tick", tick}, {"time_s", static_cast<double>(tick) / profile.tick_hz}};
    };
    Json residual = {
        {"max", v.max_mm}, {"rms", v.rms_mm}, {"stops", v.stops}, {"window_ticks", v.window_ticks}};
    if (v.stops > 0) {
        residual["where"] = where(v.max_tick);
        residual["where"]["tool_mm"] = position_json(v.tool_mm, profile);
        residual["where"]["rest_mm"] = position_json(v.rest_mm, profile);
    } else {
        residual["where"] = nullptr;
    }
    j["residual_vibration_mm"] = residual;
    const plot::ContourFigures& c = run.contour;
    Json contour = {{"max", c.max_mm},
                    {"rms", c.rms_mm},
                    {"back_ticks", c.back_ticks},
                    {"ahead_ticks", c.ahead_ticks},
                    {"where", where(c.max_tick)}};
    contour["where"]["tool_mm"] = position_json(c.tool_mm, profile);
    contour["where"]["path_mm"] = position_json(c.path_mm, profile);
    j["contour_error_mm"] = contour;
}

/// The duration, path, pen and device lines of the report.
void run_json(const SimRun& s, const plot::RunSummary& run, const plot::ReportFigures& f, Json& j) {
    const double tick_hz = s.job.machine.tick_hz;
    j["planned_duration_s"] = f.duration;
    j["simulated_duration_s"] = run.simulated_seconds;
    j["wall_time_s"] = run.wall_seconds;
    j["speedup"] =
        run.wall_seconds > 0 ? Json(run.simulated_seconds / run.wall_seconds) : Json(nullptr);
    j["realtime"] = run.realtime;
    j["drawn_length_mm"] = s.plan.path_length;
    j["travel_length_mm"] = s.plan.travel_length;
    j["pen_switches"] = run.pen_switches;
    j["pen"] = {{"downs", f.pen_downs},
                {"ups", f.pen_ups},
                {"down_time_s", static_cast<double>(f.pen_down_ticks) / tick_hz},
                {"down_fraction", f.executed_ticks > 0 ? static_cast<double>(f.pen_down_ticks) /
                                                             static_cast<double>(f.executed_ticks)
                                                       : 0.0},
                {"dwell_time_s", static_cast<double>(f.dwell_ticks) / tick_hz}};
    j["device"] = {{"ticks", run.ticks},
                   {"spans", run.spans},
                   {"underruns", run.underruns},
                   {"late_ticks", run.late_ticks}};
}

/// The deviation and limits lines, then the per-axis table keyed by axis name.
void limits_json(const PlannedJob& job, const plot::ReportFigures& f, Json& j) {
    const PlanCheck& c = job.check;
    j["max_deviation_mm"] = c.max_deviation;
    j["max_deviation_tick"] = c.worst_deviation_tick;
    j["chord_tolerance_mm"] = job.machine.chord_tolerance;
    j["within_limits"] = c.within_limits;
    j["velocity_fraction_cubic"] = f.velocity_fraction_cubic;
    j["acceleration_fraction_cubic"] = f.acceleration_fraction_cubic;
    j["velocity_fraction_setpoints"] = c.max_velocity_fraction;
    j["acceleration_fraction_setpoints"] = c.max_acceleration_fraction;
    // Jerk figures (docs/planner.md, section 7): fractions only with a max_jerk, else null.
    j["jerk_limited"] = c.jerk_limited;
    j["jerk_fraction_cubic"] = c.jerk_limited ? Json(c.max_jerk_fraction_exact) : Json(nullptr);
    j["join_acceleration_step_fraction"] =
        c.jerk_limited ? Json(c.max_join_acceleration_step_fraction) : Json(nullptr);
    Json jerk = Json::object();
    for (std::size_t a = 0; a < job.machine.axes.size() && a < c.axis_jerk.size(); ++a) {
        jerk[job.machine.axes[a].name] = {
            {"jerk_mm_per_s3", c.axis_jerk[a]},
            {"jerk_lsb_per_tick3", c.axis_jerk_lsb[a]},
            {"join_acceleration_step_mm_per_s2", c.axis_join_acceleration_step[a]}};
    }
    j["jerk_axes"] = jerk;
    j["executed_window_ticks"] = f.executed_half_window;
    j["executed_acceleration_noise_mm_per_s2"] = f.executed_acceleration_noise;
    Json axes = Json::object();
    for (const plot::AxisFigures& x : f.axes) axes[x.name] = axis_json(x);
    j["axes"] = axes;
}

/// The report for machines: every figure of the text report, unrounded, units in the keys.
Json report_json(const SimCommandOptions& o, const SimRun& s, const plot::RunSummary& run) {
    const plot::ReportFigures f =
        plot::report_figures(s.plan, &s.job.check, s.job.machine, s.record.figures, run);
    Json j;
    machine_json(o, s, run, j);
    run_json(s, run, f, j);
    limits_json(s.job, f, j);
    motion_json(run, s.job.machine, j);
    j["layers"] = layers_json(s.job.path);
    j["pauses"] = s.job.pause_count;
    const double tick_hz = s.job.machine.tick_hz;
    j["spindle_s"] = static_cast<double>(s.job.outputs.spindle_ticks) / tick_hz;
    j["spindle_starts"] = s.job.outputs.spindle_starts;
    j["coolant_s"] = static_cast<double>(s.job.outputs.coolant_ticks) / tick_hz;
    return j;
}

/// Writes the plots into o.plot_dir (created if needed): the ideal path from the job's segments
/// (--plan-first) or read from its path again.
plot::WrittenPlots write_sim_plots(const SimCommandOptions& o, const SimRun& s) {
    std::filesystem::create_directories(o.plot_dir);
    plot::Options plot_options;
    plot_options.y_up = o.y_up;
    plot_options.title = path_display_name(o.path.file);
    for (const PathLayer& l : s.job.path.layers) plot_options.layers.push_back(l.name);
    for (const Subpath& p : s.job.path.subpaths) plot_options.subpath_layers.push_back(p.layer);
    if (!s.job.segments.empty()) {
        VectorSegmentSource segments(s.job.segments);
        return plot::write_plots(o.plot_dir, segments, s.record, s.job.machine, plot_options);
    }
    PathSegmentSource segments(s.job.path);
    return plot::write_plots(o.plot_dir, segments, s.record, s.job.machine, plot_options);
}

/// Prints what write_sim_plots wrote, as the text report's last lines.
void print_plots(const plot::WrittenPlots& written) {
    std::cout << "plots:";
    for (const auto& f : written.files) std::cout << ' ' << f;
    std::cout << '\n';
    if (!written.note.empty()) std::cout << "note: " << written.note << '\n';
}

/// Subpaths of the drawing: its spans name them by index.
std::size_t count_subpaths(const Plan& plan) {
    std::size_t n = 0;
    for (const CoreSpan& s : plan.spans) n = std::max(n, s.subpath + 1);
    return n;
}

/// One simulated tick as the events see it: the device always runs, in simulated time. Its
/// counters say where the job is: spans completed, queued, and the ticks of the spans the
/// device took (what is queued ends there).
JobSample sim_sample(const sim::TickProbe& p, std::size_t axes, double tick_hz) {
    JobSample s;
    s.sim_seconds = static_cast<double>(p.tick + 1) / tick_hz;
    s.started = true;
    s.next_span = p.last_completed_tag;
    s.ticks = std::min(p.ticks_executed, p.ticks_pushed);
    s.queued_ticks = p.ticks_pushed > s.ticks ? p.ticks_pushed - s.ticks : 0;
    s.queued_spans = p.queued_spans;
    std::copy(p.setpoints, p.setpoints + axes, s.position);
    return s;
}

/// The device's options from the command line's and the profile's: the modes of both (the
/// ideal plant ignores the profile's), and with modes a settling time after the end point as
/// long as a stop's residual vibration window, so that the last stop is measured whole.
sim::SimOptions device_options(const SimCommandOptions& o, const MachineProfile& profile) {
    sim::SimOptions options;
    options.plant = o.plant == "ideal" ? sim::PlantModel::kIdeal : sim::PlantModel::kServo;
    options.servo.bandwidth_hz = o.bandwidth_hz;
    options.servo.damping = o.damping;
    options.realtime = o.realtime;
    if (options.plant == sim::PlantModel::kServo) options.modes = run_modes(o.modes, profile);
    options.shaper = shaper_taps(run_shapers(o.shapers, profile), profile);
    double lowest = 0;
    for (const auto& axis : options.modes)
        for (const sim::ResonantMode& m : axis)
            if (lowest == 0 || m.frequency_hz < lowest) lowest = m.frequency_hz;
    if (lowest > 0)
        options.settle_ticks =
            sim::residual_window_ticks(profile.tick_hz, std::min(lowest, o.bandwidth_hz)) +
            sim::servo_settle_ticks(profile.tick_hz, o.bandwidth_hz, o.damping);
    return options;
}

/// The report's modes line: the run's modes, or that the ideal plant ignores the profile's.
std::string modes_line(const SimCommandOptions& o, const MachineProfile& profile,
                       const sim::SimulationResult& result) {
    bool profile_modes = false;
    for (const auto& axis : profile.resonance) profile_modes = profile_modes || !axis.empty();
    if (o.plant == "ideal")
        return profile_modes ? "none: the ideal plant ignores the profile's resonance" : "";
    const std::string modes = describe_modes(result.modes, profile);
    return modes.empty() ? "" : modes + " (position = the tool's)";
}

/// --plan-first: the whole plan, then the device's run with every tick kept (the report and
/// plots from all of them).
SimRun run_plan_first(const SimCommandOptions& o, const EventChannel& channel,
                      std::optional<JobEvents>& events) {
    SimRun s;
    s.job = plan_job(o.path, o.machine);
    const PlannedJob& job = s.job;
    s.plan = plot::plan_figures(job.plan, job.machine);
    events.emplace(channel, job.plan, job.machine,
                   JobInfo{"sim", path_display_name(o.path.file), "sim", count_subpaths(job.plan)});
    sim::SimOptions options = device_options(o, job.machine);
    if (!o.events.empty()) {
        options.tick_observer = [&](const sim::TickProbe& p) {
            events->sample(sim_sample(p, job.machine.axes.size(), job.machine.tick_hz));
        };
    }
    ProgressBar bar(o.realtime ? "running (real time)" : "simulating");
    events->start(std::nullopt);
    try {
        s.result =
            sim::simulate(job.plan.spans, job.machine, options, [&](double f) { bar.update(f); });
    } catch (const std::exception& e) {
        events->end("failed", e.what());
        throw;
    }
    bar.finish();
    // The series take the run's ticks over: the run keeps its counters only.
    const plot::TickSeries executed = setpoint_series(s.result);
    std::vector<Lsb>().swap(s.result.setpoints);
    const bool servo = s.result.plant == sim::PlantModel::kServo;
    plot::TickSeries plant;
    if (servo && !o.plot_dir.empty()) {
        std::vector<double> positions = std::move(s.result.positions);
        s.result.positions.clear();
        plant = plant_series(s.result);
        plant.position = std::move(positions);
    }
    std::vector<double>().swap(s.result.positions);
    std::vector<std::uint8_t>().swap(s.result.pen);
    if (o.plot_dir.empty()) {
        s.record.figures = plot::executed_figures(executed, job.machine);
    } else {
        s.record = plot::record_of(executed, servo ? &plant : nullptr, job.machine);
    }
    return s;
}

/// The planning thread's look at the plan before the device gets it: the device's travel
/// check and the dwells. The per-tick check is plan_stream's own (check(): StreamCheck with its
/// own pass over the path for the deviation).
class SimPlanTap : public PlanSink {
public:
    SimPlanTap(const PlannedJob& job, const std::string& file)
        : job_(job), file_(file), checked_path_(job.path) {
        check_.path = &checked_path_;
    }
    void span(const CoreSpan& s) override {
        check_span_travel(s, spans_++, job_.path, job_.machine, file_);
        outputs_.add(s);
    }
    void pen(const PenEvent& e) override {
        dwell_ticks_ += delay_ticks(
            e.down ? job_.machine.pen_down_delay : job_.machine.pen_up_delay, job_.machine.tick_hz);
    }
    void pause(const PlanPause&) override {}
    /// For PlanningThread::Hooks::check; its result once planning finished.
    StreamCheck* stream_check() { return &check_; }
    const PlanCheck& check() const { return check_.result; }
    std::uint64_t dwell_ticks() const { return dwell_ticks_; }
    const OutputFigures& outputs() const { return outputs_; }

private:
    const PlannedJob& job_;
    const std::string& file_;
    PathSegmentSource checked_path_;  ///< the check's own pass over the path
    StreamCheck check_;
    std::size_t spans_ = 0;
    std::uint64_t dwell_ticks_ = 0;
    OutputFigures outputs_;
};

/// The default: the plan made on a planning thread as the device runs it (the device fed span
/// by span through the thread's bounded queue), every tick into a record of bounded size.
SimRun run_streamed(const SimCommandOptions& o, const EventChannel& channel,
                    std::optional<JobEvents>& events) {
    SimRun s;
    s.job = prepare_streamed_job(o.path, o.machine);
    PlannedJob& job = s.job;
    const std::size_t axes = job.machine.axes.size();
    events.emplace(channel, job.machine,
                   JobInfo{"sim", path_display_name(o.path.file), "sim", job.path.subpaths.size()});
    // Until planning ends, the events' fraction is the job's ticks estimated from its path.
    std::optional<JobEstimate> estimate;
    double taken_mm = 0;
    std::uint64_t taken_ticks = 0;
    if (!o.events.empty()) {
        PathSegmentSource path(job.path);
        estimate.emplace(path, job.machine);
        events->set_progress_basis(0, [&]() -> std::optional<std::uint64_t> {
            return estimate->total_ticks(taken_mm, taken_ticks);
        });
    }
    const bool servo = o.plant != "ideal";
    plot::RunRecorder recorder(job.machine, axes, job.machine.tick_hz, job.machine.mm_per_lsb,
                               servo, plot::RunRecorder::kDefaultCapacity, 0, !o.plot_dir.empty());
    sim::SimOptions options = device_options(o, job.machine);
    options.record_ticks = false;
    std::vector<double> setpoint_mm(axes);
    options.tick_observer = [&](const sim::TickProbe& p) {
        for (std::size_t a = 0; a < axes; ++a)
            setpoint_mm[a] = p.setpoints[a] * job.machine.mm_per_lsb;
        recorder.add(setpoint_mm.data(), p.positions, p.pen_down);
        if (!o.events.empty()) events->sample(sim_sample(p, axes, job.machine.tick_hz));
    };

    SimPlanTap tap(job, o.path.file);
    PathSegmentSource source(job.path);
    events->start(std::nullopt);
    try {
        PlanningThread planning(source, job.machine, PlanOptions{}, {&tap, {}, tap.stream_check()});
        sim::Simulator simulator(job.machine, options);
        ProgressBar bar(o.realtime ? "planning and running (real time)"
                                   : "planning and simulating");
        bool totals_known = false;
        const auto learn_totals = [&] {
            if (totals_known || !planning.finished()) return;
            if (const std::optional<PlanTotals> t = planning.totals()) {
                totals_known = true;
                events->set_totals(t->total_ticks, t->spans, t->pauses);
            }
        };
        CoreSpan span;
        for (std::size_t taken = 0;;) {
            const SpanSupply::Take take = planning.take(span);
            if (take == SpanSupply::Take::kEnd) break;
            if (take == SpanSupply::Take::kWait) {
                bar.update(planning.fraction());
                std::this_thread::sleep_for(std::chrono::microseconds(200));
                continue;
            }
            learn_totals();
            if (!o.events.empty()) {
                events->add_span(span);
                double chord = 0;
                for (const auto& axis : span.control) {
                    const double d = static_cast<double>(axis[1]) - static_cast<double>(axis[0]);
                    chord += d * d;
                }
                taken_mm += std::sqrt(chord) * job.machine.mm_per_lsb;
                taken_ticks += span.ticks;
            }
            simulator.push(span);
            if (++taken % 256 == 0) bar.update(planning.fraction());
        }
        learn_totals();
        s.result = simulator.finish();
        bar.update(1.0);
        bar.finish();
        const std::optional<PlanTotals> totals = planning.totals();
        if (!totals) throw PlanError("planning ended without its totals");
        job.planning_seconds = planning.planning_seconds();
        job.check = tap.check();
        job.plan.total_ticks = totals->total_ticks;
        job.plan.duration = totals->duration;
        job.plan.path_length = totals->path_length;
        job.plan.travel_length = totals->travel_length;
        job.span_count = totals->spans;
        job.pen_count = totals->pen_changes;
        job.pause_count = totals->pauses;
        job.outputs = tap.outputs();
    } catch (const std::exception& e) {
        events->end("failed", e.what());
        throw;
    }
    s.plan.duration = job.plan.duration;
    s.plan.total_ticks = job.plan.total_ticks;
    s.plan.path_length = job.plan.path_length;
    s.plan.travel_length = job.plan.travel_length;
    s.plan.dwell_ticks = tap.dwell_ticks();
    s.record = recorder.finish();
    s.record.executed_name = "setpoints";
    s.record.plant_name = servo ? "servo plant" : "ideal plant";
    return s;
}

/// job_end of the run: finished, or failed with the reason run_sim exits with.
void end_events(JobEvents& events, const sim::SimulationResult& result, bool failed) {
    const std::uint64_t ticks = result.stream.ticks_executed;
    if (result.underruns != 0) {
        events.end(
            "failed",
            "the device ran dry " + std::to_string(result.underruns) + " times (a streaming bug)",
            ticks);
    } else if (failed) {
        events.end("failed", "the plan failed its per-tick check (a planner bug)", ticks);
    } else {
        events.end("finished", "", ticks);
    }
}

}  // namespace

int run_sim(const SimCommandOptions& o) {
    EventChannel channel;
    channel.progress_hz = o.events_rate;
    if (!o.events.empty()) channel.writer = NdjsonWriter::open(o.events);
    std::optional<JobEvents> events;
    SimRun s = o.plan_first ? run_plan_first(o, channel, events) : run_streamed(o, channel, events);
    const PlannedJob& job = s.job;
    const sim::SimulationResult& result = s.result;
    plot::RunSummary run = run_summary(result);
    run.modes = modes_line(o, job.machine, result);
    s.shapers = run_shapers(o.shapers, job.machine);
    s.shaper_taps = shaper_taps(s.shapers, job.machine);
    run.shaper = describe_shapers(s.shapers, s.shaper_taps, job.machine);
    if (!run.shaper.empty()) {
        char deviation[160];
        std::snprintf(deviation, sizeof deviation,
                      "; the shaped command is up to %.1f um off the path (tolerance %.1f um%s)",
                      result.shaped_command.max_mm * 1000, job.machine.chord_tolerance * 1000,
                      job.machine.plan_for_shaper ? ", planned for it" : "");
        run.shaper += deviation;
    }
    if (!o.plot_dir.empty()) s.record.corner = corner_window(result, job.machine);
    const bool failed =
        result.underruns != 0 || !job.check.within_limits || job.check.drawing_while_pen_moves;
    end_events(*events, result, failed);
    const auto report = [&] {
        return plot::text_report(s.plan, &job.check, job.machine, s.record.figures, run);
    };
    // With --json, standard output holds the document or, on failure, nothing: the text
    // report the error message points to then goes to standard error.
    if (!o.json) {
        std::cout << report();
        if (const std::string layers = layers_text(job.path); !layers.empty())
            std::cout << "  " << layers << " (the operator's time is not in the durations)\n";
        if (job.outputs.any()) {
            char line[160];
            std::snprintf(line, sizeof line,
                          "  machine    spindle on %.3f s, %zu starts; coolant on %.3f s\n",
                          static_cast<double>(job.outputs.spindle_ticks) / job.machine.tick_hz,
                          job.outputs.spindle_starts,
                          static_cast<double>(job.outputs.coolant_ticks) / job.machine.tick_hz);
            std::cout << line;
        }
    }
    if (o.json && failed) std::cerr << report();
    Json document;
    if (o.json) document = report_json(o, s, run);
    if (!o.plot_dir.empty()) {
        const plot::WrittenPlots written = write_sim_plots(o, s);
        if (o.json) {
            document["plots"] = written.files;
            document["plot_note"] = written.note.empty() ? Json(nullptr) : Json(written.note);
        } else {
            print_plots(written);
        }
    }
    if (result.underruns != 0) {
        std::cerr << "pathstream: the device ran dry " << result.underruns
                  << " times (a streaming bug)\n";
        return kExitInternal;
    }
    if (failed) {
        // Name the rule the plan broke: the jerk limit is checked with the others.
        const PlanCheck& c = job.check;
        if (c.jerk_limited &&
            (c.max_jerk_fraction_exact > 1 || c.max_join_acceleration_step_fraction > 1)) {
            throw PlanError(
                "the plan exceeds the machine's max_jerk (a planner bug): see the report above");
        }
        throw PlanError("the plan failed its per-tick check (a planner bug): see the report above");
    }
    if (o.json) std::cout << document.dump(2) << '\n';
    return 0;
}

}  // namespace pathstream::host
