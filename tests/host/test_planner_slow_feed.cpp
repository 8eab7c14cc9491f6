// Feeds far below one LSB per tick (docs/planner.md, "Very slow feeds"): LinuxCNC's
// good-arc programs at F1 (1 mm/min: 0.017 um per tick on the pen plotter's 1 um LSB at
// 1 kHz; tests/data/gcode/arc_f1_*.ngc) and seeded slow feeds from 0.1 to 10 mm/min on short
// lines, corners and arcs, each planned and checked tick by tick: within the limits and the
// chord tolerance, never faster than the feed, and not much slower.
//
// Random cases: PATHSTREAM_SLOW_FEED_CASES (default 12), seed PATHSTREAM_PLAN_SEED (default 1).
// The 2 m and 6 m arcs move for 52 and 157 hours (190 and 570 million ticks, minutes of
// checking): a hidden test, host_tests "[slow_feed_long]".
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <sstream>
#include <string>

#include "pathstream/host/gcode_path.hpp"
#include "pathstream/host/geometry.hpp"
#include "pathstream/host/planner.hpp"
#include "pathstream/machine/machine.hpp"

using namespace pathstream::host;

namespace {

constexpr double kPi = 3.14159265358979323846;

std::string source_dir() {
#ifdef PATHSTREAM_SOURCE_DIR
    return PATHSTREAM_SOURCE_DIR;
#else
    return ".";
#endif
}

MachineProfile pen_plotter() {
    return load_machine_profile(source_dir() + "/examples/machines/pen_plotter.json");
}

/// Plans a one-subpath drawing that starts at the origin (no travel), checks every tick and
/// requires the limits, the tolerance, and a motion time between the drawn length at the feed
/// (less an LSB per axis at both ends, where the path's ends are rounded onto the grid) and
/// 1 % plus six spans of the slow feed's length (8 LSB each) more.
PlanCheck plan_slow(const Path& path, const MachineProfile& p) {
    REQUIRE(path.subpaths.size() == 1);
    const double feed = path.subpaths[0].feed;
    REQUIRE(feed > 0);
    const auto segs = to_bezier_segments(path);
    PlanStats stats;
    const Plan plan = plan_path(segs, p, PlanOptions{}, &stats);
    const PlanCheck c = check_plan(plan, segs, p);
    const double motion = static_cast<double>(stats.motion_ticks) / p.tick_hz;
    const double lsb = p.mm_per_lsb * std::sqrt(static_cast<double>(p.axes.size()));
    INFO("feed " << feed * 60 << " mm/min, " << plan.path_length << " mm, motion " << motion
                 << " s, " << plan.spans.size() << " spans");
    CHECK(c.within_limits);
    CHECK_FALSE(c.drawing_while_pen_moves);
    CHECK(c.max_deviation <= p.chord_tolerance);
    CHECK(plan.travel_length < 1e-9);
    CHECK(motion >= (plan.path_length - 2 * lsb) / feed);
    CHECK(motion <= 1.01 * plan.path_length / feed + 6 * 8 * p.mm_per_lsb / feed);
    return c;
}

std::string fixed(double x) {
    char b[64];
    std::snprintf(b, sizeof b, "%.6f", x);
    return b;
}

}  // namespace

TEST_CASE("slow feed: LinuxCNC's small off-radius arc at F1 plans within the limits",
          "[planner][slow_feed]") {
    // 78.5 mm at 1 mm/min: 79 minutes, 4.7 million ticks; 0.017 um per tick.
    const Path path = load_gcode_path(source_dir() + "/tests/data/gcode/arc_f1_small.ngc");
    const PlanCheck c = plan_slow(path, pen_plotter());
    CHECK(c.max_deviation < 0.002);
}

TEST_CASE("slow feed: LinuxCNC's medium and big off-radius arcs at F1 plan within the limits",
          "[.][slow_feed_long]") {
    const MachineProfile p = pen_plotter();
    SECTION("medium, 2 m across") {
        plan_slow(load_gcode_path(source_dir() + "/tests/data/gcode/arc_f1_medium.ngc"), p);
    }
    SECTION("big, 6 m across") {
        plan_slow(load_gcode_path(source_dir() + "/tests/data/gcode/arc_f1_big.ngc"), p);
    }
}

TEST_CASE("slow feed: seeded lines, corners and arcs from 0.1 to 10 mm/min",
          "[planner][slow_feed][property]") {
    const char* env_cases = std::getenv("PATHSTREAM_SLOW_FEED_CASES");
    const char* env_seed = std::getenv("PATHSTREAM_PLAN_SEED");
    const int cases = env_cases != nullptr ? std::atoi(env_cases) : 12;
    const unsigned seed = env_seed != nullptr ? static_cast<unsigned>(std::atoi(env_seed)) : 1;
    const MachineProfile p = pen_plotter();
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> unit(0, 1);
    for (int i = 0; i < cases; ++i) {
        // Log-uniform feeds; at most ~150 s of motion (150,000 ticks) per case.
        const double feed_mm_min = std::pow(10.0, -1 + 2 * unit(rng));
        const double budget_mm = std::min(2.0, feed_mm_min / 60 * 150);
        std::ostringstream g;
        g << "G21 G90\nF" << fixed(feed_mm_min) << "\nG0 X0 Y0 Z0\n";
        const int kind = static_cast<int>(rng() % 4);
        const double heading = 2 * kPi * unit(rng);
        if (kind == 0) {  // a line
            const double len = budget_mm * (0.1 + 0.9 * unit(rng));
            g << "G1 X" << fixed(len * std::cos(heading)) << " Y" << fixed(len * std::sin(heading))
              << "\n";
        } else if (kind == 1) {  // two or three lines, corners shallow to sharp (stops)
            const int lines = 2 + static_cast<int>(rng() % 2);
            double x = 0, y = 0, h = heading;
            for (int k = 0; k < lines; ++k) {
                const double len = budget_mm / lines * (0.2 + 0.8 * unit(rng));
                x += len * std::cos(h);
                y += len * std::sin(h);
                g << "G1 X" << fixed(x) << " Y" << fixed(y) << "\n";
                h += (unit(rng) < 0.5 ? -1 : 1) * (0.05 + 2.5 * unit(rng));
            }
        } else {  // an arc (kind 2) or an off-radius one, a spiral (kind 3)
            const double sweep = 0.3 + 4.7 * unit(rng);
            const double r =
                std::max(0.02, std::min(2.0, budget_mm * (0.2 + 0.8 * unit(rng)) / sweep));
            const bool ccw = unit(rng) < 0.5;
            const double cx = -r * std::cos(heading), cy = -r * std::sin(heading);
            const double end_angle = heading + (ccw ? sweep : -sweep);
            const double r1 = kind == 3 ? r + (unit(rng) - 0.5) * std::min(0.02, 0.3 * r) : r;
            g << (ccw ? "G3" : "G2") << " X" << fixed(cx + r1 * std::cos(end_angle)) << " Y"
              << fixed(cy + r1 * std::sin(end_angle)) << " I" << fixed(cx) << " J" << fixed(cy)
              << "\n";
        }
        g << "M2\n";
        INFO("seed " << seed << " case " << i << ":\n" << g.str());
        const Path path = parse_gcode_path(g.str(), "slow.ngc");
        plan_slow(path, p);
    }
}
