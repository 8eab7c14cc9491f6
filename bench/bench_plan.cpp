// bench_plan: how long does planning a 10,000-segment drawing take, and how close to the
// time-optimal motion is the plan the device executes?
//
// Paths (2 axes, millimetres), each --segments Bezier segments long (default 10,000):
//   * rose     : closed uniform B-spline through N points of a 7-petal rose r = 60 cos(7 t);
//   * wander   : open uniform B-spline through N - 1 points of a smooth random walk (seeded);
//   * spiral   : polyline of N straight segments along an Archimedean spiral (every vertex a
//                small corner, crossed at the corner speed).
// Machine: examples/machines/pen_plotter.json's values (250 mm/s, 3000 mm/s^2 per axis, 1 kHz,
// 8 ticks per span, 1 um LSB, feed 80 mm/s, chord tolerance 5 um).
//
// For each path, in the same run:
//   * plan       : plan_path with the default options; wall time best of --runs (3) runs;
//   * fine       : the same planner on a --density (16) times denser lookahead grid (grid step
//                  and min nodes per segment x density, max turn / 4): the planner's own
//                  converged figure;
//   * optimum    : the continuous time-optimal profile (TOPP-RA forward pass, piecewise
//                  constant path acceleration, full limits, no margins, no whole ticks) on that
//                  dense grid: an independent lower bound of what any plan of this path can do.
// "motion" is the executed motion time (span ticks / tick_hz, pen dwells excluded); "% above"
// compares it with fine and with optimum. Every plan goes through check_plan (every tick, the
// core's setpoints): within the limits, no motion during pen dwells, deviation within the chord
// tolerance plus 1.5 sqrt(2) LSB; any failure prints why and exits with 1. Timings and the
// motion times against fine and optimum are printed, never judged.
//
// Usage: bench_plan [--quick] [--segments N] [--density D] [--runs R] [--markdown] [--help]
// Exit status (also printed by --help): 0 every plan passed its check, 1 a plan failed its check
// or could not be made, 2 usage error.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "pathstream/host/geometry.hpp"
#include "pathstream/host/planner.hpp"

using namespace pathstream::host;

namespace {

constexpr double kPi = 3.14159265358979323846;

MachineProfile pen_plotter() {
    MachineProfile p;
    p.axes = {{"x", 250, 3000}, {"y", 250, 3000}};
    p.mm_per_lsb = 0.001;
    p.tick_hz = 1000;
    p.ticks_per_span = 8;
    p.feed = 80;
    p.travel_feed = 200;
    p.pen_down_delay = 0.08;
    p.pen_up_delay = 0.06;
    p.chord_tolerance = 0.005;
    return p;
}

Path rose(std::size_t n) {
    Subpath s;
    s.basis = PathBasis::kBSpline;
    s.closed = true;
    for (std::size_t i = 0; i < n; ++i) {
        const double t = 2 * kPi * static_cast<double>(i) / static_cast<double>(n);
        const double r = 60 * std::cos(7 * t);
        s.points.push_back({r * std::cos(t), r * std::sin(t)});
    }
    Path p;
    p.subpaths = {s};
    return p;
}

Path wander(std::size_t n) {
    std::mt19937_64 rng(20261122);
    std::normal_distribution<double> turn(0, 0.25);
    Subpath s;
    s.basis = PathBasis::kBSpline;
    double x = 0, y = 0, heading = 0;
    for (std::size_t i = 0; i + 1 < n; ++i) {  // an open B-spline of m points has m - 1 segments
        s.points.push_back({x, y});
        heading += turn(rng);
        x += 1.5 * std::cos(heading);
        y += 1.5 * std::sin(heading);
        // stay within a 200 mm square: steer back towards the centre near the edges
        if (std::fabs(x) > 100 || std::fabs(y) > 100) heading = std::atan2(-y, -x) + turn(rng);
    }
    s.points.push_back({x, y});
    Path p;
    p.subpaths = {s};
    return p;
}

Path spiral(std::size_t n) {
    Subpath s;
    s.basis = PathBasis::kPolyline;
    const double turns = 20, pitch = 3;  // mm between turns
    for (std::size_t i = 0; i <= n; ++i) {
        const double t = 2 * kPi * turns * static_cast<double>(i) / static_cast<double>(n);
        const double r = 5 + pitch * t / (2 * kPi);
        s.points.push_back({r * std::cos(t), r * std::sin(t)});
    }
    Path p;
    p.subpaths = {s};
    return p;
}

struct Row {
    std::string name;
    std::size_t segments = 0, nodes = 0, spans = 0, pieces = 0, retries = 0;
    int replans = 0;
    double plan_ms = 0, check_ms = 0, motion = 0, fine = 0, optimum = 0, length = 0;
    double max_deviation = 0, v_fraction_exact = 0, a_fraction_exact = 0;
    std::uint64_t ticks = 0;
};

double ms_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

constexpr const char* kUsageText =
    "usage: bench_plan [--quick] [--segments N] [--density D] [--runs R] [--markdown] [--help]\n"
    "  Plans three 2-axis drawings (rose, wander, spiral) of N segments (default 10000) for the "
    "pen\n"
    "  plotter and prints planning time, motion time against the same planner on a D times denser\n"
    "  grid (default 16) and the continuous optimum, and the check of every executed tick.\n"
    "  --quick        1000 segments, one run (the ctest smoke run)\n"
    "  --segments N   segments per path (>= 10)\n"
    "  --density D    the denser grid's factor (>= 1)\n"
    "  --runs R       planning runs per path, best time kept (default 3)\n"
    "  --markdown     the table in Markdown\n"
    "targets (independent of the machine's speed): every plan within the limits for its exact\n"
    "cubic and every tick, no motion during a pen dwell, deviation within the chord tolerance "
    "plus\n"
    "1.5 sqrt(2) LSB. Times are printed, never judged.\n"
    "exit status: 0 every plan passed; 1 a plan failed its check or could not be made; 2 usage\n"
    "error.\n";

int main(int argc, char** argv) {
    std::size_t segments = 10000;
    double density = 16;
    int runs = 3;
    bool markdown = false, quick = false;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        const bool has_value = i + 1 < argc;
        if (a == "--quick") {
            quick = true;
        } else if (a == "--markdown") {
            markdown = true;
        } else if (a == "--segments" && has_value) {
            segments = static_cast<std::size_t>(std::strtoul(argv[++i], nullptr, 10));
        } else if (a == "--density" && has_value) {
            density = std::strtod(argv[++i], nullptr);
        } else if (a == "--runs" && has_value) {
            runs = std::atoi(argv[++i]);
        } else if (a == "--help" || a == "-h") {
            std::fputs(kUsageText, stdout);
            return 0;
        } else {
            std::fputs(kUsageText, stderr);
            return 2;
        }
    }
    if (quick) {
        segments = std::min<std::size_t>(segments, 1000);
        runs = 1;
    }
    if (segments < 10 || density < 1 || runs < 1) {
        std::fprintf(stderr, "bench_plan: --segments >= 10, --density >= 1, --runs >= 1\n");
        return 2;
    }

    const MachineProfile profile = pen_plotter();
    const PlanOptions options;
    PlanOptions fine = options;
    fine.grid_step /= density;
    fine.min_nodes_per_segment = static_cast<std::size_t>(std::ceil(options.min_nodes_per_segment * density));
    fine.max_turn /= 4;
    const double quantisation = 1.5 * std::sqrt(2.0) * profile.mm_per_lsb;

    struct Named {
        const char* name;
        Path path;
    };
    const Named paths[] = {{"rose", rose(segments)}, {"wander", wander(segments)}, {"spiral", spiral(segments)}};
    std::vector<Row> rows;
    bool ok = true;
    for (const Named& np : paths) {
        Row row;
        row.name = np.name;
        const std::vector<BezierSegment> segs = to_bezier_segments(np.path);
        row.segments = segs.size();
        try {
            Plan plan;
            PlanStats stats;
            row.plan_ms = 1e300;
            for (int r = 0; r < runs; ++r) {
                const auto t0 = std::chrono::steady_clock::now();
                plan = plan_path(segs, profile, options, &stats);
                row.plan_ms = std::min(row.plan_ms, ms_since(t0));
            }
            const auto t1 = std::chrono::steady_clock::now();
            const PlanCheck check = check_plan(plan, segs, profile);
            row.check_ms = ms_since(t1);
            PlanStats fine_stats;
            (void)plan_path(segs, profile, fine, &fine_stats);
            row.nodes = stats.grid_nodes;
            row.spans = plan.spans.size();
            row.pieces = stats.pieces;
            row.retries = stats.local_retries;
            row.replans = stats.replans;
            row.ticks = plan.total_ticks;
            row.length = plan.path_length;
            row.motion = static_cast<double>(stats.motion_ticks) / profile.tick_hz;
            row.fine = static_cast<double>(fine_stats.motion_ticks) / profile.tick_hz;
            row.optimum = fine_stats.reference_motion_time;
            row.max_deviation = check.max_deviation;
            row.v_fraction_exact = std::max(check.max_velocity_fraction_exact, check.max_span_velocity_fraction);
            row.a_fraction_exact =
                std::max(check.max_acceleration_fraction_exact, check.max_span_acceleration_fraction);
            if (!check.within_limits) {
                std::fprintf(stderr, "%s: over the limits (v %.6f, a %.6f of the limit exactly)\n", np.name,
                             row.v_fraction_exact, row.a_fraction_exact);
                ok = false;
            }
            if (check.drawing_while_pen_moves) {
                std::fprintf(stderr, "%s: motion during a pen dwell\n", np.name);
                ok = false;
            }
            if (check.max_deviation > profile.chord_tolerance + quantisation) {
                std::fprintf(stderr, "%s: deviation %.6f mm at tick %llu exceeds %.6f mm\n", np.name,
                             check.max_deviation, static_cast<unsigned long long>(check.worst_deviation_tick),
                             profile.chord_tolerance + quantisation);
                ok = false;
            }
        } catch (const std::exception& e) {
            std::fprintf(stderr, "%s: %s\n", np.name, e.what());
            ok = false;
        }
        rows.push_back(row);
    }

    std::printf("bench_plan: %zu segments per path, pen plotter profile (%g mm/s, %g mm/s^2, %g Hz, %u ticks/span)\n",
                segments, profile.axes[0].max_velocity, profile.axes[0].max_acceleration, profile.tick_hz,
                profile.ticks_per_span);
    std::printf("fine = same planner, %gx denser lookahead grid; optimum = continuous TOPP-RA on that grid\n\n",
                density);
    if (markdown) {
        std::printf("| path | segments | grid nodes | spans | plan ms | check ms | motion s | fine s | optimum s | "
                    "%% above fine | %% above optimum | retries | replans | max dev um | v %% exact | a %% exact |\n");
        std::printf("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    } else {
        std::printf("%-7s %8s %9s %7s %9s %9s %9s %9s %9s %8s %8s %7s %7s %8s %8s %8s\n", "path", "segments", "nodes",
                    "spans", "plan ms", "check ms", "motion s", "fine s", "optim s", "%>fine", "%>optim", "retries",
                    "replans", "dev um", "v % ex", "a % ex");
    }
    for (const Row& r : rows) {
        const double above_fine = r.fine > 0 ? 100 * (r.motion / r.fine - 1) : 0;
        const double above_opt = r.optimum > 0 ? 100 * (r.motion / r.optimum - 1) : 0;
        if (markdown) {
            std::printf("| %s | %zu | %zu | %zu | %.1f | %.1f | %.3f | %.3f | %.3f | %+.2f | %+.2f | %zu | %d | %.2f | %.2f | %.2f |\n",
                        r.name.c_str(), r.segments, r.nodes, r.spans, r.plan_ms, r.check_ms, r.motion, r.fine,
                        r.optimum, above_fine, above_opt, r.retries, r.replans, 1000 * r.max_deviation,
                        100 * r.v_fraction_exact, 100 * r.a_fraction_exact);
        } else {
            std::printf("%-7s %8zu %9zu %7zu %9.1f %9.1f %9.3f %9.3f %9.3f %+8.2f %+8.2f %7zu %7d %8.2f %8.2f %8.2f\n",
                        r.name.c_str(), r.segments, r.nodes, r.spans, r.plan_ms, r.check_ms, r.motion, r.fine,
                        r.optimum, above_fine, above_opt, r.retries, r.replans, 1000 * r.max_deviation,
                        100 * r.v_fraction_exact, 100 * r.a_fraction_exact);
        }
    }
    std::printf("\ncheck (exact cubic and every tick within limits, no motion in pen dwells, deviation <= tolerance + "
                "%.2f um): %s\n",
                1000 * quantisation, ok ? "passed" : "FAILED");
    return ok ? 0 : 1;
}
