// Path -> Bezier segments: each basis agrees with a direct evaluation of that basis, joints are
// exact, closed subpaths close, travel joins subpaths pen-up; Bezier derivatives.
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "pathstream/basis.hpp"
#include "pathstream/host/geometry.hpp"
#include "pathstream/host/segment_source.hpp"

using namespace pathstream::host;

namespace {

std::vector<PathPoint> random_points(std::mt19937_64& rng, std::size_t count, std::size_t axes) {
    std::uniform_real_distribution<double> d(-50, 50);
    std::vector<PathPoint> pts(count, PathPoint(axes));
    for (auto& p : pts) {
        for (auto& x : p) x = d(rng);
    }
    return pts;
}

/// [u^3 u^2 u 1] M [w0..w3] / scale on every axis: the basis evaluated directly from its matrix.
PathPoint direct(pathstream::Basis basis, const std::array<PathPoint, 4>& w, double u) {
    const auto m = pathstream::basis_matrix(basis);
    const double pw[4] = {u * u * u, u * u, u, 1};
    PathPoint r(w[0].size(), 0.0);
    for (std::size_t a = 0; a < r.size(); ++a) {
        for (int row = 0; row < 4; ++row) {
            double s = 0;
            for (int col = 0; col < 4; ++col)
                s += m.m[row][col] * w[static_cast<std::size_t>(col)][a];
            r[a] += pw[row] * s;
        }
        r[a] /= m.scale;
    }
    return r;
}

double distance(const PathPoint& a, const PathPoint& b) {
    double s = 0;
    for (std::size_t i = 0; i < a.size(); ++i) s += (a[i] - b[i]) * (a[i] - b[i]);
    return std::sqrt(s);
}

PathPoint reflect(const PathPoint& end, const PathPoint& next) {
    PathPoint r(end.size());
    for (std::size_t i = 0; i < r.size(); ++i) r[i] = 2 * end[i] - next[i];
    return r;
}

/// The four-point windows the core uses (phantom ends when open, periodic when closed).
std::vector<std::array<PathPoint, 4>> windows(const std::vector<PathPoint>& p, bool closed) {
    std::vector<PathPoint> ext;
    const std::size_t m = p.size();
    std::vector<std::array<PathPoint, 4>> out;
    if (closed) {
        for (std::size_t i = 0; i < m; ++i)
            out.push_back({p[(i + m - 1) % m], p[i], p[(i + 1) % m], p[(i + 2) % m]});
        return out;
    }
    ext.push_back(reflect(p[0], p[1]));
    ext.insert(ext.end(), p.begin(), p.end());
    ext.push_back(reflect(p[m - 1], p[m - 2]));
    for (std::size_t i = 0; i + 3 < ext.size(); ++i)
        out.push_back({ext[i], ext[i + 1], ext[i + 2], ext[i + 3]});
    return out;
}

void check_joints(const std::vector<BezierSegment>& segs) {
    for (std::size_t i = 1; i < segs.size(); ++i) CHECK(segs[i].p[0] == segs[i - 1].p[3]);  // exact
}

}  // namespace

TEST_CASE("B-spline and Catmull-Rom segments agree with the basis evaluated directly",
          "[geometry]") {
    std::mt19937_64 rng(1234);
    for (const PathBasis basis : {PathBasis::kBSpline, PathBasis::kCatmullRom}) {
        for (const bool closed : {false, true}) {
            for (std::size_t axes = 1; axes <= 4; ++axes) {
                for (int trial = 0; trial < 5; ++trial) {
                    Path path;
                    path.axes = axes;
                    Subpath sp;
                    sp.basis = basis;
                    sp.closed = closed;
                    sp.points = random_points(rng, 3 + static_cast<std::size_t>(trial) * 2, axes);
                    path.subpaths.push_back(sp);
                    const auto segs = to_bezier_segments(path);
                    const auto w = windows(sp.points.vectors(), closed);
                    REQUIRE(segs.size() == w.size());
                    const auto core = basis == PathBasis::kBSpline
                                          ? pathstream::Basis::kUniformBSpline
                                          : pathstream::Basis::kCatmullRom;
                    double worst = 0;
                    for (std::size_t s = 0; s < segs.size(); ++s) {
                        for (int k = 0; k <= 64; ++k) {
                            const double u = k / 64.0;
                            worst = std::max(
                                worst, distance(bezier_point(segs[s], u), direct(core, w[s], u)));
                        }
                        CHECK(segs[s].pen_down);
                        CHECK(segs[s].subpath == 0);
                    }
                    CHECK(worst < 1e-12 * 100);
                    check_joints(segs);
                    if (closed) {
                        CHECK(segs.back().p[3] == segs.front().p[0]);
                    } else {  // clamped: starts at the first point, ends at the last, exactly
                        CHECK(segs.front().p[0] == sp.points.front());
                        CHECK(segs.back().p[3] == sp.points.back());
                    }
                }
            }
        }
    }
}

TEST_CASE("Bezier chains are kept, polylines become straight thirds", "[geometry]") {
    std::mt19937_64 rng(99);
    const auto pts = random_points(rng, 10, 2);
    Path path;
    Subpath open;
    open.basis = PathBasis::kBezier;
    open.points = pts;  // 3 * 3 + 1
    Subpath closed = open;
    closed.closed = true;
    closed.points.pop_back();  // 9 = 3 * 3
    Subpath poly;
    poly.basis = PathBasis::kPolyline;
    poly.points = {pts[0], pts[1], pts[2]};
    poly.closed = true;
    path.subpaths = {open, closed, poly};
    const auto segs = to_bezier_segments(path);
    // 3 open Bezier, travel, 3 closed Bezier, travel, 3 polyline (closed)
    REQUIRE(segs.size() == 11);
    for (std::size_t i = 0; i < 3; ++i) {
        for (std::size_t k = 0; k < 4; ++k) CHECK(segs[i].p[k] == pts[3 * i + k]);
    }
    CHECK(segs[6].p[3] == pts[0]);  // closed chain: last segment back to P0
    CHECK(segs[6].p[1] == pts[7]);
    for (std::size_t i = 8; i < 11; ++i) {
        const auto& s = segs[i];
        for (int k = 0; k <= 16; ++k) {  // exactly straight and uniform in u
            const double u = k / 16.0;
            PathPoint line(2);
            for (std::size_t a = 0; a < 2; ++a) line[a] = s.p[0][a] + u * (s.p[3][a] - s.p[0][a]);
            CHECK(distance(bezier_point(s, u), line) < 1e-12);
        }
    }
    CHECK(segs[10].p[3] == pts[0]);
    check_joints(segs);
}

TEST_CASE("travel segments join consecutive subpaths pen-up, straight", "[geometry]") {
    Path path;
    Subpath a, b, c;
    a.basis = b.basis = c.basis = PathBasis::kPolyline;
    a.points = {{0, 0}, {10, 0}};
    b.points = {{10, 5}, {0, 5}};
    b.feed = 12;
    c.points = {{0, 5}, {0, 9}};  // starts where b ends: a zero-length travel, the pen still lifts
    path.subpaths = {a, b, c};
    const auto segs = to_bezier_segments(path);
    REQUIRE(segs.size() == 5);
    CHECK(segs[0].pen_down);
    CHECK_FALSE(segs[1].pen_down);
    CHECK(segs[1].subpath == 1);  // travel belongs to the subpath it leads to
    CHECK(segs[1].p[0] == PathPoint{10, 0});
    CHECK(segs[1].p[3] == PathPoint{10, 5});
    CHECK(distance(bezier_point(segs[1], 0.5), PathPoint{10, 2.5}) < 1e-12);
    CHECK(segs[2].feed == 12);
    CHECK(segs[1].feed == 0);
    CHECK_FALSE(segs[3].pen_down);
    CHECK(segs[3].p[0] == segs[3].p[3]);
    CHECK(segs[4].subpath == 2);
    check_joints(segs);
}

TEST_CASE("Bezier derivatives match finite differences", "[geometry]") {
    std::mt19937_64 rng(7);
    for (int trial = 0; trial < 20; ++trial) {
        BezierSegment s;
        const auto pts = random_points(rng, 4, 3);
        for (std::size_t k = 0; k < 4; ++k) s.p[k] = pts[k];
        CHECK(bezier_point(s, 0) == s.p[0]);
        CHECK(bezier_point(s, 1) == s.p[3]);
        for (int k = 1; k < 10; ++k) {
            const double u = k / 10.0, h = 1e-5;
            const auto p0 = bezier_point(s, u - h), p1 = bezier_point(s, u + h);
            const auto d1 = bezier_d1(s, u), d2 = bezier_d2(s, u);
            const auto d1m = bezier_d1(s, u - h), d1p = bezier_d1(s, u + h);
            for (std::size_t a = 0; a < 3; ++a) {
                CHECK(d1[a] == Approx((p1[a] - p0[a]) / (2 * h)).margin(1e-5));
                CHECK(d2[a] == Approx((d1p[a] - d1m[a]) / (2 * h)).margin(1e-4));
            }
        }
    }
}

TEST_CASE("too few points is an error, not a crash", "[geometry]") {
    Path path;
    Subpath sp;
    sp.basis = PathBasis::kBSpline;
    sp.points = {{1, 2}};
    path.subpaths = {sp};
    CHECK_THROWS_AS(to_bezier_segments(path), std::invalid_argument);
}

TEST_CASE("a path's segments made one at a time: the list's, a lead-in first, again on rewind",
          "[geometry]") {
    std::mt19937_64 rng(37);
    Path path;
    const PathBasis bases[] = {PathBasis::kBSpline, PathBasis::kCatmullRom, PathBasis::kBezier,
                               PathBasis::kPolyline};
    for (int i = 0; i < 12; ++i) {
        Subpath sp;
        sp.basis = bases[i % 4];
        sp.closed = i % 3 == 1;
        const std::size_t n = sp.basis == PathBasis::kBezier ? (sp.closed ? 9 : 10) : 2 + i;
        for (const PathPoint& p : random_points(rng, n, 2)) sp.points.push_back(p);
        sp.feed = i;
        path.subpaths.push_back(sp);
    }
    std::vector<BezierSegment> expected = to_bezier_segments(path);
    const PathPoint rest{-3, 7};
    prepend_lead_in(expected, rest);
    PathSegmentSource source(path, rest);
    CHECK(source.size_hint() + 1 == expected.size());
    for (int pass = 0; pass < 2; ++pass) {
        std::size_t k = 0;
        BezierSegment s;
        while (source.next(s)) {
            REQUIRE(k < expected.size());
            CHECK(s.p == expected[k].p);
            CHECK(s.pen_down == expected[k].pen_down);
            CHECK(s.subpath == expected[k].subpath);
            CHECK(s.feed == expected[k].feed);
            ++k;
        }
        CHECK(k == expected.size());
        REQUIRE(source.rewind());
    }
    // At the start already: no lead-in.
    PathSegmentSource at_start(path, expected[1].p[0]);
    BezierSegment first;
    REQUIRE(at_start.next(first));
    CHECK(first.pen_down);
}

TEST_CASE("a routed travel's pause stays first behind a lead-in", "[geometry]") {
    // A machine program that starts with M6 then G0: the travel subpath carries the pause, and
    // the lead-in that joins its run must carry it, or the pause is lost.
    Path path;
    path.axes = 2;
    Subpath rapid;
    rapid.basis = PathBasis::kPolyline;
    rapid.travel = true;
    rapid.pause_before = true;
    rapid.points = PointList({{10, 0}, {10, 10}});
    path.subpaths.push_back(rapid);
    Subpath cut;
    cut.basis = PathBasis::kPolyline;
    cut.points = PointList({{10, 10}, {20, 10}});
    path.subpaths.push_back(cut);
    PathSegmentSource source(path, PathPoint{0, 0});
    BezierSegment first, second;
    REQUIRE(source.next(first));
    REQUIRE(source.next(second));
    CHECK_FALSE(first.pen_down);
    CHECK(first.pause_before);  // the lead-in, first of the run
    CHECK(second.subpath == first.subpath);
    CHECK_FALSE(second.pause_before);
}
