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

/// Empty when the peer's plan is consistent and its sampled motion ends where the path does.
std::string peer_problem(const char* peer, const PeerPlan& plan, const TickFigures& ticks) {
    std::string problem = consistency_problem(plan);
    if (problem.empty() && ticks.end_error > 1e-6)
        problem = "sampled motion does not end at the path's end";
    return problem.empty() ? problem : std::string(peer) + ": " + problem;
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
        const PeerPlan grbl = plan_grbl_style(lines, profile);
        const PeerPlan klipper = plan_klipper_style(lines, profile);
        row.grbl = grbl.motion_time();
        row.klipper = klipper.motion_time();
        row.grbl_ticks = sample_at_ticks(grbl, profile);
        row.klipper_ticks = sample_at_ticks(klipper, profile);
        for (const std::string& p : {peer_problem("grbl-style", grbl, row.grbl_ticks),
                                     peer_problem("Klipper-style", klipper, row.klipper_ticks)}) {
            if (row.problem.empty()) row.problem = p;
        }
    } catch (const std::exception& e) {
        row.problem = e.what();
    }
    return row;
}

void print_peer_table(const std::vector<PeerRow>& rows, const host::MachineProfile& profile,
                      bool markdown) {
    const double step_limit = profile.axes.at(0).max_acceleration / profile.tick_hz;
    std::printf(
        "\npeers: pathstream against a grbl-style planner (junction deviation 0.01 mm) and a "
        "Klipper-style "
        "planner\n(square corner velocity 5 mm/s, minimum cruise ratio 0.5), both reference code "
        "in "
        "bench/reference_planners/,\non the same limits; the peers run the path flattened into "
        "lines within the "
        "chord tolerance.\nmotion = motion time, s (pen dwells excluded); x = pathstream / peer (< "
        "1: "
        "pathstream faster); optimum = pathstream's\ncontinuous TOPP-RA reference. dv = a peer's "
        "largest "
        "per-tick velocity step of one axis at %g Hz, mm/s\n(the limit a T is %g mm/s); a %% = the "
        "same as a "
        "fraction of the axis acceleration limit; ps a %% = pathstream's exact peak.\n\n",
        profile.tick_hz, step_limit);
    if (markdown) {
        std::printf(
            "| path | segments | lines | pathstream s | optimum s | %% above optimum | grbl s | x "
            "grbl | "
            "Klipper s | x Klipper | grbl dv mm/s | grbl a %% | Klipper dv mm/s | Klipper a %% | "
            "ps a %% |\n");
        std::printf(
            "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    } else {
        std::printf("%-14s %7s %7s %9s %9s %7s %9s %6s %9s %6s %8s %7s %8s %7s %6s\n", "path",
                    "segs", "lines", "ps s", "optim s", "%>opt", "grbl s", "x grbl", "klip s",
                    "x klip", "grbl dv", "grbl a%", "klip dv", "klip a%", "ps a%");
    }
    int faster_grbl = 0, faster_klipper = 0, near_optimum = 0, planned = 0;
    for (const PeerRow& r : rows) {
        if (r.motion <= 0 || r.grbl <= 0 || r.klipper <= 0) {
            std::printf(
                markdown ? "| %s | %zu | %zu | failed: %s |\n" : "%-14s %7zu %7zu failed: %s\n",
                r.name.c_str(), r.segments, r.lines, r.problem.c_str());
            continue;
        }
        ++planned;
        const double above = r.optimum > 0 ? 100 * (r.motion / r.optimum - 1) : 0;
        faster_grbl += r.motion <= r.grbl;
        faster_klipper += r.motion <= r.klipper;
        near_optimum += above <= 1;
        std::printf(markdown ? "| %s | %zu | %zu | %.3f | %.3f | %+.2f | %.3f | %.3f | %.3f | %.3f "
                               "| %.1f | %.0f | %.1f | "
                               "%.0f | %.2f |\n"
                             : "%-14s %7zu %7zu %9.3f %9.3f %+7.2f %9.3f %6.3f %9.3f %6.3f %8.1f "
                               "%7.0f %8.1f %7.0f %6.2f\n",
                    r.name.c_str(), r.segments, r.lines, r.motion, r.optimum, above, r.grbl,
                    r.motion / r.grbl, r.klipper, r.motion / r.klipper,
                    r.grbl_ticks.max_velocity_step, 100 * r.grbl_ticks.max_acceleration_fraction,
                    r.klipper_ticks.max_velocity_step,
                    100 * r.klipper_ticks.max_acceleration_fraction, 100 * r.acceleration_exact);
        if (!r.problem.empty()) std::printf("  %s: %s\n", r.name.c_str(), r.problem.c_str());
    }
    std::printf(
        "\ntargets (printed, not judged): pathstream <= 1.00x grbl on %d of %d paths, <= 1.00x "
        "Klipper on %d of "
        "%d, <= 1 %% above the optimum on %d of %d\n",
        faster_grbl, planned, faster_klipper, planned, near_optimum, planned);
}

}  // namespace pathstream::bench
