// With a per-axis max_jerk, every span the planner returns meets the jerk rules exactly
// (docs/planner.md §12): the constant third derivative of each Hermite span, and the
// acceleration step at every join (rest before the first span and after the last one
// included), each within one tick of jerk. Checked here from the spans' integer control values
// alone, independently of the planner, together with the velocity and acceleration limits and
// check_plan's per-tick figures.
//
// Random cases: PATHSTREAM_JERK_CASES (default 3) paths, seed PATHSTREAM_PLAN_SEED (default 1).
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdlib>
#include <random>
#include <string>

#include "pathstream/host/csv_path.hpp"
#include "pathstream/host/gcode_path.hpp"
#include "pathstream/host/geometry.hpp"
#include "pathstream/host/json_path.hpp"
#include "pathstream/host/planner.hpp"
#include "pathstream/host/svg_path.hpp"
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

/// The worst figures of a plan against the jerk rules, as fractions of J (LSB/tick^3).
struct JerkFigures {
    double inside = 0;                      ///< |6 (2 P0 - 2 P1 + T0 + T1)| / n^3 over J
    double join = 0;                        ///< |a_start(next) - a_end(previous)| over J
    double velocity = 0, acceleration = 0;  ///< exact span peaks over the limits
};

JerkFigures jerk_figures(const Plan& plan, const MachineProfile& p) {
    JerkFigures f;
    const double t = 1 / p.tick_hz;
    const std::size_t axes = p.axes.size();
    std::vector<long double> a_end(axes, 0.0L);  // rest before the first span
    for (const CoreSpan& s : plan.spans) {
        REQUIRE(s.basis == pathstream::Basis::kHermite);
        const long double n = s.ticks;
        for (std::size_t i = 0; i < axes; ++i) {
            const auto& c = s.control[i];
            const long double p0 = c[0], p1 = c[1], t0 = c[2], t1 = c[3];
            const long double j = p.axes[i].max_jerk * t * t * t / p.mm_per_lsb;
            const long double third = 6 * (2 * p0 - 2 * p1 + t0 + t1) / (n * n * n);
            const long double start = (6 * (p1 - p0) - 4 * t0 - 2 * t1) / (n * n);
            const long double end = (-6 * (p1 - p0) + 2 * t0 + 4 * t1) / (n * n);
            f.inside = std::max(f.inside, static_cast<double>(std::fabs(third) / j));
            f.join = std::max(f.join, static_cast<double>(std::fabs(start - a_end[i]) / j));
            a_end[i] = end;
            const double a_lim = p.axes[i].max_acceleration * t * t / p.mm_per_lsb;
            const double v_lim = p.axes[i].max_velocity * t / p.mm_per_lsb;
            f.acceleration =
                std::max(f.acceleration,
                         static_cast<double>(std::max(std::fabs(start), std::fabs(end))) / a_lim);
            const double a0 = static_cast<double>(start * n * n),
                         a1 = static_cast<double>(end * n * n);
            const auto v = [&](double u) {
                return std::fabs(static_cast<double>(t0) + a0 * u + (a1 - a0) * u * u / 2) /
                       static_cast<double>(n) / v_lim;
            };
            for (int k = 0; k <= 16; ++k) f.velocity = std::max(f.velocity, v(k / 16.0));
            if (a0 * a1 < 0) f.velocity = std::max(f.velocity, v(a0 / (a0 - a1)));
        }
    }
    for (std::size_t i = 0; i < axes; ++i) {  // rest after the last span
        const long double j = p.axes[i].max_jerk * t * t * t / p.mm_per_lsb;
        f.join = std::max(f.join, static_cast<double>(std::fabs(a_end[i]) / j));
    }
    return f;
}

/// Plans with the jerk limit and requires every rule and every other limit; returns the plan.
Plan plan_with_jerk(const Path& path, const MachineProfile& p, PlanStats* stats = nullptr) {
    const auto segs = to_bezier_segments(path);
    PlanStats local;
    const Plan plan = plan_path(segs, p, PlanOptions{}, stats != nullptr ? stats : &local);
    const JerkFigures f = jerk_figures(plan, p);
    CHECK(f.inside <= 1.0);
    CHECK(f.join <= 1.0);
    CHECK(f.velocity <= 1.0);
    CHECK(f.acceleration <= 1.0);
    const PlanCheck c = check_plan(plan, segs, p);
    CHECK(c.within_limits);
    CHECK_FALSE(c.drawing_while_pen_moves);
    CHECK(c.max_feed_fraction <= 1.0);
    CHECK(c.max_deviation <=
          p.chord_tolerance + 1.5 * std::sqrt(static_cast<double>(p.axes.size())) * p.mm_per_lsb);
    return plan;
}

MachineProfile profile(double v, double a, double j, std::size_t axes) {
    MachineProfile p;
    for (std::size_t i = 0; i < axes; ++i) {
        AxisLimits l;
        l.name = std::string(1, static_cast<char>('x' + i));
        l.max_velocity = v;
        l.max_acceleration = a;
        l.max_jerk = j;
        p.axes.push_back(l);
    }
    p.feed = 80;
    p.travel_feed = 200;
    return p;
}

MachineProfile pen_plotter(double jerk) {
    MachineProfile p = load_machine_profile(source_dir() + "/examples/machines/pen_plotter.json");
    for (auto& a : p.axes) a.max_jerk = jerk;
    return p;
}

Path line(std::vector<PathPoint> points, std::size_t axes) {
    Path path;
    path.axes = axes;
    Subpath s;
    s.basis = PathBasis::kPolyline;
    s.points = std::move(points);
    path.subpaths = {s};
    return path;
}

/// Time of the jerk-limited S-curve from rest to rest over `d` (v, a, j reached or not).
double s_curve_time(double d, double v, double a, double j) {
    // Accelerating to speed w takes w/a + a/j when a is reached (w >= a^2/j), else 2 sqrt(w/j);
    // the distance covered meanwhile is w times half of that. Bisect the top speed.
    const auto ramp_time = [&](double w) {
        return w >= a * a / j ? w / a + a / j : 2 * std::sqrt(w / j);
    };
    double lo = 0, hi = v;
    if (ramp_time(v) * v > d) {
        for (int it = 0; it < 200; ++it) {
            const double w = 0.5 * (lo + hi);
            (ramp_time(w) * w > d ? hi : lo) = w;
        }
        return 2 * ramp_time(lo);
    }
    return 2 * ramp_time(v) + (d - ramp_time(v) * v) / v;
}

}  // namespace

TEST_CASE("jerk: a straight line is near the analytic S-curve time", "[planner][jerk]") {
    for (const double j : {1e5, 1e6}) {
        INFO("max_jerk " << j);
        const MachineProfile p = pen_plotter(j);
        PlanStats st;
        plan_with_jerk(line({{0, 0}, {100, 0}}, 2), p, &st);
        const double time = static_cast<double>(st.motion_ticks) / p.tick_hz;
        const double best = s_curve_time(100, p.feed * 0.999, 3000, j);
        CHECK(time >= best * 0.999);
        CHECK(time <= best * 1.06);
        CHECK(st.jerk_filter_ticks > 0);
        // One piece: the filter's length plus the rest up to a whole span.
        CHECK(st.jerk_added_ticks >= st.jerk_filter_ticks);
        CHECK(st.jerk_added_ticks < st.jerk_filter_ticks + 4 * st.ticks_per_span);
    }
}

TEST_CASE("jerk: a circle and the examples on the pen plotter", "[planner][jerk]") {
    const std::string ex = source_dir() + "/examples/";
    const MachineProfile p = pen_plotter(1e5);
    SECTION("circle") {
        Path path;
        path.axes = 2;
        Subpath s;
        s.basis = PathBasis::kBSpline;
        s.closed = true;
        for (int i = 0; i < 48; ++i) {
            const double t = 2 * kPi * i / 48;
            s.points.push_back({20 * std::cos(t), 20 * std::sin(t)});
        }
        path.subpaths = {s};
        plan_with_jerk(path, p);
    }
    SECTION("rose.json") {
        plan_with_jerk(load_json_path(ex + "rose.json"), p);
    }
    SECTION("wave.json") {
        plan_with_jerk(load_json_path(ex + "wave.json"), p);
    }
    SECTION("landscape.svg") {
        plan_with_jerk(load_svg_path(ex + "landscape.svg"), p);
    }
    SECTION("two_pens.svg") {
        plan_with_jerk(load_svg_path(ex + "two_pens.svg"), p);
    }
    SECTION("leaf.ngc") {
        plan_with_jerk(load_gcode_path(ex + "leaf.ngc"), p);
    }
    SECTION("star.csv, a closed polyline with blended corners") {
        plan_with_jerk(load_csv_path(ex + "star.csv", PathBasis::kPolyline, true),
                       pen_plotter(1e6));
    }
}

TEST_CASE("jerk: from rest to rest on one axis and on three", "[planner][jerk]") {
    SECTION("one axis") {
        plan_with_jerk(line({{0}, {30}, {10}, {10.5}}, 1), profile(100, 2000, 5e4, 1));
    }
    SECTION("three axes") {
        Path path;
        path.axes = 3;
        Subpath h;
        h.basis = PathBasis::kBSpline;
        for (int i = 0; i <= 60; ++i) {
            const double t = 2 * kPi * i / 40.0;
            h.points.push_back({10 * std::cos(t), 10 * std::sin(t), 0.5 * t});
        }
        path.subpaths = {h};
        plan_with_jerk(path, profile(250, 3000, 2e5, 3));
    }
}

TEST_CASE("jerk: seeded random walks", "[planner][jerk]") {
    const char* env_cases = std::getenv("PATHSTREAM_JERK_CASES");
    const char* env_seed = std::getenv("PATHSTREAM_PLAN_SEED");
    const int cases = env_cases != nullptr ? std::atoi(env_cases) : 3;
    const unsigned long seed = env_seed != nullptr ? std::strtoul(env_seed, nullptr, 10) : 1;
    std::mt19937_64 rng(seed ^ 0x1e4cULL);
    std::uniform_real_distribution<double> unit(0, 1);
    for (int c = 0; c < cases; ++c) {
        const std::size_t axes = 1 + rng() % 3;
        const double jerk = std::exp(std::log(3e4) + unit(rng) * std::log(100.0));
        MachineProfile p = profile(250, 3000, jerk, axes);
        Path path;
        path.axes = axes;
        Subpath s;
        s.basis = c % 2 == 0 ? PathBasis::kBSpline : PathBasis::kPolyline;
        PathPoint q(axes, 0.0);
        for (int i = 0; i < 40; ++i) {
            for (auto& x : q) x += 6 * (unit(rng) - 0.5);
            s.points.push_back(q);
        }
        path.subpaths = {s};
        INFO("case " << c << " seed " << seed << ": " << axes << " axes, max_jerk " << jerk);
        try {
            plan_with_jerk(path, p);
        } catch (const PlanError& e) {
            FAIL_CHECK("planning failed: " << e.what());
        }
    }
}

TEST_CASE("jerk: max_jerk 0 leaves the plan as it was", "[planner][jerk]") {
    // rose.json read as is (no ordering): 16,052 ticks of motion before the jerk stage existed,
    // 16,051 since a landing's first span may be shorter than a regular one (docs/planner.md §5,
    // which a jerk limit does not use).
    MachineProfile p = pen_plotter(0);
    const auto segs = to_bezier_segments(load_json_path(source_dir() + "/examples/rose.json"));
    PlanStats st;
    const Plan plan = plan_path(segs, p, PlanOptions{}, &st);
    CHECK(st.motion_ticks == 16051);
    CHECK(st.jerk_filter_ticks == 0);
    CHECK(st.ticks_per_span == 8);
    // ...and with a jerk limit the motion changes (the test above can fail).
    p.axes[0].max_jerk = 1e5;
    PlanStats limited;
    plan_path(segs, p, PlanOptions{}, &limited);
    CHECK(limited.motion_ticks > st.motion_ticks);
}

TEST_CASE("jerk: a limit too low for the profile is refused with its axis", "[planner][jerk]") {
    MachineProfile p = pen_plotter(1e5);
    p.source = "plotter.json";
    p.axes[1].max_jerk = 100;
    const auto segs = to_bezier_segments(line({{0, 0}, {10, 0}}, 2));
    try {
        plan_path(segs, p);
        FAIL("no PlanError");
    } catch (const PlanError& e) {
        const std::string m = e.what();
        CHECK(m.find("plotter.json") != std::string::npos);
        CHECK(m.find("axis y") != std::string::npos);
        CHECK(m.find("max_jerk 100") != std::string::npos);
    }
}

TEST_CASE("jerk: windows of 16 segments carry the filter across their joints", "[planner][jerk]") {
    // A smooth random walk of 200 B-spline segments is one piece: planned in windows of 16,
    // the jerk stage's filter and knots continue across every window's cut.
    const MachineProfile p = pen_plotter(1e6);
    Path path;
    path.axes = 2;
    Subpath s;
    std::mt19937_64 rng(5);
    std::normal_distribution<double> turn(0, 0.25);
    double x = 0, y = 0, heading = 0;
    for (int i = 0; i < 201; ++i) {
        s.points.push_back({x, y});
        heading += turn(rng);
        x += 1.5 * std::cos(heading);
        y += 1.5 * std::sin(heading);
    }
    path.subpaths = {s};
    const auto segs = to_bezier_segments(path);
    PlanOptions small;
    small.window_segments = 16;
    PlanStats st;
    const Plan windowed = plan_path(segs, p, small, &st);
    const JerkFigures f = jerk_figures(windowed, p);
    CHECK(f.inside <= 1.0);
    CHECK(f.join <= 1.0);
    CHECK(f.velocity <= 1.0);
    CHECK(f.acceleration <= 1.0);
    const PlanCheck c = check_plan(windowed, segs, p);
    CHECK(c.within_limits);
    CHECK(c.max_deviation <= p.chord_tolerance + 1.5 * std::sqrt(2.0) * p.mm_per_lsb);
    // The same motion as the plan of one window.
    PlanStats whole;
    plan_path(segs, p, PlanOptions{}, &whole);
    CHECK(st.motion_ticks == whole.motion_ticks);
}
