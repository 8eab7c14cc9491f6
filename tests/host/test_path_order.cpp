// Subpath order (path_order.hpp): reversal and rotation keep the curve, joining, travel never
// worse than the document order, determinism, and the landscape figure of docs/path-order.md.
#include <catch2/catch.hpp>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "pathstream/host/geometry.hpp"
#include "pathstream/host/path_order.hpp"
#include "pathstream/host/svg_path.hpp"

using namespace pathstream::host;

namespace {

std::string source_dir() {
#ifdef PATHSTREAM_SOURCE_DIR
    return PATHSTREAM_SOURCE_DIR;
#else
    return ".";
#endif
}

/// A one-subpath path.
Path single(const Subpath& s) {
    Path p;
    p.subpaths = {s};
    return p;
}

/// Cubic segments of one subpath (pen-down only).
std::vector<BezierSegment> segments_of(const Subpath& s) {
    std::vector<BezierSegment> out;
    for (const BezierSegment& b : to_bezier_segments(single(s))) {
        if (b.pen_down) out.push_back(b);
    }
    return out;
}

/// Largest distance between control points of two segments, the second read backwards
/// when `backwards`.
double segment_gap(const BezierSegment& a, const BezierSegment& b, bool backwards) {
    double worst = 0;
    for (std::size_t k = 0; k < 4; ++k) {
        const PathPoint& q = b.p[backwards ? 3 - k : k];
        for (std::size_t i = 0; i < q.size(); ++i)
            worst = std::max(worst, std::fabs(a.p[k][i] - q[i]));
    }
    return worst;
}

/// A subpath of n random points (n fitted to the basis), open or closed.
Subpath random_subpath(std::mt19937_64& rng, PathBasis basis, bool closed, std::size_t n) {
    std::uniform_real_distribution<double> coord(-50, 50);
    Subpath s;
    s.basis = basis;
    s.closed = closed;
    if (basis == PathBasis::kBezier)
        n = closed ? 3 * std::max<std::size_t>(1, n / 3) : 3 * (n / 3) + 1;
    for (std::size_t i = 0; i < n; ++i) s.points.push_back({coord(rng), coord(rng)});
    return s;
}

/// A drawing of `count` random short strokes (bases mixed), seeded.
Path random_strokes(std::uint64_t seed, std::size_t count) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> where(0, 300), step(-8, 8);
    const PathBasis bases[] = {PathBasis::kPolyline, PathBasis::kBezier, PathBasis::kBSpline,
                               PathBasis::kCatmullRom};
    Path p;
    for (std::size_t i = 0; i < count; ++i) {
        Subpath s;
        s.basis = bases[i % 4];
        s.closed = i % 7 == 3;
        const std::size_t n = s.basis == PathBasis::kBezier ? (s.closed ? 6 : 4) : 4;
        double x = where(rng), y = where(rng);
        for (std::size_t k = 0; k < n; ++k) {
            s.points.push_back({x, y});
            x += step(rng), y += step(rng);
        }
        p.subpaths.push_back(s);
    }
    return p;
}

}  // namespace

TEST_CASE("reversal draws the same curve backwards, every basis", "[order]") {
    std::mt19937_64 rng(7);
    for (PathBasis basis :
         {PathBasis::kBSpline, PathBasis::kCatmullRom, PathBasis::kBezier, PathBasis::kPolyline}) {
        for (bool closed : {false, true}) {
            const Subpath s = random_subpath(rng, basis, closed, 10);
            const std::vector<BezierSegment> a = segments_of(s),
                                             b = segments_of(reversed_subpath(s));
            REQUIRE(a.size() == b.size());
            for (std::size_t i = 0; i < a.size(); ++i) {
                CHECK(segment_gap(a[i], b[b.size() - 1 - i], true) < 1e-12);
            }
            CHECK(curve_start(reversed_subpath(s)) == curve_end(s));
        }
    }
}

TEST_CASE("rotating a closed subpath keeps its curve", "[order]") {
    std::mt19937_64 rng(11);
    for (PathBasis basis :
         {PathBasis::kBSpline, PathBasis::kCatmullRom, PathBasis::kBezier, PathBasis::kPolyline}) {
        const Subpath s = random_subpath(rng, basis, true, 12);
        const std::size_t shift = basis == PathBasis::kBezier ? 6 : 5;
        const std::size_t per = basis == PathBasis::kBezier ? 3 : 1;
        const std::vector<BezierSegment> a = segments_of(s),
                                         b = segments_of(rotated_subpath(s, shift));
        REQUIRE(a.size() == b.size());
        for (std::size_t i = 0; i < a.size(); ++i) {
            CHECK(segment_gap(a[(i + shift / per) % a.size()], b[i], false) < 1e-12);
        }
    }
    Subpath bezier = random_subpath(rng, PathBasis::kBezier, true, 9);
    CHECK_THROWS_AS(rotated_subpath(bezier, 4), std::invalid_argument);
    bezier.closed = false;
    CHECK_THROWS_AS(rotated_subpath(bezier, 3), std::invalid_argument);
}

TEST_CASE("touching polyline and Bezier ends are joined, splines are not", "[order]") {
    Path p;
    Subpath a{PathBasis::kPolyline, false, {{0, 20}, {10, 20}}, 0, {}};
    // touches a's end, reversed
    Subpath b{PathBasis::kPolyline, false, {{20, 25}, {10.004, 20}}, 0, {}};
    Subpath c{PathBasis::kBezier, false, {{0, 0}, {1, 1}, {2, 1}, {3, 0}}, 0, {}};
    Subpath d{PathBasis::kBezier, false, {{3, 0}, {4, -1}, {5, -1}, {6, 0}}, 0, {}};
    Subpath e{PathBasis::kBSpline, false, {{6, 0}, {7, 3}, {8, 0}}, 0, {}};
    Subpath f{PathBasis::kBSpline, false, {{8, 0}, {9, 3}, {10, 0}}, 0, {}};
    Subpath g{PathBasis::kPolyline, false, {{20, 25}, {30, 25}}, 25, {}};  // another feed
    p.subpaths = {a, b, c, d, e, f, g};
    std::size_t merged = 0;
    const Path m = merge_touching(p, 0.01, &merged);
    CHECK(merged == 2);
    REQUIRE(m.subpaths.size() == 5);
    CHECK(m.subpaths[0].points == std::vector<PathPoint>{{0, 20}, {10, 20}, {20, 25}});
    CHECK(m.subpaths[1].points.size() == 7);
    CHECK(point_count_problem(m.subpaths[1]).empty());
    CHECK(m.subpaths[2].basis == PathBasis::kBSpline);
    CHECK(m.subpaths[4].feed == 25);
    std::size_t none = 0;
    CHECK(merge_touching(p, 0.001, &none).subpaths.size() == 6);
    CHECK(none == 1);
}

TEST_CASE("a polyline touching a Bezier chain joins it as a Bezier chain of the same curve",
          "[order]") {
    Path p;
    const Subpath line{PathBasis::kPolyline, false, {{0, 0}, {3, 0}, {3, 3}}, 0, {}};
    const Subpath curve{PathBasis::kBezier, false, {{3, 3}, {4, 4}, {5, 4}, {6, 3}}, 0, {}};
    p.subpaths = {curve, line};
    std::size_t merged = 0;
    const Path m = merge_touching(p, 0.01, &merged);
    CHECK(merged == 1);
    REQUIRE(m.subpaths.size() == 1);
    const Subpath& joined = m.subpaths[0];
    CHECK(joined.basis == PathBasis::kBezier);
    REQUIRE(point_count_problem(joined).empty());
    // The line's segments first (the chain grew backwards from the curve's start), then the curve:
    // segment by segment what the two subpaths draw, control points exactly.
    std::vector<BezierSegment> expected = segments_of(line);
    for (const BezierSegment& b : segments_of(curve)) expected.push_back(b);
    const std::vector<BezierSegment> got = segments_of(joined);
    REQUIRE(got.size() == expected.size());
    for (std::size_t i = 0; i < got.size(); ++i)
        CHECK(segment_gap(got[i], expected[i], false) == 0);
}

TEST_CASE("order: never more travel than document order (seeded)", "[order]") {
    for (std::uint64_t seed = 1; seed <= 20; ++seed) {
        const Path p = random_strokes(seed, 5 + seed * 7);
        OrderReport r;
        const Path o = order_path(p, {}, &r);
        CHECK(r.travel_after <= r.travel_before + 1e-9);
        CHECK(pen_up_travel(o) == Approx(r.travel_after));
        CHECK(r.travel_before == Approx(pen_up_travel(p)));
        // Nothing lost: the same total of points (joins drop one point each).
        std::size_t before = 0, after = 0;
        for (const Subpath& s : p.subpaths) before += s.points.size();
        for (const Subpath& s : o.subpaths) after += s.points.size();
        CHECK(after + r.merged == before);
    }
}

TEST_CASE("order: 2-opt and Or-opt never lose to plain greedy", "[order]") {
    for (std::uint64_t seed = 30; seed < 40; ++seed) {
        const Path p = random_strokes(seed, 200);
        OrderOptions greedy;
        greedy.improve = false;
        OrderReport g, i;
        (void)order_path(p, greedy, &g);
        (void)order_path(p, {}, &i);
        CHECK(i.travel_after <= g.travel_after + 1e-9);
    }
}

TEST_CASE("order: a good document order stays (start point given)", "[order]") {
    Path p;
    for (int i = 0; i < 10; ++i) {
        p.subpaths.push_back(
            {PathBasis::kPolyline, false, {{10.0 * i, 0}, {10.0 * i + 5, 0}}, 0, {}});
    }
    OrderOptions o;
    o.start = {0, 0};
    OrderReport r;
    const Path q = order_path(p, o, &r);
    CHECK(r.travel_after == Approx(45.0));
    CHECK(r.travel_before == Approx(45.0));
    CHECK(q.subpaths.size() == 10);
    o.start = {1, 2, 3};
    CHECK_THROWS_AS(order_path(p, o), std::invalid_argument);
}

TEST_CASE("order: closed subpaths start at their nearest vertex", "[order]") {
    Subpath square{
        PathBasis::kPolyline, true, {{100, 100}, {110, 100}, {110, 110}, {100, 110}}, 0, {}};
    Subpath loop{PathBasis::kBezier,
                 false,
                 {{0, 50},
                  {0, 55},
                  {5, 60},
                  {10, 60},
                  {15, 60},
                  {20, 55},
                  {20, 50},
                  {10, 45},
                  {5, 45},
                  {0, 50.005}},
                 0,
                 {}};
    Path p;
    p.subpaths = {square, loop};
    OrderOptions o;
    o.start = {115, 115};
    OrderReport r;
    const Path q = order_path(p, o, &r);
    REQUIRE(q.subpaths.size() == 2);
    CHECK(q.subpaths[0].points[0] == PathPoint{110, 110});
    CHECK(q.subpaths[0].closed);
    // The open Bezier loop (ends 5 um apart) starts at its on-curve point nearest (110, 110).
    CHECK(q.subpaths[1].points[0] == PathPoint{20, 50});
    CHECK(point_count_problem(q.subpaths[1]).empty());
    CHECK(r.travel_after < r.travel_before);
}

TEST_CASE("order: same input, same output", "[order]") {
    const Path p = random_strokes(99, 500);
    const Path a = order_path(p), b = order_path(p);
    REQUIRE(a.subpaths.size() == b.subpaths.size());
    for (std::size_t i = 0; i < a.subpaths.size(); ++i)
        CHECK(a.subpaths[i].points == b.subpaths[i].points);
}

TEST_CASE("order: a bounded work limit still gives a valid order", "[order]") {
    const Path p = random_strokes(5, 3000);
    OrderOptions o;
    o.work_limit = 100000;
    OrderReport r;
    const Path q = order_path(p, o, &r);
    CHECK(r.work <= o.work_limit + 4'000'000);
    CHECK(r.travel_after <= r.travel_before);
    CHECK(q.subpaths.size() == r.subpaths_after);
}

TEST_CASE("order: landscape.svg pen-up travel at most 582 mm", "[order]") {
    const Path p = load_svg_path(source_dir() + "/examples/landscape.svg");
    OrderReport r;
    const Path q = order_path(p, {}, &r);
    INFO("before " << r.travel_before << " mm, after " << r.travel_after << " mm, "
                   << r.subpaths_before << " -> " << r.subpaths_after);
    CHECK(r.travel_after <= 582.0);
    CHECK(r.travel_after < r.travel_before);
    WARN("landscape.svg: " << r.travel_before << " mm -> " << r.travel_after << " mm, "
                           << r.subpaths_before << " -> " << r.subpaths_after << " subpaths");
}
