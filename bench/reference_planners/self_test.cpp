#include "self_test.hpp"

#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include "grbl_style.hpp"
#include "klipper_style.hpp"
#include "tick_sampling.hpp"

namespace pathstream::bench {

using host::BezierSegment;
using host::MachineProfile;
using host::PathPoint;

namespace {

MachineProfile test_profile() {
    MachineProfile p;
    p.axes = {{"x", 250, 3000}, {"y", 250, 3000}};
    p.tick_hz = 1000;
    p.feed = 80;
    p.travel_feed = 200;
    p.chord_tolerance = 0.005;
    return p;
}

BezierSegment straight(const PathPoint& a, const PathPoint& b, bool pen_down = true,
                       double feed = 0) {
    BezierSegment s;
    s.p[0] = a;
    s.p[3] = b;
    s.p[1] = s.p[2] = a;
    for (std::size_t i = 0; i < a.size(); ++i) {
        s.p[1][i] = a[i] + (b[i] - a[i]) / 3;
        s.p[2][i] = a[i] + 2 * (b[i] - a[i]) / 3;
    }
    s.pen_down = pen_down;
    s.feed = feed;
    return s;
}

struct Checker {
    int failed = 0, run = 0;
    void expect(bool ok, const std::string& what) {
        ++run;
        if (!ok) {
            ++failed;
            std::fprintf(stderr, "self-test FAILED: %s\n", what.c_str());
        }
    }
    void near(double got, double want, double tolerance, const std::string& what) {
        char text[300];
        std::snprintf(text, sizeof text, "%s: got %.12g, expected %.12g (+- %g)", what.c_str(), got,
                      want, tolerance);
        expect(std::fabs(got - want) <= tolerance, text);
    }
};

using Planner = PeerPlan (*)(std::vector<LineMove>, const MachineProfile&);
PeerPlan grbl(std::vector<LineMove> m, const MachineProfile& p) {
    return plan_grbl_style(std::move(m), p);
}
PeerPlan klipper(std::vector<LineMove> m, const MachineProfile& p) {
    return plan_klipper_style(std::move(m), p);
}
PeerPlan grbl_held(std::vector<LineMove> m, const MachineProfile& p) {
    return plan_grbl_style(std::move(m), p, JunctionRule::per_tick);
}
PeerPlan klipper_held(std::vector<LineMove> m, const MachineProfile& p) {
    return plan_klipper_style(std::move(m), p, JunctionRule::per_tick);
}

/// `cruise_ratio`: the share of a lone short move spent cruising (0 for grbl's triangle).
void straight_lines(Checker& c, const char* name, Planner plan, double cruise_ratio) {
    const MachineProfile p = test_profile();
    const std::string n = name;
    // 100 mm along x at 80 mm/s, 3000 mm/s^2: trapezoid L/v + v/a.
    const PeerPlan line = plan(flatten_to_lines({straight({0, 0}, {100, 0})}, p), p);
    c.near(line.motion_time(), 100.0 / 80 + 80.0 / 3000, 1e-9, n + " 100 mm line time");
    c.expect(consistency_problem(line).empty(),
             n + " 100 mm line consistent: " + consistency_problem(line));
    // 1 mm, too short to reach the feed: grbl accelerates over half of it and brakes over the
    // other half (a triangle, peak sqrt(a L) = 54.8 mm/s, time 2 sqrt(L / a)); Klipper's
    // minimum cruise ratio r keeps a share r cruising: peak v^2 = a L (1 - r), time
    // 2 v / a + r L / v.
    const PeerPlan short_line = plan(flatten_to_lines({straight({0, 0}, {0, 1})}, p), p);
    const double peak = std::sqrt(3000 * 1.0 * (1 - cruise_ratio));
    c.near(short_line.motion_time(), 2 * peak / 3000 + cruise_ratio * 1.0 / peak, 1e-9,
           n + " 1 mm short move time");
    // Diagonal at 1000 mm/s requested: each axis at 250 mm/s and 3000 mm/s^2, so along the
    // move 250 sqrt 2 and 3000 sqrt 2.
    const double l = 100 * std::sqrt(2.0), v = 250 * std::sqrt(2.0), a = 3000 * std::sqrt(2.0);
    const PeerPlan diagonal =
        plan(flatten_to_lines({straight({0, 0}, {100, 100}, true, 1000)}, p), p);
    c.near(diagonal.motion_time(), l / v + v / a, 1e-9, n + " diagonal at both axes' limits");
    // Sampled at the tick, a straight line stays within the limits and ends at its end.
    const TickFigures f = sample_at_ticks(line, p);
    c.expect(f.max_acceleration_fraction <= 1 + 1e-6,
             n + " straight line within the acceleration limit per tick");
    c.expect(f.max_velocity_fraction <= 80.0 / 250 + 1e-9,
             n + " straight line within the feed per tick");
    c.near(f.end_error, 0, 1e-9, n + " sampled line ends at its end");
}

void corners(Checker& c) {
    const MachineProfile p = test_profile();
    const std::vector<LineMove> corner =
        flatten_to_lines({straight({0, 0}, {50, 0}), straight({50, 0}, {50, 50})}, p);
    c.expect(corner.size() == 2, "a 90 degree corner is two moves");
    // grbl: v^2 = a_j d sin(45)/(1 - sin(45)), a_j along (-1, 1)/sqrt 2: 3000 sqrt 2.
    const double s = std::sqrt(0.5);
    const double grbl_v = std::sqrt(3000 * std::sqrt(2.0) * 0.01 * s / (1 - s));
    const PeerPlan g = plan_grbl_style(corner, p);
    c.near(g.timed[0].v_exit, grbl_v, 1e-9, "grbl 90 degree junction speed (10.12 mm/s)");
    c.near(g.timed[1].v_entry, grbl_v, 1e-9,
           "grbl 90 degree: the next move enters at the junction speed");
    // Klipper: a 90 degree corner of moves at a_max is crossed at the square corner velocity.
    const PeerPlan k = plan_klipper_style(corner, p);
    c.near(k.timed[0].v_exit, kKlipperSquareCornerVelocity, 1e-9,
           "Klipper 90 degree junction speed (5 mm/s)");
    // Sampled at the tick, x's velocity falls by 5 mm/s at the corner, after braking at 3000
    // mm/s^2 (a T = 3 mm/s per tick at 1 kHz). Two tick averages straddling the corner differ
    // by at least half the jump and at most the jump plus 1.5 a T.
    const TickFigures f = sample_at_ticks(k, p);
    c.expect(f.max_velocity_step >= 2.5 - 1e-9 && f.max_velocity_step <= 5 + 4.5 + 1e-9,
             "Klipper corner: sampled velocity step within [2.5, 9.5] mm/s, got " +
                 std::to_string(f.max_velocity_step));
    c.expect(f.max_acceleration_fraction > 1,
             "Klipper corner: over the acceleration limit at the tick");
    // A reversal stops both.
    const std::vector<LineMove> back =
        flatten_to_lines({straight({0, 0}, {50, 0}), straight({50, 0}, {0, 0})}, p);
    c.near(plan_grbl_style(back, p).timed[0].v_exit, 0, 1e-12, "grbl reversal junction speed");
    c.near(plan_klipper_style(back, p).timed[0].v_exit, 0, 1e-12,
           "Klipper reversal junction speed");
    // Pen-up travel between two strokes: stops before and after, at the travel feed.
    const std::vector<LineMove> strokes = flatten_to_lines(
        {straight({0, 0}, {10, 0}), straight({10, 0}, {20, 0}, false), straight({20, 0}, {30, 0})},
        p);
    c.expect(strokes.size() == 3 && strokes[1].stop_before && strokes[2].stop_before &&
                 strokes[1].feed == 200,
             "pen changes are stops, travel at the travel feed");
    c.near(plan_grbl_style(strokes, p).timed[0].v_exit, 0, 1e-12, "grbl stops at a pen change");
    c.near(plan_klipper_style(strokes, p).timed[1].v_exit, 0, 1e-12,
           "Klipper stops at a pen change");
}

/// A closed polyline through `points` (back to the first), one straight segment per side.
std::vector<LineMove> closed_polyline(const std::vector<PathPoint>& points,
                                      const MachineProfile& p) {
    std::vector<BezierSegment> sides;
    for (std::size_t k = 0; k < points.size(); ++k)
        sides.push_back(straight(points[k], points[(k + 1) % points.size()]));
    return flatten_to_lines(sides, p);
}

/// The held peers (JunctionRule::per_tick) at the corners of `moves`: every junction at
/// `held_speed`, no junction stepping an axis's velocity by more than a T, and the step sampled
/// at the tick within `sampled_bound`; the peers on their own rules step by more than a T.
void held_shape(Checker& c, const std::string& shape, const std::vector<LineMove>& moves,
                double held_speed, double sampled_bound) {
    const MachineProfile p = test_profile();
    const struct {
        const char* name;
        Planner own, held;
    } peers[] = {{"grbl", grbl, grbl_held}, {"Klipper", klipper, klipper_held}};
    for (const auto& peer : peers) {
        const std::string n = std::string("held ") + peer.name + " " + shape;
        const PeerPlan plan = peer.held(moves, p);
        c.expect(consistency_problem(plan).empty(),
                 n + " consistent: " + consistency_problem(plan));
        for (std::size_t k = 0; k + 1 < plan.timed.size(); ++k)
            c.near(plan.timed[k].v_exit, held_speed, 1e-9, n + " junction " + std::to_string(k));
        c.near(max_junction_step_fraction(plan, p), 1, 1e-9,
               n + ": the junctions step an axis by exactly a T");
        const TickFigures f = sample_at_ticks(plan, p);
        c.expect(f.max_velocity_step <= sampled_bound + 1e-9,
                 n + ": sampled velocity step " + std::to_string(f.max_velocity_step) +
                     " mm/s within " + std::to_string(sampled_bound));
        c.expect(max_junction_step_fraction(peer.own(moves, p), p) > 1,
                 std::string(peer.name) + " " + shape + " on its own rule steps by more than a T");
    }
}

/// Closed forms of the per-tick cap, min over axes of a_i T / |to_i - from_i| (a T = 3 mm/s).
/// Sampled at the tick, the second difference straddling a junction at t_j weighs the jump J by
/// s = 1 - |t_j - t_k| / T and the acceleration around it by a triangle of area T, so it is at
/// most J s + a T (1 - s^2 / 2) where the axis brakes at a before the junction and stands after,
/// and J + a T where it runs at a on both sides in the direction of the jump.
void held_corners(Checker& c) {
    const MachineProfile p = test_profile();
    const double a_t = 3000.0 / 1000;
    // Axis-aligned square: at each corner one axis stops (from v to 0) and the other starts,
    // |to_i - from_i| = 1 on both, so the held speed is a T = 3 mm/s (under grbl's 10.12 and
    // Klipper's 5). The stopping axis brakes at a before the corner and stands after it: the
    // sampled step is at most J + a T / 2 = 1.5 a T (s = 1).
    held_shape(c, "square", closed_polyline({{0, 0}, {50, 0}, {50, 50}, {0, 50}}, p), a_t,
               1.5 * a_t);
    // The square turned by 45 degrees: at each corner one axis reverses, from v / sqrt 2 to
    // -v / sqrt 2 (|to_i - from_i| = sqrt 2), so the held speed is a T / sqrt 2 = 2.121 mm/s.
    // That axis brakes at a before the corner and, reversed, speeds up at a after it, both in
    // the direction of the jump: the sampled step is at most J + a T = 2 a T.
    held_shape(c, "diamond", closed_polyline({{0, 0}, {25, 25}, {0, 50}, {-25, 25}}, p),
               a_t / std::sqrt(2.0), 2 * a_t);
}

void flattening(Checker& c) {
    MachineProfile p = test_profile();
    // A quarter circle of radius 20 as one cubic: every chord within the tolerance of it.
    const double k = 0.5522847498 * 20;
    BezierSegment arc;
    arc.p = {PathPoint{20, 0}, PathPoint{20, k}, PathPoint{k, 20}, PathPoint{0, 20}};
    const std::vector<LineMove> moves = flatten_to_lines({arc}, p);
    c.expect(moves.size() > 10, "a quarter circle of 20 mm needs many 5 um chords");
    double worst = 0;
    const std::size_t n = moves.size();
    for (std::size_t j = 0; j < n; ++j) {
        // The chord's midpoint against the cubic at the midpoint parameter (equal steps in u).
        const PathPoint mid =
            host::bezier_point(arc, (static_cast<double>(j) + 0.5) / static_cast<double>(n));
        const double dx = mid[0] - 0.5 * (moves[j].start[0] + moves[j].end[0]);
        const double dy = mid[1] - 0.5 * (moves[j].start[1] + moves[j].end[1]);
        worst = std::max(worst, std::hypot(dx, dy));
    }
    c.expect(worst <= p.chord_tolerance, "every chord's sagitta within the chord tolerance");
    c.expect(worst > 0.25 * p.chord_tolerance, "chords are not needlessly short");
    c.expect(flatten_to_lines({straight({0, 0}, {7, 3})}, p).size() == 1,
             "a straight segment stays one move");
}

void random_polylines(Checker& c) {
    const MachineProfile p = test_profile();
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> turn(-3.1, 3.1), length(0.01, 8);
    for (int path = 0; path < 40; ++path) {
        std::vector<BezierSegment> segs;
        PathPoint at{0, 0};
        double heading = 0;
        for (int k = 0; k < 60; ++k) {
            heading += path % 2 ? turn(rng) : 0.1 * turn(rng);
            const double l = length(rng);
            const PathPoint to{at[0] + l * std::cos(heading), at[1] + l * std::sin(heading)};
            segs.push_back(straight(at, to, k % 17 != 16));
            at = to;
        }
        const std::vector<LineMove> moves = flatten_to_lines(segs, p);
        for (Planner plan : {grbl, klipper, grbl_held, klipper_held}) {
            const PeerPlan result = plan(moves, p);
            const std::string problem = consistency_problem(result);
            c.expect(problem.empty(), "random polyline " + std::to_string(path) + ": " + problem);
            const TickFigures f = sample_at_ticks(result, p);
            c.expect(f.end_error < 1e-9,
                     "random polyline " + std::to_string(path) + " ends at its end");
            if (plan == grbl_held || plan == klipper_held) {
                c.expect(max_junction_step_fraction(result, p) <= 1 + 1e-9,
                         "random polyline " + std::to_string(path) +
                             ": held junctions within one tick of acceleration");
            }
        }
    }
}

}  // namespace

int run_reference_self_test() {
    Checker c;
    straight_lines(c, "grbl", grbl, 0);
    straight_lines(c, "Klipper", klipper, kKlipperMinimumCruiseRatio);
    corners(c);
    held_corners(c);
    flattening(c);
    random_polylines(c);
    std::printf("reference planner self-test: %d of %d checks passed\n", c.run - c.failed, c.run);
    return c.failed;
}

}  // namespace pathstream::bench
