#include "sim_command.hpp"

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>

#include "pathstream/host/events.hpp"
#include "pathstream/host/layers.hpp"
#include "pathstream/host/planner.hpp"
#include "pathstream/host/plot.hpp"
#include "pathstream/host/progress.hpp"
#include "pathstream/machine/exit_codes.hpp"
#include "pathstream/sim/device.hpp"
#include "plan_command.hpp"
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
                    "directory for path/speed/acceleration plots (SVG, and PNG with rsvg-convert)");
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
    cmd->add_flag("--y-up", o.y_up,
                  "draw path.svg with +y upwards (default: downwards, like SVG and most plotters)");
    cmd->add_flag("--json", o.json, "print the report as one JSON document on standard output");
    cmd->add_option(
        "--events", o.events,
        "write the run's events as NDJSON to this file (docs/events.md); -: standard output, the "
        "text report then goes to standard error");
    cmd->add_option("--events-rate", o.events_rate,
                    "progress events per second of simulated time, at most (with --events)")
        ->capture_default_str()
        ->check(CLI::Range(0.1, 1000.0));
    cmd->callback([&o] {
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

/// The machine and plant lines of the report.
void machine_json(const SimCommandOptions& o, const PlannedJob& job, const plot::RunSummary& run,
                  Json& j) {
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
    }
}

/// The duration, path, pen and device lines of the report.
void run_json(const PlannedJob& job, const plot::RunSummary& run, const plot::ReportFigures& f,
              Json& j) {
    const double tick_hz = job.machine.tick_hz;
    j["planned_duration_s"] = f.duration;
    j["simulated_duration_s"] = run.simulated_seconds;
    j["wall_time_s"] = run.wall_seconds;
    j["speedup"] =
        run.wall_seconds > 0 ? Json(run.simulated_seconds / run.wall_seconds) : Json(nullptr);
    j["realtime"] = run.realtime;
    j["drawn_length_mm"] = job.plan.path_length;
    j["travel_length_mm"] = job.plan.travel_length;
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
Json report_json(const SimCommandOptions& o, const PlannedJob& job,
                 const plot::TickSeries& executed, const plot::RunSummary& run) {
    const plot::ReportFigures f =
        plot::report_figures(job.plan, &job.check, job.machine, executed, run);
    Json j;
    machine_json(o, job, run, j);
    run_json(job, run, f, j);
    limits_json(job, f, j);
    j["layers"] = layers_json(job.path);
    j["pauses"] = job.plan.pauses.size();
    return j;
}

/// Writes the plots into o.plot_dir (created if needed).
plot::WrittenPlots write_sim_plots(const SimCommandOptions& o, const PlannedJob& job,
                                   const plot::TickSeries& executed,
                                   const plot::TickSeries* plant) {
    std::filesystem::create_directories(o.plot_dir);
    plot::Options plot_options;
    plot_options.y_up = o.y_up;
    plot_options.title = path_display_name(o.path.file);
    for (const PathLayer& l : job.path.layers) plot_options.layers.push_back(l.name);
    for (const Subpath& s : job.path.subpaths) plot_options.subpath_layers.push_back(s.layer);
    return plot::write_plots(o.plot_dir, job.segments, executed, plant, job.machine, plot_options);
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

/// One simulated tick as the events see it: the device always runs, in simulated time.
/// `prefix`: ticks before each span of the plan (size spans + 1).
JobSample sim_sample(const sim::TickProbe& p, const PlannedJob& job,
                     const std::vector<std::uint64_t>& prefix) {
    const std::size_t spans = job.plan.spans.size();
    JobSample s;
    s.sim_seconds = static_cast<double>(p.tick + 1) / job.machine.tick_hz;
    s.started = true;
    s.next_span = std::min<std::size_t>(p.last_completed_tag, spans);
    s.ticks = std::min(p.ticks_executed, job.plan.total_ticks);
    const std::uint64_t queued_end =
        prefix[std::min<std::size_t>(s.next_span + p.queued_spans, spans)];
    s.queued_ticks = queued_end > s.ticks ? queued_end - s.ticks : 0;
    s.queued_spans = p.queued_spans;
    std::copy(p.setpoints, p.setpoints + job.machine.axes.size(), s.position);
    return s;
}

/// Runs the plan on the simulated device, with a progress bar on standard error and, with
/// --events, the run's events from every tick.
sim::SimulationResult simulate_job(const SimCommandOptions& o, const PlannedJob& job,
                                   JobEvents& events) {
    sim::SimOptions options;
    options.plant = o.plant == "ideal" ? sim::PlantModel::kIdeal : sim::PlantModel::kServo;
    options.servo.bandwidth_hz = o.bandwidth_hz;
    options.servo.damping = o.damping;
    options.realtime = o.realtime;
    std::vector<std::uint64_t> prefix;
    if (!o.events.empty()) {
        prefix.reserve(job.plan.spans.size() + 1);
        prefix.push_back(0);
        for (const CoreSpan& s : job.plan.spans) prefix.push_back(prefix.back() + s.ticks);
        options.tick_observer = [&](const sim::TickProbe& p) {
            events.sample(sim_sample(p, job, prefix));
        };
    }
    ProgressBar bar(o.realtime ? "running (real time)" : "simulating");
    events.start(std::nullopt);
    try {
        return sim::simulate(job.plan.spans, job.machine, options,
                             [&](double f) { bar.update(f); });
    } catch (const std::exception& e) {
        events.end("failed", e.what());
        throw;
    }
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
    const PlannedJob job = plan_job(o.path, o.machine);
    JobEvents events(channel, job.plan, job.machine,
                     {"sim", path_display_name(o.path.file), "sim", count_subpaths(job.plan)});
    const sim::SimulationResult result = simulate_job(o, job, events);
    const plot::TickSeries executed = setpoint_series(result);
    const plot::TickSeries plant = plant_series(result);
    const plot::RunSummary run = run_summary(result);
    const bool servo = result.plant == sim::PlantModel::kServo;
    const bool failed =
        result.underruns != 0 || !job.check.within_limits || job.check.drawing_while_pen_moves;
    end_events(events, result, failed);
    // With --json, standard output holds the document or, on failure, nothing: the text
    // report the error message points to then goes to standard error.
    if (!o.json) {
        std::cout << plot::text_report(job.plan, &job.check, job.machine, executed, run);
        if (const std::string layers = layers_text(job.path); !layers.empty())
            std::cout << "  " << layers << " (the operator's time is not in the durations)\n";
    }
    if (o.json && failed)
        std::cerr << plot::text_report(job.plan, &job.check, job.machine, executed, run);
    Json document;
    if (o.json) document = report_json(o, job, executed, run);
    if (!o.plot_dir.empty()) {
        const plot::WrittenPlots written =
            write_sim_plots(o, job, executed, servo ? &plant : nullptr);
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
