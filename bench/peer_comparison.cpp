#include "peer_comparison.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>

#include "pathstream/host/geometry.hpp"
#include "pathstream/host/planner.hpp"
#include "reference_planners/grbl_style.hpp"
#include "reference_planners/klipper_style.hpp"

namespace pathstream::bench {

namespace {

/// One peer's `plan` measured: its motion time and its profile sampled at the tick. The first
/// problem found (inconsistent, not ending at the path's end, or for a held plan a junction
/// stepping an axis's velocity by more than one tick of acceleration) goes to `problem` unless
/// that already holds one.
PeerFigures measure_peer(const char* peer, const PeerPlan& plan, JunctionRule rule,
                         const host::MachineProfile& profile, std::string& problem) {
    PeerFigures f;
    f.motion = plan.motion_time();
    f.ticks = sample_at_ticks(plan, profile);
    std::string found = consistency_problem(plan);
    if (found.empty() && f.ticks.end_error > 1e-6)
        found = "sampled motion does not end at the path's end";
    // 1e-9: the cap is computed from the same directions, so only rounding can exceed it.
    if (found.empty() && rule == JunctionRule::per_tick &&
        max_junction_step_fraction(plan, profile) > 1 + 1e-9)
        found = "a junction steps an axis's velocity by more than one tick of acceleration";
    if (problem.empty() && !found.empty()) problem = std::string(peer) + ": " + found;
    return f;
}

}  // namespace

PeerRow compare_with_peers(const std::string& name, const host::Path& path,
                           const host::MachineProfile& profile) {
    PeerRow row;
    row.name = name;
    try {
        const std::vector<host::BezierSegment> segments = host::to_bezier_segments(path);
        row.segments = segments.size();
        host::PlanStats stats;
        const host::Plan plan = host::plan_path(segments, profile, host::PlanOptions{}, &stats);
        const host::PlanCheck check = host::check_plan(plan, segments, profile);
        row.motion = static_cast<double>(stats.motion_ticks) / profile.tick_hz;
        row.optimum = stats.reference_motion_time;
        row.acceleration_exact =
            std::max(check.max_acceleration_fraction_exact, check.max_span_acceleration_fraction);
        const double allowance =
            profile.chord_tolerance +
            1.5 * std::sqrt(static_cast<double>(path.axes)) * profile.mm_per_lsb;
        if (!check.within_limits) row.problem = "pathstream: over the limits";
        if (check.drawing_while_pen_moves) row.problem = "pathstream: motion during a pen dwell";
        if (check.max_deviation > allowance)
            row.problem = "pathstream: deviation over the tolerance";

        const std::vector<LineMove> lines = flatten_to_lines(segments, profile);
        row.lines = lines.size();
        const JunctionRule own = JunctionRule::peer, held = JunctionRule::per_tick;
        row.grbl = measure_peer("grbl-style", plan_grbl_style(lines, profile, own), own, profile,
                                row.problem);
        row.klipper = measure_peer("Klipper-style", plan_klipper_style(lines, profile, own), own,
                                   profile, row.problem);
        row.grbl_held = measure_peer("held grbl-style", plan_grbl_style(lines, profile, held), held,
                                     profile, row.problem);
        row.klipper_held =
            measure_peer("held Klipper-style", plan_klipper_style(lines, profile, held), held,
                         profile, row.problem);
    } catch (const std::exception& e) {
        row.problem = e.what();
    }
    return row;
}

void print_peer_table(const std::vector<PeerRow>& rows, const host::MachineProfile& profile,
                      bool markdown) {
    const double step_limit = profile.axes.at(0).max_acceleration / profile.tick_hz;
    std::printf(
        "\npeers: pathstream against a grbl-style planner (junction deviation 0.01 mm) and a\n"
        "Klipper-style planner (square corner velocity 5 mm/s, minimum cruise ratio 0.5), both\n"
        "reference code in bench/reference_planners/, on the same limits; the peers run the path\n"
        "flattened into lines within the chord tolerance. Each peer runs twice: on its own "
        "junction\n"
        "rule, and held to the per-tick limits (\"held\"): every junction speed also capped so "
        "that\n"
        "no axis's velocity steps by more than one tick of its acceleration, a T, at the "
        "junction.\n"
        "motion = motion time, s (pen dwells excluded); x = pathstream / peer (< 1: pathstream\n"
        "faster); optimum = pathstream's continuous TOPP-RA reference. dv = a peer's largest\n"
        "per-tick velocity step of one axis, sampled at %g Hz, mm/s (the limit a T is %g mm/s; a\n"
        "held peer's sampled step adds the braking of the ticks around a junction to its step);\n"
        "a %% = the same as a fraction of the axis acceleration limit; ps a %% = pathstream's "
        "exact\n"
        "peak.\n\n",
        profile.tick_hz, step_limit);
    if (markdown) {
        std::printf(
            "| path | segments | lines | pathstream s | optimum s | %% above optimum | grbl s "
            "| x grbl | Klipper s | x Klipper | grbl dv mm/s | grbl a %% | Klipper dv mm/s "
            "| Klipper a %% | held grbl s | x held grbl | held grbl dv mm/s | held Klipper s "
            "| x held Klipper | held Klipper dv mm/s | ps a %% |\n");
        std::printf(
            "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:"
            "|---:|---:|---:|---:|\n");
    } else {
        std::printf(
            "%-14s %7s %7s %9s %9s %7s %9s %6s %9s %6s %8s %7s %8s %7s %9s %7s %8s %9s %7s %8s "
            "%6s\n",
            "path", "segs", "lines", "ps s", "optim s", "%>opt", "grbl s", "x grbl", "klip s",
            "x klip", "grbl dv", "grbl a%", "klip dv", "klip a%", "hgrbl s", "x hgrbl", "hgrbl dv",
            "hklip s", "x hklip", "hklip dv", "ps a%");
    }
    int faster_grbl = 0, faster_klipper = 0, faster_grbl_held = 0, faster_klipper_held = 0;
    int near_optimum = 0, planned = 0;
    for (const PeerRow& r : rows) {
        if (r.motion <= 0 || r.grbl.motion <= 0 || r.klipper.motion <= 0 ||
            r.grbl_held.motion <= 0 || r.klipper_held.motion <= 0) {
            std::printf(
                markdown ? "| %s | %zu | %zu | failed: %s |\n" : "%-14s %7zu %7zu failed: %s\n",
                r.name.c_str(), r.segments, r.lines, r.problem.c_str());
            continue;
        }
        ++planned;
        const double above = r.optimum > 0 ? 100 * (r.motion / r.optimum - 1) : 0;
        faster_grbl += r.motion <= r.grbl.motion;
        faster_klipper += r.motion <= r.klipper.motion;
        faster_grbl_held += r.motion <= r.grbl_held.motion;
        faster_klipper_held += r.motion <= r.klipper_held.motion;
        near_optimum += above <= 1;
        std::printf(markdown ? "| %s | %zu | %zu | %.3f | %.3f | %+.2f | %.3f | %.3f | %.3f | %.3f "
                               "| %.1f | %.0f | %.1f | %.0f | %.3f | %.3f | %.1f | %.3f | %.3f "
                               "| %.1f | %.2f |\n"
                             : "%-14s %7zu %7zu %9.3f %9.3f %+7.2f %9.3f %6.3f %9.3f %6.3f %8.1f "
                               "%7.0f %8.1f %7.0f %9.3f %7.3f %8.1f %9.3f %7.3f %8.1f %6.2f\n",
                    r.name.c_str(), r.segments, r.lines, r.motion, r.optimum, above, r.grbl.motion,
                    r.motion / r.grbl.motion, r.klipper.motion, r.motion / r.klipper.motion,
                    r.grbl.ticks.max_velocity_step, 100 * r.grbl.ticks.max_acceleration_fraction,
                    r.klipper.ticks.max_velocity_step,
                    100 * r.klipper.ticks.max_acceleration_fraction, r.grbl_held.motion,
                    r.motion / r.grbl_held.motion, r.grbl_held.ticks.max_velocity_step,
                    r.klipper_held.motion, r.motion / r.klipper_held.motion,
                    r.klipper_held.ticks.max_velocity_step, 100 * r.acceleration_exact);
        if (!r.problem.empty()) std::printf("  %s: %s\n", r.name.c_str(), r.problem.c_str());
    }
    std::printf(
        "\ntargets (printed, not judged): pathstream <= 1.00x grbl on %d of %d paths, <= 1.00x "
        "Klipper on %d of %d;\nheld to the per-tick limits: <= 1.00x grbl on %d of %d, <= 1.00x "
        "Klipper on %d of %d; <= 1 %% above the optimum on %d of %d\n",
        faster_grbl, planned, faster_klipper, planned, faster_grbl_held, planned,
        faster_klipper_held, planned, near_optimum, planned);
}

}  // namespace pathstream::bench
