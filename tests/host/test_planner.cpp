// The planner: analytic minimum times, the acceleration-limited circle, stops at corners, pen
// events and dwells, feed, chord tolerance, tiny limits, clear errors, and seeded random paths
// that must pass the per-tick check and stream into the core without a refusal.
//
// Random cases: PATHSTREAM_PLAN_CASES (default 12) paths, seed PATHSTREAM_PLAN_SEED (default 1).
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <random>
#include <string>

#include "pathstream/host/geometry.hpp"
#include "pathstream/host/planner.hpp"
#include "pathstream/setpoint_stream.hpp"
#include "pathstream/span.hpp"

using namespace pathstream::host;

namespace {

constexpr double kPi = 3.14159265358979323846;

MachineProfile profile(double v = 250, double a = 3000, std::size_t axes = 2) {
    MachineProfile p;
    for (std::size_t i = 0; i < axes; ++i)
        p.axes.push_back({std::string(1, static_cast<char>('x' + i)), v, a});
    p.feed = 80;
    p.travel_feed = 200;
    p.pen_down_delay = 0.08;
    p.pen_up_delay = 0.06;
    return p;
}

Subpath polyline(std::vector<PathPoint> pts, bool closed = false) {
    Subpath s;
    s.basis = PathBasis::kPolyline;
    s.points = std::move(pts);
    s.closed = closed;
    return s;
}

Subpath circle(double r, int points, double cx = 0, double cy = 0) {
    Subpath s;
    s.basis = PathBasis::kBSpline;
    s.closed = true;
    // Control points on radius r / (1 - (2 pi / n)^2 / 12)... a uniform B-spline through
    // control points on a circle lies slightly inside it; scale so the curve has radius ~r.
    const double h = 2 * kPi / points;
    const double scale = 3 / (2 + std::cos(h));
    for (int i = 0; i < points; ++i) {
        const double t = h * i;
        s.points.push_back({cx + scale * r * std::cos(t), cy + scale * r * std::sin(t)});
    }
    return s;
}

Path path_of(std::vector<Subpath> subpaths, std::size_t axes = 2) {
    Path p;
    p.axes = axes;
    p.subpaths = std::move(subpaths);
    return p;
}

/// Every span goes into the core's SetpointStream (64 deep), ticking to make room: each push
/// must succeed (the core validates the span and refuses any discontinuity). Returns the
/// setpoints of axes 0 and 1 (2-axis paths only).
std::vector<std::array<pathstream::Lsb, 2>> stream_all(const Plan& plan) {
    std::vector<std::array<pathstream::Lsb, 2>> out;
    if (plan.spans.empty()) return out;
    pathstream::Lsb start[2] = {plan.spans.front().control[0][0], plan.spans.front().control[1][0]};
    auto stream = std::make_unique<pathstream::SetpointStream<2, 64>>(start);
    pathstream::Lsb sp[2];
    std::size_t failures = 0;
    for (const CoreSpan& cs : plan.spans) {
        pathstream::Span<2> s;
        s.basis = cs.basis;
        s.ticks = cs.ticks;
        for (unsigned a = 0; a < 2; ++a) {
            for (unsigned k = 0; k < 4; ++k) s.control[a][k] = cs.control[a][k];
        }
        pathstream::Status st = stream->push(s);
        while (st == pathstream::Status::kQueueFull) {
            (void)stream->tick(sp);
            out.push_back({sp[0], sp[1]});
            st = stream->push(s);
        }
        if (st != pathstream::Status::kOk) ++failures;
    }
    CHECK(failures == 0);
    while (stream->tick(sp) == pathstream::TickState::kMoving) out.push_back({sp[0], sp[1]});
    out.push_back({sp[0], sp[1]});  // the end point, held
    CHECK(out.size() == plan.total_ticks + 1);
    return out;
}

struct Planned {
    Plan plan;
    PlanStats stats;
    PlanCheck check;
};

/// Plans, checks every tick, and requires the checks every plan must pass.
Planned plan_and_check(const Path& path, const MachineProfile& p, const PlanOptions& o = {}) {
    Planned r;
    const auto segs = to_bezier_segments(path);
    r.plan = plan_path(segs, p, o, &r.stats);
    r.check = check_plan(r.plan, segs, p);
    CHECK(r.check.within_limits);
    CHECK_FALSE(r.check.drawing_while_pen_moves);
    CHECK(r.check.max_feed_fraction <= 1.0);
    const double quantisation = 1.5 * std::sqrt(static_cast<double>(p.axes.size())) * p.mm_per_lsb;
    CHECK(r.check.max_deviation <= p.chord_tolerance + quantisation);
    CHECK(r.check.ticks_checked == r.plan.total_ticks + 1);
    std::uint64_t ticks = 0;
    for (const auto& s : r.plan.spans) {
        CHECK(s.basis == pathstream::Basis::kHermite);
        CHECK(s.ticks >= 1);
        ticks += s.ticks;
    }
    CHECK(ticks == r.plan.total_ticks);
    CHECK(r.plan.duration == Approx(static_cast<double>(r.plan.total_ticks) / p.tick_hz));
    return r;
}

double motion_time(const Planned& r, const MachineProfile& p) {
    return static_cast<double>(r.stats.motion_ticks) / p.tick_hz;
}

}  // namespace

TEST_CASE("a straight line takes the analytic minimum time (trapezoid and triangle)", "[planner]") {
    SECTION("trapezoid: cruise at the feed") {
        const MachineProfile p = profile(250, 3000);  // feed 80 mm/s
        const Planned r = plan_and_check(path_of({polyline({{0, 0}, {100, 0}})}), p);
        const double optimum = 100 / 80.0 + 80 / 3000.0;
        CHECK(motion_time(r, p) >= optimum * 0.999);
        CHECK(motion_time(r, p) <= optimum * 1.01);
        stream_all(r.plan);
    }
    SECTION("triangle: never reaches the feed") {
        MachineProfile p = profile(250, 500);
        p.feed = 200;
        const Planned r = plan_and_check(path_of({polyline({{0, 0}, {0, 5}})}), p);
        const double optimum = 2 * std::sqrt(5 / 500.0);
        CHECK(motion_time(r, p) >= optimum * 0.999);
        // 0.5 LSB/tick^2: spans are lengthened to 20 ticks (a n^2 >= 192), and the exact spans
        // nearest the planned ones give up about 1 % of the acceleration; two span landings.
        CHECK(motion_time(r, p) <= optimum * 1.025);
    }
    SECTION("diagonal: each axis at its own limits") {
        MachineProfile p = profile(50, 1000);
        p.feed = 500;
        const Planned r = plan_and_check(path_of({polyline({{0, 0}, {60, 60}})}), p);
        // Along 45 degrees each axis carries 1/sqrt(2) of the path speed and acceleration.
        const double v = 50 * std::sqrt(2.0), a = 1000 * std::sqrt(2.0), len = 60 * std::sqrt(2.0);
        const double optimum = len / v + v / a;
        CHECK(motion_time(r, p) >= optimum * 0.999);
        CHECK(motion_time(r, p) <= optimum * 1.01);
    }
}

TEST_CASE("on a circle the speed is limited by acceleration: v = sqrt(a r)", "[planner]") {
    MachineProfile p = profile(2000, 1000);
    p.feed = 2000;
    const double r = 20;
    const Planned pl = plan_and_check(path_of({circle(r, 360)}), p);
    const auto sp = stream_all(pl.plan);
    // Speed over 4 ticks where the path crosses the y axis (x ~ 0, y ~ +r, mid-circle): the
    // centripetal acceleration is all on y there, so the speed is sqrt(a r) (within margins).
    const double lsb = p.mm_per_lsb, tick = 1 / p.tick_hz;
    const double expected = std::sqrt(1000 * r);
    int seen = 0;
    for (std::size_t k = 2; k + 2 < sp.size(); ++k) {
        const double x = sp[k][0] * lsb, y = sp[k][1] * lsb;
        if (std::fabs(x) > 0.2 || y < 0) continue;
        const double dx = (sp[k + 2][0] - sp[k - 2][0]) * lsb,
                     dy = (sp[k + 2][1] - sp[k - 2][1]) * lsb;
        const double v = std::sqrt(dx * dx + dy * dy) / (4 * tick);
        CHECK(v <= expected * 1.005);
        CHECK(v >= expected * 0.96);
        ++seen;
    }
    CHECK(seen > 0);
    CHECK(pl.check.max_acceleration_fraction_exact > 0.95);  // it does use the acceleration
    // The whole circle within 4 % of the continuous time-optimal profile (TOPP-RA, full limits):
    // at 1 LSB/tick^2 the exact spans (14 ticks) keep a few per cent of the acceleration spare.
    CHECK(motion_time(pl, p) <= pl.stats.reference_motion_time * 1.04);
}

TEST_CASE("a square polyline stops exactly at every corner", "[planner]") {
    const MachineProfile p = profile();
    const Planned r =
        plan_and_check(path_of({polyline({{0, 0}, {20, 0}, {20, 20}, {0, 20}}, true)}), p);
    const std::vector<std::array<int, 2>> corners = {
        {0, 0}, {20000, 0}, {20000, 20000}, {0, 20000}};
    int stops = 0;
    for (std::size_t i = 0; i + 1 < r.plan.spans.size(); ++i) {
        const CoreSpan& s = r.plan.spans[i];
        const std::array<int, 2> end = {s.control[0][1], s.control[1][1]};
        for (const auto& c : corners) {
            if (end != c || !s.pen_down) continue;
            // Arriving at a corner: at rest at the span boundary (end tangent 0, next start 0).
            CHECK(s.control[0][3] == 0);
            CHECK(s.control[1][3] == 0);
            CHECK(r.plan.spans[i + 1].control[0][2] == 0);
            CHECK(r.plan.spans[i + 1].control[1][2] == 0);
            ++stops;
        }
    }
    CHECK(stops >= 4);  // three corners plus the return to the start (then the pen lifts)
    stream_all(r.plan);
}

TEST_CASE("a shallow polyline corner is crossed without stopping, at the corner speed",
          "[planner]") {
    MachineProfile p = profile();
    p.feed = 100;
    // Turns by 0.05 rad (under corner_stop_angle): crossed at the corner rule's speed.
    const double turn = 0.05;
    const Planned r = plan_and_check(
        path_of({polyline({{0, 0}, {30, 0}, {30 + 30 * std::cos(turn), 30 * std::sin(turn)}})}), p);
    for (std::size_t i = 0; i + 1 < r.plan.spans.size(); ++i) {
        const CoreSpan& s = r.plan.spans[i];
        if (s.pen_down && s.control[0][1] > 5000 && s.control[0][1] < 55000) {  // no stop mid-way
            CHECK((s.control[0][3] != 0 || s.control[1][3] != 0));
        }
    }
    // Corner speed: the y velocity jump 0.05 s must stay within one tick of acceleration:
    // s <= a T / |jump_y| = 3000 * 0.001 / sin(0.05) ~ 60 mm/s, and the cut of the corner
    // (<= s T_span |J| / 8) within half the chord tolerance.
    CHECK(r.check.max_deviation <= p.chord_tolerance / 2 + 2 * p.mm_per_lsb);
}

TEST_CASE("pen events: down after arriving, dwell, draw, up, dwell, travel", "[planner]") {
    MachineProfile p = profile();
    p.pen_down_delay = 0.08;
    p.pen_up_delay = 0.06;
    const Path path = path_of({polyline({{0, 0}, {10, 0}}), polyline({{10, 5}, {0, 5}})});
    const Planned r = plan_and_check(path, p);
    REQUIRE(r.plan.pen.size() == 4);
    CHECK(r.plan.pen[0].down);
    CHECK(r.plan.pen[0].tick == 0);  // the pen starts up and goes down at the start point
    CHECK_FALSE(r.plan.pen[1].down);
    CHECK(r.plan.pen[2].down);
    CHECK_FALSE(r.plan.pen[3].down);
    CHECK(r.stats.dwell_ticks == 80 + 60 + 80 + 60);
    const auto sp = stream_all(r.plan);
    const auto at = [&](std::uint64_t t) { return sp[static_cast<std::size_t>(t)]; };
    // Holding still through each pen delay, at the right place.
    const std::array<std::array<int, 2>, 4> where = {
        {{0, 0}, {10000, 0}, {10000, 5000}, {0, 5000}}};
    const std::uint64_t delay[4] = {80, 60, 80, 60};
    for (std::size_t e = 0; e < 4; ++e) {
        for (std::uint64_t t = r.plan.pen[e].tick; t <= r.plan.pen[e].tick + delay[e]; ++t) {
            CHECK(at(t) == where[e]);
        }
    }
    CHECK(r.plan.pen[3].tick + 60 == r.plan.total_ticks);  // the final lift is planned in
    // Span flags: the pen output of every span matches the events; travel is pen-up.
    std::uint64_t tick = 0;
    std::size_t event = 0;
    bool down = false;
    for (const CoreSpan& s : r.plan.spans) {
        while (event < r.plan.pen.size() && r.plan.pen[event].tick <= tick)
            down = r.plan.pen[event++].down;
        CHECK(s.pen_down == down);
        tick += s.ticks;
    }
    CHECK(r.plan.path_length == Approx(20));
    CHECK(r.plan.travel_length == Approx(5));
}

TEST_CASE("the requested feed is honoured, per subpath", "[planner]") {
    MachineProfile p = profile();
    Subpath slow = polyline({{0, 0}, {40, 0}});
    slow.feed = 20;
    Subpath fast = polyline({{40, 10}, {0, 10}});  // profile feed: 80
    const Planned r = plan_and_check(path_of({slow, fast}), p);
    CHECK(r.check.max_feed_fraction <= 1.0);
    CHECK(r.check.max_feed_fraction > 0.95);
    // Drawing time: 40 / 20 + 40 / 80 plus the short ramps; travel at up to 200 mm/s.
    CHECK(motion_time(r, p) > 2.5);
    CHECK(motion_time(r, p) < 2.5 + 0.2);
}

TEST_CASE("the chord tolerance holds on a tight curve", "[planner]") {
    MachineProfile p = profile(1000, 50000);
    p.feed = 1000;
    p.chord_tolerance = 0.002;
    // r = 0.5 mm: the chord cap (2/T) sqrt(2 r d - d^2) ~ 89 mm/s binds before sqrt(a r) = 158.
    const Planned r = plan_and_check(path_of({circle(0.5, 40)}), p);
    CHECK(r.check.max_deviation <= p.chord_tolerance + 1.5 * std::sqrt(2.0) * p.mm_per_lsb);
    CHECK(r.check.max_feed_fraction < 0.2);
}

TEST_CASE("long spans stay on the path", "[planner]") {
    MachineProfile p = profile();
    p.ticks_per_span = 64;
    plan_and_check(path_of({circle(3, 60)}), p);
}

TEST_CASE("tiny limits still plan, impossible input gives a clear error", "[planner]") {
    SECTION("tiny limits") {
        MachineProfile p = profile(0.5, 2);
        const Planned r = plan_and_check(path_of({polyline({{0, 0}, {1, 0.5}})}), p);
        CHECK(r.plan.duration > 2);
        stream_all(r.plan);
    }
    SECTION("coarse resolution: limits below one LSB per tick") {
        MachineProfile p = profile(5, 20);
        p.mm_per_lsb = 0.01;
        p.tick_hz = 5000;
        plan_and_check(path_of({circle(2, 40)}), p);
    }
    SECTION("positions beyond the core's range") {
        const MachineProfile p = profile();
        const auto segs = to_bezier_segments(path_of({polyline({{0, 0}, {200000, 0}})}));
        CHECK_THROWS_WITH(plan_path(segs, p), Catch::Contains("outside the core's range"));
    }
    SECTION("an impossible profile") {
        MachineProfile p = profile();
        p.axes[1].max_acceleration = 0;
        const auto segs = to_bezier_segments(path_of({polyline({{0, 0}, {1, 1}})}));
        CHECK_THROWS_AS(plan_path(segs, p), PlanError);
    }
    SECTION("axes that do not match") {
        const MachineProfile p = profile(250, 3000, 3);
        const auto segs = to_bezier_segments(path_of({polyline({{0, 0}, {1, 1}})}));
        CHECK_THROWS_WITH(plan_path(segs, p), Catch::Contains("axes"));
    }
    SECTION("a discontinuous segment list") {
        auto segs = to_bezier_segments(path_of({polyline({{0, 0}, {1, 0}, {2, 0}})}));
        segs[1].p[0] = {1, 1};
        CHECK_THROWS_WITH(plan_path(segs, profile()), Catch::Contains("continuous"));
    }
    SECTION("nothing to plan") {
        const Plan plan = plan_path({}, profile());
        CHECK(plan.spans.empty());
        CHECK(plan.total_ticks == 0);
        CHECK(check_plan(plan, {}, profile()).within_limits);
    }
}

TEST_CASE("degenerate input: repeated points, a point subpath, zero-length travel", "[planner]") {
    MachineProfile p = profile();
    Subpath dup = polyline({{0, 0}, {0, 0}, {5, 0}, {5, 0}, {5, 5}});
    Subpath point = polyline({{5, 5}, {5, 5}});  // starts where dup ends: travel of length 0
    Subpath bez;
    bez.basis = PathBasis::kBezier;  // handles on the end points (common in SVG)
    bez.points = {{5, 5}, {5, 5}, {10, 10}, {10, 10}};
    const Planned r = plan_and_check(path_of({dup, point, bez}), p);
    CHECK(r.plan.pen.size() == 6);  // every subpath is drawn: the pen goes down three times
    stream_all(r.plan);
}

TEST_CASE("one and three axes: a line and a helix", "[planner]") {
    SECTION("one axis") {
        MachineProfile p = profile(100, 2000, 1);
        Subpath s = polyline({{0}, {30}, {10}});  // a reversal: a sharp corner, a stop
        const Planned r = plan_and_check(path_of({s}, 1), p);
        const double optimum =
            (30 / 80.0 + 80 / 2000.0) + (20 / 80.0 + 80 / 2000.0);  // two trapezoids
        CHECK(motion_time(r, p) >= optimum * 0.999);
        CHECK(motion_time(r, p) <= optimum * 1.02);
    }
    SECTION("three axes") {
        const MachineProfile p = profile(250, 3000, 3);
        Subpath helix;
        helix.basis = PathBasis::kBSpline;
        for (int i = 0; i <= 120; ++i) {
            const double t = 2 * kPi * i / 40.0;
            helix.points.push_back({10 * std::cos(t), 10 * std::sin(t), 0.5 * t});
        }
        const Planned r = plan_and_check(path_of({helix}, 3), p);
        CHECK(motion_time(r, p) <= r.stats.reference_motion_time * 1.02);
    }
}

TEST_CASE("progress is reported, non-decreasing, up to 1", "[planner]") {
    std::vector<double> seen;
    const auto segs = to_bezier_segments(path_of({circle(10, 100)}));
    (void)plan_path(segs, profile(), [&](double f) { seen.push_back(f); });
    REQUIRE(!seen.empty());
    for (std::size_t i = 1; i < seen.size(); ++i) CHECK(seen[i] >= seen[i - 1]);
    CHECK(seen.front() >= 0);
    CHECK(seen.back() == 1.0);
}

TEST_CASE("seeded random paths pass the per-tick check and stream into the core", "[planner]") {
    const char* env_cases = std::getenv("PATHSTREAM_PLAN_CASES");
    const char* env_seed = std::getenv("PATHSTREAM_PLAN_SEED");
    const int cases = env_cases != nullptr ? std::atoi(env_cases) : 12;
    const unsigned long seed = env_seed != nullptr ? std::strtoul(env_seed, nullptr, 10) : 1;
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> unit(0, 1);
    const auto pick = [&](double lo, double hi) { return lo + (hi - lo) * unit(rng); };
    const auto log_pick = [&](double lo, double hi) {
        return std::exp(pick(std::log(lo), std::log(hi)));
    };
    for (int c = 0; c < cases; ++c) {
        MachineProfile p = profile(log_pick(20, 500), log_pick(200, 20000));
        p.axes[1].max_velocity *= pick(0.5, 2);
        p.axes[1].max_acceleration *= pick(0.5, 2);
        p.tick_hz = log_pick(250, 8000);
        p.ticks_per_span = static_cast<std::uint32_t>(log_pick(1, 40));
        p.mm_per_lsb = log_pick(1e-4, 5e-3);
        p.feed = log_pick(10, 400);
        p.travel_feed = log_pick(10, 400);
        p.chord_tolerance = std::max(log_pick(0.002, 0.05), p.mm_per_lsb);
        p.pen_down_delay = pick(0, 0.05);
        p.pen_up_delay = pick(0, 0.05);
        Path path;
        const int subpaths = 1 + static_cast<int>(rng() % 3);
        for (int s = 0; s < subpaths; ++s) {
            Subpath sp;
            sp.basis = static_cast<PathBasis>(rng() % 4);
            sp.closed = rng() % 3 == 0;
            std::size_t n = 2 + rng() % 12;
            if (sp.basis == PathBasis::kBezier)
                n = sp.closed ? 3 * (1 + rng() % 4) : 3 * (1 + rng() % 4) + 1;
            if (sp.closed && n < 3) n = 3;
            const double size = log_pick(0.5, 60);
            for (std::size_t i = 0; i < n; ++i)
                sp.points.push_back({pick(-size, size), pick(-size, size)});
            if (rng() % 4 == 0) sp.feed = log_pick(5, 200);
            path.subpaths.push_back(sp);
        }
        INFO("case " << c << " seed " << seed << ": tick_hz " << p.tick_hz << ", ticks_per_span "
                     << p.ticks_per_span << ", lsb " << p.mm_per_lsb << ", v "
                     << p.axes[0].max_velocity << ", a " << p.axes[0].max_acceleration);
        try {
            const Planned r = plan_and_check(path, p);
            stream_all(r.plan);
            // A sanity bound against pathological slowness, not a figure (bench_plan measures
            // that): 4x the continuous optimum plus three spans per stop. Random profiles include
            // spans of up to 150 ms on millimetre-sized wiggles, where whole spans cost a lot.
            const double span = p.ticks_per_span / p.tick_hz;
            CHECK(motion_time(r, p) <= 4 * r.stats.reference_motion_time +
                                           3 * span * static_cast<double>(r.stats.pieces + 1) +
                                           0.1);
        } catch (const PlanError& e) {
            FAIL_CHECK("planning failed: " << e.what());
        }
    }
}
