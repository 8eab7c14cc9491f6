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

}  // namespace

std::string text_report(const Plan& plan, const PlanCheck* check, const MachineProfile& profile,
                        const TickSeries& executed, const RunSummary& run) {
    std::ostringstream o;
    const std::size_t axes = executed.axes;
    std::string names;
    for (std::size_t a = 0; a < axes; ++a) names += (a ? ", " : "") + name_of(profile, a);

    o << "pathstream run on the " << run.target << "\n";
    o << "  machine    " << axes << " axes (" << names << "), " << fmt("%.6g", profile.tick_hz)
      << " Hz tick, " << fmt("%.6g", profile.mm_per_lsb) << " mm/LSB\n";
    o << "  plant      " << run.plant << "\n";
    const double duration =
        plan.duration > 0 ? plan.duration : static_cast<double>(plan.total_ticks) / profile.tick_hz;
    o << "  duration   " << fmt("%.3f", duration) << " s planned; "
      << fmt("%.3f", run.simulated_seconds) << " s simulated in " << fmt("%.3f", run.wall_seconds)
      << " s wall";
    if (run.wall_seconds > 0)
        o << " (" << fmt("%.3g", run.simulated_seconds / run.wall_seconds) << "x)";
    o << (run.realtime ? ", paced" : "") << "\n";
    o << "  path       " << fmt("%.2f", plan.path_length) << " mm pen-down, "
      << fmt("%.2f", plan.travel_length) << " mm travel, " << run.pen_switches << " pen switches\n";
    // Pen: what the pen-lift output did on the executed ticks, and the time the plan holds the
    // axes still while the pen moves (no drawing then).
    {
        std::uint64_t downs = 0, ups = 0, down_ticks = 0;
        for (std::size_t k = 0; k < executed.pen_down.size(); ++k) {
            const bool down = executed.pen_down[k] != 0;
            const bool before = k > 0 && executed.pen_down[k - 1] != 0;
            down_ticks += down ? 1 : 0;
            if (down && !before) ++downs;
            if (!down && before) ++ups;
        }
        std::uint64_t dwell_ticks = 0;
        for (const auto& e : plan.pen) {
            dwell_ticks += delay_ticks(e.down ? profile.pen_down_delay : profile.pen_up_delay, profile.tick_hz);
        }
        const double total = static_cast<double>(executed.pen_down.size());
        o << "  pen        " << downs << " down, " << ups << " up; down "
          << fmt("%.3f", static_cast<double>(down_ticks) / profile.tick_hz) << " s ("
          << fmt("%.0f", total > 0 ? 100.0 * static_cast<double>(down_ticks) / total : 0.0) << " %), dwells "
          << fmt("%.3f", static_cast<double>(dwell_ticks) / profile.tick_hz) << " s\n";
    }
    o << "  device     " << run.ticks << " ticks, " << run.spans << " spans, " << run.underruns
      << " underruns";
    if (run.realtime) o << ", " << run.late_ticks << " late ticks";
    o << "\n";
    // Figures against the limits say what they measure: the exact cubic (what a device that
    // validates spans checks), the integer setpoints' differences in LSB next to the limit in
    // LSB, and the executed series' smoothed differences.
    const auto exact_peak = [&](const std::vector<double>& f) {
        double m = 0;
        for (const double x : f) m = std::max(m, x);
        return m;
    };
    if (check != nullptr) {
        o << "  deviation  " << fmt("%.2f", check->max_deviation * 1000) << " um max (tick "
          << check->worst_deviation_tick << "), tolerance "
          << fmt("%.2f", profile.chord_tolerance * 1000) << " um (planner check)\n";
        o << "  limits     "
          << (check->within_limits ? "within the axis limits" : "LIMITS EXCEEDED")
          << " (exact cubic peak: v " << percent2(exact_peak(check->axis_velocity_fraction_exact))
          << " %, a " << percent2(exact_peak(check->axis_acceleration_fraction_exact)) << " %)\n";
        if (check->max_velocity_fraction > 1 || check->max_acceleration_fraction > 1) {
            o << "             setpoint differences over limit + rounding (v "
              << percent(check->max_velocity_fraction) << " %, a "
              << percent(check->max_acceleration_fraction) << " %)\n";
        }
    } else {
        o << "  deviation  not checked (no planner check given)\n";
    }

    // Per axis: peaks against the limits, then the following error.
    const Derivatives d = differentiate(executed, profile);
    const bool following = !run.max_following_error_mm.empty();
    o << "\n            velocity peak                      acceleration peak\n"
      << "  axis      cubic   setpoints  executed     cubic   setpoints  executed\n"
      << "            % lim    LSB/tick     % lim     % lim  LSB/tick^2     % lim\n";
    for (std::size_t a = 0; a < axes; ++a) {
        double v = 0, acc = 0;
        for (std::size_t k = 0; k < executed.ticks(); ++k) {
            v = std::max(v, std::fabs(d.velocity[k * axes + a]));
            acc = std::max(acc, std::fabs(d.acceleration[k * axes + a]));
        }
        const double v_lim = a < profile.axes.size() ? profile.axes[a].max_velocity : 0;
        const double a_lim = a < profile.axes.size() ? profile.axes[a].max_acceleration : 0;
        const bool checked = check != nullptr && a < check->axis_velocity_fraction_exact.size() &&
                             a < check->axis_acceleration_fraction_exact.size() &&
                             a < check->axis_max_step.size() &&
                             a < check->axis_max_second_difference.size() &&
                             a < check->axis_velocity_limit_lsb.size() &&
                             a < check->axis_acceleration_limit_lsb.size();
        const auto steps = [&](std::int64_t peak, double limit) {
            return std::to_string(peak) + " of " + fmt("%.4g", limit);
        };
        o << "  " << pad_right(name_of(profile, a), 6)
          << pad(checked ? percent2(check->axis_velocity_fraction_exact[a]) : "-", 9)
          << pad(checked ? steps(check->axis_max_step[a], check->axis_velocity_limit_lsb[a]) : "-",
                 12)
          << pad(v_lim > 0 ? percent(v / v_lim) : "-", 10)
          << pad(checked ? percent2(check->axis_acceleration_fraction_exact[a]) : "-", 10)
          << pad(checked ? steps(check->axis_max_second_difference[a],
                                 check->axis_acceleration_limit_lsb[a])
                         : "-",
                 12)
          << pad(a_lim > 0 ? percent(acc / a_lim) : "-", 10) << "\n";
    }
    o << "  cubic      the spans' exact cubics before rounding: what the device checks\n"
      << "  setpoints  largest integer difference \"of\" the limit, both in LSB; rounding\n"
      << "             adds < 1 LSB/tick to a step, < 2 LSB/tick^2 to a 2nd difference\n";
    o << "  executed   setpoint differences over +/-" << d.half_window
      << " ticks (a noise <= " << fmt("%.0f", d.acceleration_noise) << " mm/s^2)\n";
    if (following) {
        o << "\n  axis      following error um\n"
          << "                 max       rms\n";
        for (std::size_t a = 0; a < axes && a < run.max_following_error_mm.size(); ++a) {
            o << "  " << pad_right(name_of(profile, a), 6)
              << pad(fmt("%.1f", run.max_following_error_mm[a] * 1000), 11)
              << pad(a < run.rms_following_error_mm.size()
                         ? fmt("%.1f", run.rms_following_error_mm[a] * 1000)
                         : "-",
                     10)
              << "\n";
        }
    } else {
        o << "  following error: 0 (ideal plant: position = setpoint)\n";
    }
    if (run.underruns > 0) {
        o << "  WARNING: the span queue ran dry " << run.underruns
          << " times before the end of the plan\n";
    }
    return o.str();
}

}  // namespace pathstream::host::plot
