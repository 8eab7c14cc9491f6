// The one-screen text report of a run.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "pathstream/host/planner.hpp"
#include "pathstream/host/plot.hpp"

namespace pathstream::host::plot {
namespace {

std::string fmt(const char* format, double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, format, v);
    return buf;
}

std::string percent(double fraction) {
    if (!std::isfinite(fraction)) return "-";
    return fmt("%.1f", 100 * fraction);
}

/// Two decimals: the exact cubic's figures are exact, and the last per cent matters (98.96).
std::string percent2(double fraction) {
    if (!std::isfinite(fraction)) return "-";
    return fmt("%.2f", 100 * fraction);
}

std::string pad_right(std::string s, std::size_t width) {
    if (s.size() < width) s.append(width - s.size(), ' ');
    return s;
}

std::string pad(std::string s, std::size_t width) {
    if (s.size() < width) s.insert(0, width - s.size(), ' ');
    return s;
}

std::string name_of(const MachineProfile& profile, std::size_t axis) {
    if (axis < profile.axes.size() && !profile.axes[axis].name.empty())
        return profile.axes[axis].name;
    return "axis" + std::to_string(axis);
}

/// The largest element (0 when empty): the peak of per-axis fractions.
double peak_of(const std::vector<double>& values) {
    double m = 0;
    for (const double x : values) m = std::max(m, x);
    return m;
}

/// The planner check's figures of one axis, when the check has them all.
void checked_axis_figures(const PlanCheck* check, std::size_t a, AxisFigures& f) {
    f.checked = check != nullptr && a < check->axis_velocity_fraction_exact.size() &&
                a < check->axis_acceleration_fraction_exact.size() &&
                a < check->axis_max_step.size() && a < check->axis_max_second_difference.size() &&
                a < check->axis_velocity_limit_lsb.size() &&
                a < check->axis_acceleration_limit_lsb.size();
    if (!f.checked) return;
    f.velocity_fraction_cubic = check->axis_velocity_fraction_exact[a];
    f.acceleration_fraction_cubic = check->axis_acceleration_fraction_exact[a];
    f.max_step = check->axis_max_step[a];
    f.velocity_limit_lsb = check->axis_velocity_limit_lsb[a];
    f.max_second_difference = check->axis_max_second_difference[a];
    f.acceleration_limit_lsb = check->axis_acceleration_limit_lsb[a];
}

/// One axis's row: the check's figures, the executed series' peaks, the following error.
AxisFigures axis_figures(const PlanCheck* check, const MachineProfile& profile,
                         const ExecutedFigures& executed, const RunSummary& run, std::size_t a) {
    AxisFigures f;
    f.name = name_of(profile, a);
    checked_axis_figures(check, a, f);
    f.executed_velocity = a < executed.peak_velocity.size() ? executed.peak_velocity[a] : 0;
    f.executed_acceleration =
        a < executed.peak_acceleration.size() ? executed.peak_acceleration[a] : 0;
    f.max_velocity = a < profile.axes.size() ? profile.axes[a].max_velocity : 0;
    f.max_acceleration = a < profile.axes.size() ? profile.axes[a].max_acceleration : 0;
    f.following = a < run.max_following_error_mm.size();
    if (f.following) f.max_following_error_mm = run.max_following_error_mm[a];
    f.has_rms = a < run.rms_following_error_mm.size();
    if (f.has_rms) f.rms_following_error_mm = run.rms_following_error_mm[a];
    return f;
}

/// "(20.012, 0.003)": a position in mm, three decimals.
std::string position_text(const std::vector<double>& mm) {
    std::string out = "(";
    for (std::size_t a = 0; a < mm.size(); ++a) out += (a ? ", " : "") + fmt("%.3f", mm[a]);
    return out + ")";
}

/// The residual vibration and contour error lines.
void motion_lines(std::ostream& o, const RunSummary& run, double tick_hz) {
    const ResidualFigures& v = run.residual;
    const auto seconds = [&](std::uint64_t tick) {
        return fmt("%.3f", static_cast<double>(tick) / tick_hz);
    };
    if (v.stops == 0) {
        o << "  vibration  no stop after a motion: no residual vibration measured\n";
    } else {
        o << "  vibration  residual after " << v.stops << (v.stops == 1 ? " stop" : " stops")
          << ": max " << fmt("%.1f", v.max_mm * 1000) << " um, rms " << fmt("%.1f", v.rms_mm * 1000)
          << " um\n"
          << "             worst " << seconds(v.max_tick) << " s, tool " << position_text(v.tool_mm)
          << " mm, window " << v.window_ticks << " ticks\n";
    }
    const ContourFigures& c = run.contour;
    o << "  contour    error max " << fmt("%.1f", c.max_mm * 1000) << " um, rms "
      << fmt("%.1f", c.rms_mm * 1000) << " um\n"
      << "             worst " << seconds(c.max_tick) << " s, tool " << position_text(c.tool_mm)
      << " mm, window -" << c.back_ticks << "..+" << c.ahead_ticks << " ticks\n";
}

}  // namespace

void pen_figures(const TickSeries& executed, ExecutedFigures& f) {
    for (std::size_t k = 0; k < executed.pen_down.size(); ++k) {
        const bool down = executed.pen_down[k] != 0;
        const bool before = k > 0 && executed.pen_down[k - 1] != 0;
        f.pen_down_ticks += down ? 1 : 0;
        if (down && !before) ++f.pen_downs;
        if (!down && before) ++f.pen_ups;
    }
    f.ticks = executed.pen_down.size();
}

ExecutedFigures executed_figures(const TickSeries& executed, const MachineProfile& profile,
                                 unsigned half_window) {
    ExecutedFigures f;
    f.axes = executed.axes;
    pen_figures(executed, f);
    const Derivatives d = differentiate(executed, profile, half_window);
    f.half_window = d.half_window;
    f.acceleration_noise = d.acceleration_noise;
    f.peak_velocity.assign(executed.axes, 0.0);
    f.peak_acceleration.assign(executed.axes, 0.0);
    const std::size_t axes = executed.axes;
    for (std::size_t k = 0; k < executed.ticks(); ++k) {
        for (std::size_t a = 0; a < axes; ++a) {
            f.peak_velocity[a] = std::max(f.peak_velocity[a], std::fabs(d.velocity[k * axes + a]));
            f.peak_acceleration[a] =
                std::max(f.peak_acceleration[a], std::fabs(d.acceleration[k * axes + a]));
        }
        f.peak_speed = std::max(f.peak_speed, d.speed[k]);
    }
    return f;
}

PlanFigures plan_figures(const Plan& plan, const MachineProfile& profile) {
    PlanFigures f;
    f.duration =
        plan.duration > 0 ? plan.duration : static_cast<double>(plan.total_ticks) / profile.tick_hz;
    f.total_ticks = plan.total_ticks;
    f.path_length = plan.path_length;
    f.travel_length = plan.travel_length;
    for (const auto& e : plan.pen) {
        f.dwell_ticks +=
            delay_ticks(e.down ? profile.pen_down_delay : profile.pen_up_delay, profile.tick_hz);
    }
    return f;
}

ReportFigures report_figures(const PlanFigures& plan, const PlanCheck* check,
                             const MachineProfile& profile, const ExecutedFigures& executed,
                             const RunSummary& run) {
    ReportFigures f;
    f.duration =
        plan.duration > 0 ? plan.duration : static_cast<double>(plan.total_ticks) / profile.tick_hz;
    f.pen_downs = executed.pen_downs;
    f.pen_ups = executed.pen_ups;
    f.pen_down_ticks = executed.pen_down_ticks;
    f.executed_ticks = executed.ticks;
    f.dwell_ticks = plan.dwell_ticks;
    if (check != nullptr) {
        f.velocity_fraction_cubic = peak_of(check->axis_velocity_fraction_exact);
        f.acceleration_fraction_cubic = peak_of(check->axis_acceleration_fraction_exact);
    }
    f.executed_half_window = executed.half_window;
    f.executed_acceleration_noise = executed.acceleration_noise;
    for (std::size_t a = 0; a < executed.axes; ++a) {
        f.axes.push_back(axis_figures(check, profile, executed, run, a));
    }
    return f;
}

ReportFigures report_figures(const Plan& plan, const PlanCheck* check,
                             const MachineProfile& profile, const TickSeries& executed,
                             const RunSummary& run) {
    return report_figures(plan_figures(plan, profile), check, profile,
                          executed_figures(executed, profile), run);
}

std::string text_report(const Plan& plan, const PlanCheck* check, const MachineProfile& profile,
                        const TickSeries& executed, const RunSummary& run) {
    return text_report(plan_figures(plan, profile), check, profile,
                       executed_figures(executed, profile), run);
}

std::string text_report(const PlanFigures& plan, const PlanCheck* check,
                        const MachineProfile& profile, const ExecutedFigures& executed,
                        const RunSummary& run) {
    std::ostringstream o;
    const ReportFigures f = report_figures(plan, check, profile, executed, run);
    const std::size_t axes = executed.axes;
    std::string names;
    for (std::size_t a = 0; a < axes; ++a) names += (a ? ", " : "") + name_of(profile, a);

    o << "pathstream run on the " << run.target << "\n";
    o << "  machine    " << axes << " axes (" << names << "), " << fmt("%.6g", profile.tick_hz)
      << " Hz tick, " << fmt("%.6g", profile.mm_per_lsb) << " mm/LSB\n";
    o << "  plant      " << run.plant << "\n";
    if (!run.modes.empty()) o << "  modes      " << run.modes << "\n";
    if (!run.shaper.empty()) o << "  shaper     " << run.shaper << "\n";
    o << "  duration   " << fmt("%.3f", f.duration) << " s planned; "
      << fmt("%.3f", run.simulated_seconds) << " s simulated in " << fmt("%.3f", run.wall_seconds)
      << " s wall";
    if (run.wall_seconds > 0)
        o << " (" << fmt("%.3g", run.simulated_seconds / run.wall_seconds) << "x)";
    o << (run.realtime ? ", paced" : "") << "\n";
    o << "  path       " << fmt("%.2f", plan.path_length) << " mm pen-down, "
      << fmt("%.2f", plan.travel_length) << " mm travel, " << run.pen_switches
      << " pen lifts and lowers\n";
    {
        const double total = static_cast<double>(f.executed_ticks);
        const double down_ticks = static_cast<double>(f.pen_down_ticks);
        o << "  pen        " << f.pen_downs << " down, " << f.pen_ups << " up; down "
          << fmt("%.3f", down_ticks / profile.tick_hz) << " s ("
          << fmt("%.0f", total > 0 ? 100.0 * down_ticks / total : 0.0) << " %), dwells "
          << fmt("%.3f", static_cast<double>(f.dwell_ticks) / profile.tick_hz) << " s\n";
    }
    o << "  device     " << run.ticks << " ticks, " << run.spans << " spans, " << run.underruns
      << " underruns";
    if (run.realtime) o << ", " << run.late_ticks << " late ticks";
    o << "\n";
    // Figures against the limits say what they measure: the exact cubic (what a device that
    // validates spans checks), the integer setpoints' differences in LSB next to the limit in
    // LSB, and the executed series' smoothed differences.
    if (check != nullptr) {
        o << "  deviation  " << fmt("%.2f", check->max_deviation * 1000) << " um max (tick "
          << check->worst_deviation_tick << "), tolerance "
          << fmt("%.2f", profile.chord_tolerance * 1000) << " um (planner check)\n";
        o << "  limits     "
          << (check->within_limits ? "within the axis limits" : "LIMITS EXCEEDED")
          << " (exact cubic peak: v " << percent2(f.velocity_fraction_cubic) << " %, a "
          << percent2(f.acceleration_fraction_cubic) << " %)\n";
        // Jerk next to it: against max_jerk when the profile sets one, else in mm/s^3.
        if (check->jerk_limited) {
            o << "  jerk       cubic " << percent2(check->max_jerk_fraction_exact)
              << " % of max jerk, join step "
              << percent2(check->max_join_acceleration_step_fraction) << " % of one tick of it\n";
        } else if (!check->axis_jerk.empty()) {
            o << "  jerk       cubic peak "
              << fmt("%.4g", *std::max_element(check->axis_jerk.begin(), check->axis_jerk.end()))
              << " mm/s^3, join step "
              << fmt("%.4g", *std::max_element(check->axis_join_acceleration_step.begin(),
                                               check->axis_join_acceleration_step.end()))
              << " mm/s^2 (no max_jerk)\n";
        }
        if (check->max_velocity_fraction > 1 || check->max_acceleration_fraction > 1) {
            o << "             setpoint differences over limit + rounding (v "
              << percent(check->max_velocity_fraction) << " %, a "
              << percent(check->max_acceleration_fraction) << " %)\n";
        }
    } else {
        o << "  deviation  not checked (no planner check given)\n";
    }

    // Per axis: peaks against the limits, then the following error.
    const bool following = !run.max_following_error_mm.empty();
    o << "\n            velocity peak                      acceleration peak\n"
      << "  axis      cubic   setpoints  executed     cubic   setpoints  executed\n"
      << "            % lim    LSB/tick     % lim     % lim  LSB/tick^2     % lim\n";
    for (const AxisFigures& x : f.axes) {
        const auto steps = [&](std::int64_t peak, double limit) {
            return std::to_string(peak) + " of " + fmt("%.4g", limit);
        };
        o << "  " << pad_right(x.name, 6)
          << pad(x.checked ? percent2(x.velocity_fraction_cubic) : "-", 9)
          << pad(x.checked ? steps(x.max_step, x.velocity_limit_lsb) : "-", 12)
          << pad(x.max_velocity > 0 ? percent(x.executed_velocity / x.max_velocity) : "-", 10)
          << pad(x.checked ? percent2(x.acceleration_fraction_cubic) : "-", 10)
          << pad(x.checked ? steps(x.max_second_difference, x.acceleration_limit_lsb) : "-", 12)
          << pad(x.max_acceleration > 0 ? percent(x.executed_acceleration / x.max_acceleration)
                                        : "-",
                 10)
          << "\n";
    }
    o << "  cubic      the spans' exact cubics before rounding: what the device checks\n"
      << "  setpoints  largest integer difference \"of\" the limit, both in LSB; rounding\n"
      << "             adds < 1 LSB/tick to a step, < 2 LSB/tick^2 to a 2nd difference\n";
    o << "  executed   setpoint differences over +/-" << f.executed_half_window
      << " ticks (a noise <= " << fmt("%.0f", f.executed_acceleration_noise) << " mm/s^2)\n";
    if (following) {
        o << "\n  axis      following error um\n"
          << "                 max       rms\n";
        for (const AxisFigures& x : f.axes) {
            if (!x.following) break;
            o << "  " << pad_right(x.name, 6)
              << pad(fmt("%.1f", x.max_following_error_mm * 1000), 11)
              << pad(x.has_rms ? fmt("%.1f", x.rms_following_error_mm * 1000) : "-", 10) << "\n";
        }
    } else {
        o << "  following error: 0 (ideal plant: position = setpoint)\n";
    }
    if (run.motion_measured) motion_lines(o, run, profile.tick_hz);
    if (run.underruns > 0) {
        o << "  WARNING: the span queue ran dry " << run.underruns
          << " times before the end of the plan\n";
    }
    return o.str();
}

}  // namespace pathstream::host::plot
