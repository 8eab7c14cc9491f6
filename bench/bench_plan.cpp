// bench_plan: how long does planning a drawing take, how close to the time-optimal motion is the
// plan the device executes, how does it compare with a grbl-style and a Klipper-style planner on
// the same limits, and how do planning time and memory grow with the job?
//
// Machine: examples/machines/pen_plotter.json's values (250 mm/s, 3000 mm/s^2 per axis, 1 kHz,
// 8 ticks per span, 1 um LSB, feed 80 mm/s, chord tolerance 5 um); the examples are planned on
// that file itself, read as the CLI reads it.
//
// 1. Grid table: three 2-axis drawings of --segments Bezier segments (default 10,000) --
//    rose (closed B-spline, 7 petals), wander (open B-spline random walk), spiral (polyline,
//    every vertex a small corner; plan_paths.hpp):
//    * plan       : plan_path with the default options; wall time best of --runs (3) runs;
//    * fine       : the same planner on a --density (16) times denser lookahead grid (grid step
//                   and min nodes per segment x density, max turn / 4): the planner's own
//                   converged figure;
//    * optimum    : the continuous time-optimal profile (TOPP-RA forward pass, piecewise
//                   constant path acceleration, full limits, no margins, no whole ticks) on that
//                   dense grid: an independent lower bound of what any plan of this path can do.
//    "motion" is the executed motion time (span ticks / tick_hz, pen dwells excluded).
// 2. Peer table (peer_comparison.hpp): the 1k and 10k spiral, random polylines with sharp
//    (0.5-2.5 rad) and shallow (0.05-0.3 rad) corners, the random walk, the rose and every
//    drawing in examples/, planned by pathstream and by the reference planners of
//    bench/reference_planners/ (grbl-style junction deviation, Klipper-style square corner
//    velocity), each on its own junction rule and held to the per-tick limits (no junction
//    stepping an axis's velocity by more than a T); pathstream's motion time over theirs, its
//    continuous optimum, and the peers' largest per-tick velocity step and acceleration
//    sampled from their own profiles.
// 3. --scaling (plan_scaling.hpp): 1k, 10k, 100k, 1M-point random walks, each planned in a
//    forked child with a wall-time limit: time per segment, its ratio to 1k, peak RSS, load.
// Every pathstream plan goes through check_plan (every tick, the core's setpoints): within the
// limits, no motion during pen dwells, deviation within the chord tolerance plus 1.5 sqrt(2)
// LSB. Timings, motion-time ratios and the targets' tallies are printed, never judged.
//
// Usage: bench_plan [--quick] [--segments N] [--density D] [--runs R] [--no-peers] [--markdown]
//        bench_plan --scaling [--max-segments N] [--timeout S] [--markdown]
//        bench_plan --jerk [--segments N] [--markdown]
//        bench_plan --self-test
// Exit status (also printed by --help): 0 every plan passed its check (and the peers are
// self-consistent); 1 a plan failed its check or could not be made, a peer's result is
// inconsistent (or a held peer steps an axis's velocity by more than a T at a junction), or a
// self-test check failed; 2 usage error.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "cli_scaling.hpp"
#include "pathstream/host/geometry.hpp"
#include "pathstream/host/planner.hpp"
#include "peer_comparison.hpp"
#include "plan_paths.hpp"
#include "plan_scaling.hpp"
#include "reference_planners/self_test.hpp"

using namespace pathstream::host;
using namespace pathstream::bench;

namespace {

#ifdef PATHSTREAM_SOURCE_DIR
const std::string kSource = PATHSTREAM_SOURCE_DIR;
#else
const std::string kSource = ".";
#endif

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

/// The load averages, as /proc/loadavg has them ("0.54 1.22 1.70").
std::string load_text() {
    std::ifstream in("/proc/loadavg");
    std::string one, five, fifteen;
    in >> one >> five >> fifteen;
    return one + " " + five + " " + fifteen;
}

/// The grid table: plan, fine grid and optimum for three drawings. False if a plan failed.
bool run_grid_table(std::size_t segments, double density, int runs, bool markdown,
                    const MachineProfile& profile) {
    const PlanOptions options;
    PlanOptions fine = options;
    fine.grid_step /= density;
    fine.min_nodes_per_segment =
        static_cast<std::size_t>(std::ceil(options.min_nodes_per_segment * density));
    fine.max_turn /= 4;
    const double quantisation = 1.5 * std::sqrt(2.0) * profile.mm_per_lsb;

    struct Named {
        const char* name;
        Path path;
    };
    const Named paths[] = {{"rose", rose_path(segments)},
                           {"wander", wander_path(segments)},
                           {"spiral", spiral_path(segments)}};
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
            row.v_fraction_exact =
                std::max(check.max_velocity_fraction_exact, check.max_span_velocity_fraction);
            row.a_fraction_exact = std::max(check.max_acceleration_fraction_exact,
                                            check.max_span_acceleration_fraction);
            if (!check.within_limits) {
                std::fprintf(stderr, "%s: over the limits (v %.6f, a %.6f of the limit exactly)\n",
                             np.name, row.v_fraction_exact, row.a_fraction_exact);
                ok = false;
            }
            if (check.drawing_while_pen_moves) {
                std::fprintf(stderr, "%s: motion during a pen dwell\n", np.name);
                ok = false;
            }
            if (check.max_deviation > profile.chord_tolerance + quantisation) {
                std::fprintf(stderr, "%s: deviation %.6f mm at tick %llu exceeds %.6f mm\n",
                             np.name, check.max_deviation,
                             static_cast<unsigned long long>(check.worst_deviation_tick),
                             profile.chord_tolerance + quantisation);
                ok = false;
            }
        } catch (const std::exception& e) {
            std::fprintf(stderr, "%s: %s\n", np.name, e.what());
            ok = false;
        }
        rows.push_back(row);
    }

    std::printf(
        "bench_plan: %zu segments per path, pen plotter profile (%g mm/s, %g mm/s^2, %g Hz, %u "
        "ticks/span)\n",
        segments, profile.axes[0].max_velocity, profile.axes[0].max_acceleration, profile.tick_hz,
        profile.ticks_per_span);
    std::printf(
        "fine = same planner, %gx denser lookahead grid; optimum = continuous TOPP-RA on that "
        "grid\n\n",
        density);
    if (markdown) {
        std::printf(
            "| path | segments | grid nodes | spans | plan ms | check ms | motion s | fine s | "
            "optimum s | "
            "%% above fine | %% above optimum | retries | replans | max dev um | v %% exact | a %% "
            "exact |\n");
        std::printf(
            "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    } else {
        std::printf("%-7s %8s %9s %7s %9s %9s %9s %9s %9s %8s %8s %7s %7s %8s %8s %8s\n", "path",
                    "segments", "nodes", "spans", "plan ms", "check ms", "motion s", "fine s",
                    "optim s", "%>fine", "%>optim", "retries", "replans", "dev um", "v % ex",
                    "a % ex");
    }
    for (const Row& r : rows) {
        const double above_fine = r.fine > 0 ? 100 * (r.motion / r.fine - 1) : 0;
        const double above_opt = r.optimum > 0 ? 100 * (r.motion / r.optimum - 1) : 0;
        if (markdown) {
            std::printf(
                "| %s | %zu | %zu | %zu | %.1f | %.1f | %.3f | %.3f | %.3f | %+.2f | %+.2f | %zu | "
                "%d | %.2f | %.2f | %.2f |\n",
                r.name.c_str(), r.segments, r.nodes, r.spans, r.plan_ms, r.check_ms, r.motion,
                r.fine, r.optimum, above_fine, above_opt, r.retries, r.replans,
                1000 * r.max_deviation, 100 * r.v_fraction_exact, 100 * r.a_fraction_exact);
        } else {
            std::printf(
                "%-7s %8zu %9zu %7zu %9.1f %9.1f %9.3f %9.3f %9.3f %+8.2f %+8.2f %7zu %7d %8.2f "
                "%8.2f %8.2f\n",
                r.name.c_str(), r.segments, r.nodes, r.spans, r.plan_ms, r.check_ms, r.motion,
                r.fine, r.optimum, above_fine, above_opt, r.retries, r.replans,
                1000 * r.max_deviation, 100 * r.v_fraction_exact, 100 * r.a_fraction_exact);
        }
    }
    std::printf(
        "\ncheck (exact cubic and every tick within limits, no motion in pen dwells, deviation <= "
        "tolerance + "
        "%.2f um): %s\n",
        1000 * quantisation, ok ? "passed" : "FAILED");
    return ok;
}

/// The peer table. False if a plan failed its check or a peer is inconsistent.
bool run_peer_table(bool quick, bool markdown, const MachineProfile& profile) {
    // Quick (the ctest smoke run): the same kinds of path, a tenth of the size.
    const std::size_t scale = quick ? 10 : 1;
    struct Named {
        std::string name;
        Path path;
    };
    const auto sized = [&](const char* kind, std::size_t n) {
        return std::string(kind) + " " + std::to_string(n / scale);
    };
    std::vector<Named> paths = {
        {sized("spiral", 1000), spiral_path(1000 / scale)},
        {sized("spiral", 10000), spiral_path(10000 / scale)},
        {sized("sharp", 1000), random_polyline(1000 / scale, 0.5, 2.5, 11)},
        {sized("shallow", 1000), random_polyline(1000 / scale, 0.05, 0.3, 12)},
        {sized("wander", 1000), wander_path(1000 / scale)},
        {sized("rose", 1000), rose_path(1000 / scale)},
    };
    std::vector<PeerRow> rows;
    for (const Named& n : paths) rows.push_back(compare_with_peers(n.name, n.path, profile));
    // The examples on the profile file itself, read as `pathstream plan FILE -m ...` reads them.
    MachineProfile plotter = profile;
    try {
        plotter = load_machine_profile(kSource + "/examples/machines/pen_plotter.json");
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bench_plan: %s\n", e.what());
        return false;
    }
    for (const char* file :
         {"landscape.svg", "rose.json", "leaf.ngc", "star.csv", "two_pens.svg", "wave.json"}) {
        try {
            rows.push_back(compare_with_peers(
                file, read_example(kSource + "/examples/" + file, plotter), plotter));
        } catch (const std::exception& e) {
            PeerRow failed;
            failed.name = file;
            failed.problem = e.what();
            rows.push_back(failed);
        }
    }
    print_peer_table(rows, profile, markdown);
    bool ok = true;
    for (const PeerRow& r : rows) {
        if (!r.problem.empty()) {
            std::fprintf(stderr, "bench_plan: %s: %s\n", r.name.c_str(), r.problem.c_str());
            ok = false;
        }
    }
    return ok;
}

/// Worst jerk figures of a plan from its integer control values (docs/planner.md §12), as
/// fractions of the limit: inside the spans and at the joins (rest at both ends).
double jerk_fraction(const Plan& plan, const MachineProfile& p) {
    const double t = 1 / p.tick_hz;
    double worst = 0;
    std::vector<long double> a_end(p.axes.size(), 0.0L);
    for (const CoreSpan& s : plan.spans) {
        const long double n = s.ticks;
        for (std::size_t i = 0; i < p.axes.size(); ++i) {
            const auto& c = s.control[i];
            const long double j = p.axes[i].max_jerk * t * t * t / p.mm_per_lsb;
            const long double dp = static_cast<long double>(c[1]) - c[0];
            const long double third = 6 * (-2 * dp + c[2] + c[3]) / (n * n * n);
            const long double start = (6 * dp - 4 * c[2] - 2 * c[3]) / (n * n);
            worst = std::max(
                worst,
                static_cast<double>(std::max(std::fabs(third), std::fabs(start - a_end[i])) / j));
            a_end[i] = (-6 * dp + 2 * c[2] + 4 * c[3]) / (n * n);
        }
    }
    for (std::size_t i = 0; i < p.axes.size(); ++i) {
        const long double j = p.axes[i].max_jerk * t * t * t / p.mm_per_lsb;
        worst = std::max(worst, static_cast<double>(std::fabs(a_end[i]) / j));
    }
    return worst;
}

/// The jerk table: motion and planning time with max_jerk 1e5 and 1e6 mm/s^3 on every axis
/// against the plan without a jerk limit, on the grid table's drawings and the examples.
bool run_jerk_table(std::size_t segments, bool markdown, const MachineProfile& profile) {
    struct Named {
        std::string name;
        Path path;
    };
    std::vector<Named> paths = {{"rose " + std::to_string(segments), rose_path(segments)},
                                {"wander " + std::to_string(segments), wander_path(segments)},
                                {"spiral " + std::to_string(segments), spiral_path(segments)}};
    for (const char* f :
         {"rose.json", "wave.json", "landscape.svg", "leaf.ngc", "star.csv", "two_pens.svg"}) {
        paths.push_back({f, read_example(kSource + "/examples/" + f, profile)});
    }
    const double jerks[] = {1e5, 1e6};
    std::printf("\n%s",
                markdown
                    ? "| path | segments | motion s | plan ms | motion s, j 1e5 | % | plan ms | j "
                      "% | replans | "
                      "motion s, j 1e6 | % | plan ms | j % | replans |\n"
                      "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n"
                    : "path               segments  motion s   plan ms  | j=1e5: motion s        % "
                      "  plan ms     j %  r "
                      "| j=1e6: motion s        %   plan ms     j %  r\n");
    bool ok = true;
    for (const Named& np : paths) {
        const std::vector<BezierSegment> segs = to_bezier_segments(np.path);
        double base = 0;
        std::string line;
        char cell[200];
        for (int k = -1; k < 2; ++k) {
            MachineProfile p = profile;
            for (auto& a : p.axes) a.max_jerk = k < 0 ? 0 : jerks[k];
            try {
                PlanStats st;
                const auto t0 = std::chrono::steady_clock::now();
                const Plan plan = plan_path(segs, p, PlanOptions{}, &st);
                const double ms = ms_since(t0);
                const double motion = static_cast<double>(st.motion_ticks) / p.tick_hz;
                const PlanCheck check = check_plan(plan, segs, p);
                const bool passed =
                    check.within_limits && !check.drawing_while_pen_moves &&
                    check.max_deviation <= p.chord_tolerance + 1.5 * std::sqrt(2.0) * p.mm_per_lsb;
                if (k < 0) {
                    base = motion;
                    std::snprintf(
                        cell, sizeof cell,
                        markdown ? "| %s | %zu | %.3f | %.1f " : "%-18s %8zu %9.3f %9.1f ",
                        np.name.c_str(), segs.size(), motion, ms);
                } else {
                    const double jf = jerk_fraction(plan, p);
                    std::snprintf(cell, sizeof cell,
                                  markdown ? "| %.3f | %+.2f | %.1f | %.1f | %d "
                                           : "| %15.3f %+8.2f %9.1f %7.1f %2d ",
                                  motion, 100 * (motion / base - 1), ms, 100 * jf, st.replans);
                    if (jf > 1) ok = false;
                }
                if (!passed) ok = false;
                line += cell;
                if (!passed) {
                    char why[160];
                    std::snprintf(why, sizeof why, "(check FAILED: v %.3f a %.3f dev %.4f mm) ",
                                  std::max(check.max_velocity_fraction_exact,
                                           check.max_span_velocity_fraction),
                                  std::max(check.max_acceleration_fraction_exact,
                                           check.max_span_acceleration_fraction),
                                  check.max_deviation);
                    line += why;
                }
            } catch (const std::exception& e) {
                line += std::string("| ") + e.what() + " ";
                ok = false;
            }
        }
        std::printf("%s%s\n", line.c_str(), markdown ? "|" : "");
    }
    return ok;
}
}  // namespace

constexpr const char* kUsageText =
    "usage: bench_plan [--quick] [--segments N] [--density D] [--runs R] [--no-peers] "
    "[--markdown]\n"
    "       bench_plan --scaling [--max-segments N] [--timeout S] [--markdown]\n"
    "       bench_plan --jerk [--segments N] [--markdown]\n"
    "       bench_plan --self-test\n"
    "  Plans three 2-axis drawings (rose, wander, spiral) of N segments (default 10000) for the "
    "pen\n"
    "  plotter and prints planning time, motion time against the same planner on a D times denser\n"
    "  grid (default 16) and the continuous optimum, and the check of every executed tick; then\n"
    "  the peer table: pathstream's motion time against grbl-style and Klipper-style reference\n"
    "  planners on spirals, random polylines, a random walk, a rose and the examples, each peer\n"
    "  on its own junction rule and held to one tick of acceleration per junction, with the\n"
    "  peers' largest per-tick velocity step and acceleration.\n"
    "  --quick          1000 segments, one run, peer paths a tenth the size (the ctest smoke run)\n"
    "  --segments N     segments per path of the grid table (>= 10)\n"
    "  --density D      the denser grid's factor (>= 1)\n"
    "  --runs R         planning runs per path, best time kept (default 3)\n"
    "  --no-peers       the grid table only\n"
    "  --markdown       the tables in Markdown\n"
    "  --scaling        planning time and peak memory of 1k, 10k, 100k and 1M-point random walks,\n"
    "                   each in its own process; then the same walks as files through\n"
    "                   `pathstream plan` and `pathstream sim` (these tables only)\n"
    "  --max-segments N largest scaling size (default 1000000)\n"
    "  --timeout S      wall seconds a scaling size may take (default 300)\n"
    "  --jerk           the cost of a jerk limit: motion and planning time with max_jerk 1e5 and\n"
    "                   1e6 mm/s^3 against none, on the grid table's drawings (N segments, "
    "default\n"
    "                   1000 here) and the examples, each plan checked (this table only)\n"
    "  --self-test      the reference planners against closed-form answers\n"
    "targets (independent of the machine's speed): every plan within the limits for its exact\n"
    "cubic and every tick, no motion during a pen dwell, deviation within the chord tolerance "
    "plus\n"
    "1.5 sqrt(2) LSB; the peers' results self-consistent. Times and ratios are printed, never "
    "judged.\n"
    "exit status: 0 every plan passed; 1 a plan failed its check or could not be made, a peer's\n"
    "result is inconsistent (or a held peer steps an axis by more than a T at a junction), a\n"
    "scaling size failed to plan, or a self-test check failed; 2 usage error.\n";

int main(int argc, char** argv) {
    std::size_t segments = 10000;
    double density = 16;
    int runs = 3;
    bool markdown = false, quick = false, peers = true, scaling = false, self_test = false,
         jerk = false;
    bool segments_given = false;
    ScalingOptions scaling_options;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        const bool has_value = i + 1 < argc;
        if (a == "--quick") {
            quick = true;
        } else if (a == "--markdown") {
            markdown = true;
        } else if (a == "--no-peers") {
            peers = false;
        } else if (a == "--scaling") {
            scaling = true;
        } else if (a == "--self-test") {
            self_test = true;
        } else if (a == "--jerk") {
            jerk = true;
        } else if (a == "--segments" && has_value) {
            segments = static_cast<std::size_t>(std::strtoul(argv[++i], nullptr, 10));
            segments_given = true;
        } else if (a == "--max-segments" && has_value) {
            scaling_options.max_segments =
                static_cast<std::size_t>(std::strtoul(argv[++i], nullptr, 10));
        } else if (a == "--timeout" && has_value) {
            scaling_options.timeout_seconds =
                static_cast<unsigned>(std::strtoul(argv[++i], nullptr, 10));
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
    if (segments < 10 || density < 1 || runs < 1 || scaling_options.max_segments < 1000 ||
        scaling_options.timeout_seconds < 1) {
        std::fprintf(
            stderr,
            "bench_plan: --segments >= 10, --density >= 1, --runs >= 1, --max-segments >= 1000, "
            "--timeout >= 1\n");
        return 2;
    }
    if (self_test) return run_reference_self_test() == 0 ? 0 : 1;

    const MachineProfile profile = bench_pen_plotter();
    std::printf("bench_plan: machine load (1, 5, 15 min) at start: %s\n", load_text().c_str());
    bool ok = true;
    if (jerk) {
        ok = run_jerk_table(segments_given ? segments : 1000, markdown, profile);
    } else if (scaling) {
        const std::vector<ScalingRow> rows = run_scaling(scaling_options, profile);
        print_scaling(rows, scaling_options, markdown);
        ok = scaling_passed(rows);
        const std::vector<CliRow> commands = run_cli_scaling(
            scaling_options, PATHSTREAM_CLI, kSource + "/examples/machines/pen_plotter.json");
        print_cli_scaling(commands, rows, markdown);
        ok = cli_scaling_passed(commands) && ok;
    } else {
        ok = run_grid_table(segments, density, runs, markdown, profile);
        if (peers) ok = run_peer_table(quick, markdown, profile) && ok;
    }
    std::printf("\nbench_plan: machine load at end: %s; %s\n", load_text().c_str(),
                ok ? "passed" : "FAILED");
    return ok ? 0 : 1;
}
