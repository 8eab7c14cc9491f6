#include "plan_command.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "pathstream/host/core_playback.hpp"
#include "pathstream/host/job_estimate.hpp"
#include "pathstream/host/layers.hpp"
#include "pathstream/host/planner.hpp"
#include "pathstream/host/progress.hpp"
#include "pathstream/host/segment_source.hpp"
#include "pathstream/host/work_area.hpp"
#include "pathstream/machine/atomic_file.hpp"
#include "pathstream/machine/input_error.hpp"
#include "pathstream/sim/device.hpp"
#include "shaper_option.hpp"

namespace pathstream::host {

void add_plan_command(CLI::App& app, PlanCommandOptions& o) {
    CLI::App* cmd = app.add_subcommand("plan",
                                       "Plan the path for a machine (near time-optimal under its "
                                       "limits) and write the executed setpoints as "
                                       "CSV tick,t,x,y,...,pen in mm");
    add_path_options(*cmd, o.path);
    cmd->add_option("--machine,-m", o.machine, "machine profile (JSON, docs/formats.md)")
        ->required()
        ->check(CLI::ExistingFile);
    cmd->add_option("--out,-o", o.output,
                    "CSV output file, - for standard output (the summary then goes to standard "
                    "error; default: only the summary)");
    cmd->add_flag("--json", o.json, "print the summary as one JSON document on standard output");
    cmd->add_flag(
        "--preview", o.preview,
        "print planning progress as JSON lines, then the preview document of `pathstream serve` "
        "(the path simplified, speed bins, figures) as one JSON line");
    cmd->add_option("--max-motion", o.max_motion,
                    "s: refuse, before planning, a job estimated to move for longer (0: no limit)")
        ->capture_default_str()
        ->check(CLI::NonNegativeNumber);
}

std::string lsb_to_mm_text(Lsb value, double mm_per_lsb) {
    double lsb_per_mm = 1.0 / mm_per_lsb;
    if (std::fabs(lsb_per_mm - std::round(lsb_per_mm)) < 1e-9 * lsb_per_mm)
        lsb_per_mm = std::round(lsb_per_mm);
    return exact_decimal(value / lsb_per_mm);
}

void print_plan_summary(const PlannedJob& job, std::ostream& out) {
    const PlanCheck& c = job.check;
    char line[256];
    std::snprintf(line, sizeof line,
                  "  motion: %.3f s (%llu ticks at %g Hz), %zu spans, %zu pen lifts and lowers\n",
                  job.plan.duration, static_cast<unsigned long long>(job.plan.total_ticks),
                  job.machine.tick_hz, job.span_count, job.pen_count);
    out << line;
    if (const std::string layers = layers_text(job.path); !layers.empty())
        out << "  " << layers << '\n';
    std::snprintf(line, sizeof line, "  path: %.3f mm drawn, %.3f mm travel; planned in %.3f s\n",
                  job.plan.path_length, job.plan.travel_length, job.planning_seconds);
    out << line;
    if (job.outputs.any()) {
        std::snprintf(line, sizeof line,
                      "  spindle: on %.3f s, %zu starts (spin-up %g s); coolant on %.3f s\n",
                      static_cast<double>(job.outputs.spindle_ticks) / job.machine.tick_hz,
                      job.outputs.spindle_starts, job.machine.spindle.spin_up,
                      static_cast<double>(job.outputs.coolant_ticks) / job.machine.tick_hz);
        out << line;
    }
    std::snprintf(line, sizeof line,
                  "  max deviation from the path: %.2f um (tolerance %.2f um) at tick %llu\n",
                  c.max_deviation * 1000, job.machine.chord_tolerance * 1000,
                  static_cast<unsigned long long>(c.worst_deviation_tick));
    out << line;
    // The exact cubic's peaks (what a device checks) and the integer setpoints' largest
    // differences next to the limits in the same unit (rounding adds < 1 and < 2 LSB).
    for (std::size_t a = 0; a < job.machine.axes.size(); ++a) {
        std::snprintf(
            line, sizeof line,
            "  axis %s: exact cubic peak %.2f %% of max velocity, %.2f %% of max acceleration; "
            "setpoints %lld of %.4g LSB/tick, %lld of %.4g LSB/tick^2\n",
            job.machine.axes[a].name.c_str(), 100 * c.axis_velocity_fraction_exact.at(a),
            100 * c.axis_acceleration_fraction_exact.at(a),
            static_cast<long long>(c.axis_max_step.at(a)), c.axis_velocity_limit_lsb.at(a),
            static_cast<long long>(c.axis_max_second_difference.at(a)),
            c.axis_acceleration_limit_lsb.at(a));
        out << line;
        // Jerk: the spans' constant jerk and the largest acceleration step at a join, against
        // J and one tick of J when the profile sets max_jerk.
        if (c.axis_jerk_limit_lsb.at(a) > 0) {
            std::snprintf(line, sizeof line,
                          "  axis %s: exact cubic jerk %.2f %% of max jerk (%.4g mm/s^3), join "
                          "acceleration step "
                          "%.2f %% of one tick of it\n",
                          job.machine.axes[a].name.c_str(), 100 * c.axis_jerk_fraction_exact.at(a),
                          c.axis_jerk.at(a), 100 * c.axis_join_acceleration_step_fraction.at(a));
        } else {
            std::snprintf(
                line, sizeof line,
                "  axis %s: exact cubic jerk %.4g mm/s^3 (%.4g LSB/tick^3), join acceleration step "
                "%.4g mm/s^2 (no max_jerk)\n",
                job.machine.axes[a].name.c_str(), c.axis_jerk.at(a), c.axis_jerk_lsb.at(a),
                c.axis_join_acceleration_step.at(a));
        }
        out << line;
    }
    std::snprintf(line, sizeof line, "  every tick checked (%llu): %s%s\n",
                  static_cast<unsigned long long>(c.ticks_checked),
                  c.within_limits ? "within limits" : "LIMITS EXCEEDED",
                  c.drawing_while_pen_moves ? "; MOTION WHILE THE PEN MOVES"
                                            : "; no motion while the pen moves");
    out << line;
}

namespace {

/// Per axis, keyed by name: the plan check's limit figures, as the summary prints them.
nlohmann::ordered_json plan_axes_json(const PlannedJob& job) {
    const PlanCheck& c = job.check;
    nlohmann::ordered_json axes = nlohmann::ordered_json::object();
    for (std::size_t a = 0; a < job.machine.axes.size(); ++a) {
        axes[job.machine.axes[a].name] = {
            {"velocity_fraction_cubic", c.axis_velocity_fraction_exact.at(a)},
            {"acceleration_fraction_cubic", c.axis_acceleration_fraction_exact.at(a)},
            {"max_step_lsb_per_tick", c.axis_max_step.at(a)},
            {"velocity_limit_lsb_per_tick", c.axis_velocity_limit_lsb.at(a)},
            {"max_second_difference_lsb_per_tick2", c.axis_max_second_difference.at(a)},
            {"acceleration_limit_lsb_per_tick2", c.axis_acceleration_limit_lsb.at(a)},
            {"jerk_lsb_per_tick3", c.axis_jerk_lsb.at(a)},
            {"jerk_mm_per_s3", c.axis_jerk.at(a)},
            {"join_acceleration_step_lsb_per_tick2", c.axis_join_acceleration_step_lsb.at(a)},
            {"join_acceleration_step_mm_per_s2", c.axis_join_acceleration_step.at(a)}};
        // Only with a max_jerk: the limit and the fractions of it.
        if (c.axis_jerk_limit_lsb.at(a) > 0) {
            auto& x = axes[job.machine.axes[a].name];
            x["jerk_limit_lsb_per_tick3"] = c.axis_jerk_limit_lsb.at(a);
            x["jerk_fraction_cubic"] = c.axis_jerk_fraction_exact.at(a);
            x["join_acceleration_step_fraction"] = c.axis_join_acceleration_step_fraction.at(a);
        }
    }
    return axes;
}

/// The summary's figures for machines: the same numbers, unrounded, in the units the keys name.
nlohmann::ordered_json plan_summary_json(const PlanCommandOptions& o, const PlannedJob& job) {
    const PlanCheck& c = job.check;
    nlohmann::ordered_json j;
    j["file"] = path_display_name(o.path.file);
    j["machine"] = o.machine;
    j["output"] =
        o.output.empty() ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(o.output);
    j["duration_s"] = job.plan.duration;
    j["ticks"] = job.plan.total_ticks;
    j["tick_hz"] = job.machine.tick_hz;
    j["spans"] = job.span_count;
    j["pen_changes"] = job.pen_count;
    j["pauses"] = job.pause_count;
    j["spindle_s"] = static_cast<double>(job.outputs.spindle_ticks) / job.machine.tick_hz;
    j["spindle_starts"] = job.outputs.spindle_starts;
    j["coolant_s"] = static_cast<double>(job.outputs.coolant_ticks) / job.machine.tick_hz;
    j["layers"] = layers_json(job.path);
    j["drawn_length_mm"] = job.plan.path_length;
    j["travel_length_mm"] = job.plan.travel_length;
    j["planning_time_s"] = job.planning_seconds;
    j["max_deviation_mm"] = c.max_deviation;
    j["max_deviation_tick"] = c.worst_deviation_tick;
    j["chord_tolerance_mm"] = job.machine.chord_tolerance;
    j["axes"] = plan_axes_json(job);
    j["ticks_checked"] = c.ticks_checked;
    j["within_limits"] = c.within_limits;
    j["motion_while_pen_moves"] = c.drawing_while_pen_moves;
    return j;
}

/// The CSV header: tick, time, one column per axis, pen.
void write_plan_header(std::size_t axes, std::ostream& csv) {
    csv << "tick,t";
    for (std::size_t a = 0; a < axes; ++a) csv << ',' << axis_column_name(a);
    csv << ",pen\n";
}

/// One executed tick as a CSV row.
void write_plan_row(const PlannedJob& job, std::uint64_t tick, const std::int64_t* setpoint,
                    bool pen_down, std::ostream& csv) {
    csv << tick << ',' << exact_decimal(static_cast<double>(tick) / job.machine.tick_hz);
    for (std::size_t a = 0; a < job.path.axes; ++a)
        csv << ',' << lsb_to_mm_text(setpoint[a], job.machine.mm_per_lsb);
    csv << ',' << (pen_down ? 1 : 0) << '\n';
}

/// The plan as it is made, span by span, through the device's travel check; with `csv`, also
/// through a second per-tick check whose ticks become the CSV rows. Without, plan_stream's own
/// check gives the figures (deviation against the path read alongside): every tick is stepped
/// once. Nothing of the plan is kept.
class StreamedPlan : public PlanSink {
public:
    StreamedPlan(PlannedJob& job, const std::string& file, std::ostream* csv)
        : job_(job), file_(file), checked_path_(job.path) {
        // With an input shaper in the profile, the device's shaped command is played too (an
        // ideal plant: the setpoints themselves) to measure how far it leaves the path.
        shapers_ = run_shapers({}, job.machine);
        taps_ = shaper_taps(shapers_, job.machine);
        bool any = false;
        for (const auto& t : taps_) any = any || !t.empty();
        if (any) {
            sim::SimOptions so;
            so.record_ticks = false;
            so.shaper = taps_;
            shaped_.emplace(job.machine, so);
        }
        if (csv != nullptr) {
            checker_.emplace(checked_path_, job.machine);
            write_plan_header(job.path.axes, *csv);
            checker_->on_tick(
                [this, csv](std::uint64_t tick, const std::int64_t* setpoint, bool pen_down) {
                    write_plan_row(job_, tick, setpoint, pen_down, *csv);
                });
        }
    }
    void span(const CoreSpan& s) override {
        check_span_travel(s, spans_++, job_.path, job_.machine, file_);
        job_.outputs.add(s);
        if (checker_) checker_->span(s);
        if (shaped_) shaped_->push(s);
    }
    void pen(const PenEvent& e) override {
        if (checker_) checker_->pen(e);
    }
    void pause(const PlanPause& p) override {
        if (checker_) checker_->pause(p);
    }

    /// Plans the job through this sink; the check's figures and the counts go into the job.
    void run() {
        const auto t0 = std::chrono::steady_clock::now();
        PathSegmentSource source(job_.path);
        PlanTotals totals;
        StreamCheck own;
        if (!checker_) own.path = &checked_path_;
        {
            ProgressBar bar("planning");
            totals = plan_stream(source, job_.machine, PlanOptions{}, *this, &own, nullptr,
                                 [&](double f) { bar.update(f); });
        }
        job_.planning_seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        job_.check = checker_ ? checker_->finish() : own.result;
        job_.plan.total_ticks = totals.total_ticks;
        job_.plan.duration = totals.duration;
        job_.plan.path_length = totals.path_length;
        job_.plan.travel_length = totals.travel_length;
        job_.span_count = totals.spans;
        job_.pen_count = totals.pen_changes;
        job_.pause_count = totals.pauses;
        if (shaped_ && totals.spans > 0)
            shaped_deviation_ = shaped_->finish().shaped_command.max_mm;
    }

    /// The input shaper line of the summary ("" without one): each axis's shaper and how far
    /// the shaped command leaves the path, against the chord tolerance.
    std::string shaper_line() const {
        if (!shaped_deviation_) return "";
        char tail[160];
        std::snprintf(tail, sizeof tail,
                      "; the shaped command is up to %.2f um off the path (chord tolerance "
                      "%.2f um)",
                      *shaped_deviation_ * 1000, job_.machine.chord_tolerance * 1000);
        return "  input shaper: " + describe_shapers(shapers_, taps_, job_.machine) + tail + "\n";
    }
    /// The shaped command's largest distance from the path, mm; nothing without a shaper.
    std::optional<double> shaped_deviation() const { return shaped_deviation_; }

private:
    PlannedJob& job_;
    const std::string& file_;
    PathSegmentSource checked_path_;  ///< the check's own pass over the path
    std::optional<PlanChecker> checker_;
    std::size_t spans_ = 0;
    std::vector<std::optional<ShaperSpec>> shapers_;
    std::vector<std::vector<ShaperTap>> taps_;
    std::optional<sim::Simulator> shaped_;
    std::optional<double> shaped_deviation_;
};

}  // namespace

int run_plan(const PlanCommandOptions& o) {
    if (o.json && o.output == "-") {
        throw std::invalid_argument("--json and -o -: both would be written to standard output");
    }
    // The plan is streamed: checked, and written as CSV rows when asked, as it is made (an
    // output file appears whole or not at all).
    if (o.preview) return run_plan_preview(o);
    PlannedJob job = prepare_streamed_job(o.path, o.machine);
    refuse_long_motion(job, o.max_motion);
    std::string shaper_line;
    std::optional<double> shaped_deviation;
    const auto plan = [&](std::ostream* csv) {
        StreamedPlan streamed(job, o.path.file, csv);
        streamed.run();
        shaper_line = streamed.shaper_line();
        shaped_deviation = streamed.shaped_deviation();
    };
    if (o.output.empty()) {
        plan(nullptr);
    } else {
        write_output(o.output, [&](std::ostream& csv) { plan(&csv); });
    }
    const bool failed = !job.check.within_limits || job.check.drawing_while_pen_moves;
    // With --json, standard output holds the document or, on failure, nothing: the text
    // summary the error message points to then goes to standard error.
    std::ostream& text = o.json || o.output == "-" ? std::cerr : std::cout;
    if (!o.json || failed) {
        text << "pathstream plan: " << path_display_name(o.path.file) << " on " << o.machine
             << (o.output.empty() ? "" : " -> " + o.output) << '\n';
        print_plan_summary(job, text);
        text << shaper_line;
    }
    if (failed) {
        // Name the rule the plan broke: the jerk limit is checked with the others.
        const PlanCheck& c = job.check;
        if (c.jerk_limited &&
            (c.max_jerk_fraction_exact > 1 || c.max_join_acceleration_step_fraction > 1)) {
            throw PlanError(
                "the plan exceeds the machine's max_jerk (a planner bug): see the summary above");
        }
        throw PlanError(
            "the plan failed its per-tick check (a planner bug): see the summary above");
    }
    if (o.json) {
        auto j = plan_summary_json(o, job);
        // The device's input shaper (docs/input-shaping.md): null without one.
        j["shaped_command_deviation_mm"] =
            shaped_deviation ? nlohmann::ordered_json(*shaped_deviation) : nullptr;
        std::cout << j.dump(2) << '\n';
    }
    return 0;
}

}  // namespace pathstream::host
