// The SVG reader: every path command, shape, transform and unit, arcs within the tolerance
// against the analytic ellipse, and each kind of broken document with its exact message.
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "pathstream/host/svg_path.hpp"
#include "pathstream/machine/input_error.hpp"

using namespace pathstream::host;
using svg::Point;

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kEps = 1e-9;

// A document whose user unit is one millimetre: 100 x 100 mm, viewBox 0 0 100 100.
std::string doc(const std::string& body) {
    return R"(<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" viewBox="0 0 100 100">)" +
           body + "</svg>";
}

Path parse(const std::string& body, double tolerance = 0.01) {
    return parse_svg_path(doc(body), "t.svg", tolerance);
}

// The one subpath of a path element with data `d`.
Subpath one(const std::string& d) {
    const Path p = parse("<path d=\"" + d + "\"/>");
    REQUIRE(p.subpaths.size() == 1);
    return p.subpaths[0];
}

std::string error_of(const std::string& text, double tolerance = 0.01) {
    try {
        parse_svg_path(text, "t.svg", tolerance);
    } catch (const InputError& e) {
        return e.what();
    }
    return "no error";
}

std::string body_error(const std::string& body) {
    return error_of(doc(body));
}

Point third(Point a, Point b, double t) {
    return {a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t};
}

// A subpath's Bezier chain: its points, or for a polyline its pieces with their control
// points at the thirds (the curve the planner draws of it).
std::vector<Point> chain_of(const Subpath& s) {
    std::vector<Point> out;
    for (std::size_t i = 0; i < s.points.size(); ++i) {
        const Point p{s.points[i][0], s.points[i][1]};
        if (s.basis == PathBasis::kPolyline && i > 0) {
            out.push_back(third(out.back(), p, 1.0 / 3));
            out.push_back(third(out[out.size() - 2], p, 2.0 / 3));
        }
        out.push_back(p);
    }
    return out;
}

// The subpath draws the Bezier chain `expected`: as that chain, or as a polyline when every
// piece of it is straight.
void check_points(const Subpath& s, const std::vector<Point>& expected) {
    CHECK((s.basis == PathBasis::kBezier || s.basis == PathBasis::kPolyline));
    CHECK_FALSE(s.closed);
    REQUIRE(s.points.axes() == 2);
    const std::vector<Point> chain = chain_of(s);
    REQUIRE(chain.size() == expected.size());
    for (std::size_t i = 0; i < expected.size(); ++i) {
        INFO("point " << i << ": (" << chain[i].x << ", " << chain[i].y << ") expected ("
                      << expected[i].x << ", " << expected[i].y << ")");
        CHECK(std::fabs(chain[i].x - expected[i].x) <= kEps);
        CHECK(std::fabs(chain[i].y - expected[i].y) <= kEps);
    }
}

// The chain of straight pieces through `corners`, as the reader must produce it.
std::vector<Point> lines(const std::vector<Point>& corners) {
    std::vector<Point> out{corners[0]};
    for (std::size_t i = 1; i < corners.size(); ++i) {
        out.push_back(third(corners[i - 1], corners[i], 1.0 / 3));
        out.push_back(third(corners[i - 1], corners[i], 2.0 / 3));
        out.push_back(corners[i]);
    }
    return out;
}

Point bezier(const Subpath& s, std::size_t piece, double t) {
    const auto& p = s.points;
    const std::size_t i = 3 * piece;
    const double u = 1 - t;
    const double b[4] = {u * u * u, 3 * u * u * t, 3 * u * t * t, t * t * t};
    Point out;
    for (int k = 0; k < 4; ++k) {
        out.x += b[k] * p[i + k][0];
        out.y += b[k] * p[i + k][1];
    }
    return out;
}

// An ellipse given by centre, radii and rotation (then optionally mapped by `map`), and the
// distance of a point from it, found independently of the reader: dense sampling of the
// angle, then golden-section refinement around the nearest sample.
struct Ellipse {
    Point c;
    double rx, ry, phi;
    svg::Affine map{};
    int samples = 720;

    Point at(double t) const {
        const double x = rx * std::cos(t), y = ry * std::sin(t);
        return map({c.x + x * std::cos(phi) - y * std::sin(phi),
                    c.y + x * std::sin(phi) + y * std::cos(phi)});
    }

    double distance(Point p) const {
        const auto d = [&](double t) { return std::hypot(at(t).x - p.x, at(t).y - p.y); };
        const int kN = samples;
        int best = 0;
        for (int i = 1; i < kN; ++i) {
            if (d(2 * kPi * i / kN) < d(2 * kPi * best / kN)) best = i;
        }
        double lo = 2 * kPi * (best - 1) / kN, hi = 2 * kPi * (best + 1) / kN;
        for (int i = 0; i < 100; ++i) {
            const double m1 = lo + (hi - lo) * 0.382, m2 = lo + (hi - lo) * 0.618;
            if (d(m1) < d(m2))
                hi = m2;
            else
                lo = m1;
        }
        return d((lo + hi) / 2);
    }
};

// Largest distance of the subpath's pieces [first, last) from the ellipse, 200 samples each.
double worst_deviation(const Subpath& s, const Ellipse& e, std::size_t first = 0,
                       std::size_t last = SIZE_MAX, int per_piece = 200) {
    double worst = 0;
    last = std::min(last, (s.points.size() - 1) / 3);
    for (std::size_t piece = first; piece < last; ++piece) {
        for (int i = 0; i <= per_piece; ++i) {
            worst =
                std::max(worst, e.distance(bezier(s, piece, static_cast<double>(i) / per_piece)));
        }
    }
    return worst;
}

// Signed angle swept around `c` through the chain's on-curve points.
double swept(const Subpath& s, Point c) {
    double total = 0;
    for (std::size_t i = 3; i < s.points.size(); i += 3) {
        const double a = std::atan2(s.points[i - 3][1] - c.y, s.points[i - 3][0] - c.x);
        const double b = std::atan2(s.points[i][1] - c.y, s.points[i][0] - c.x);
        double d = b - a;
        while (d > kPi) d -= 2 * kPi;
        while (d < -kPi) d += 2 * kPi;
        total += d;
    }
    return total;
}

std::string source_dir() {
#ifdef PATHSTREAM_SOURCE_DIR
    return PATHSTREAM_SOURCE_DIR;
#else
    const std::string here = __FILE__;
    return here.substr(0, here.rfind("/tests/host/"));
#endif
}

}  // namespace

// ---- path commands ------------------------------------------------------------------------

TEST_CASE("svg: M and L, absolute and relative, with implicit linetos", "[svg]") {
    check_points(one("M 10 20 L 40 50"), lines({{10, 20}, {40, 50}}));
    check_points(one("M10,20 40,50 70,20"), lines({{10, 20}, {40, 50}, {70, 20}}));
    check_points(one("m 10 20 l 30 30 30 -30"), lines({{10, 20}, {40, 50}, {70, 20}}));
    check_points(one("m10 20 30 30"), lines({{10, 20}, {40, 50}}));  // implicit l after m
    const Path p = parse(R"(<path d="M 1 1 L 2 2 m 10 0 l 1 0 M 50 50 L 60 60"/>)");
    REQUIRE(p.subpaths.size() == 3);
    check_points(p.subpaths[1], lines({{12, 2}, {13, 2}}));  // m relative to the current point
    check_points(p.subpaths[2], lines({{50, 50}, {60, 60}}));
}

TEST_CASE("svg: a subpath of straight pieces only is a polyline of their ends", "[svg]") {
    const Path p =
        parse(R"(<path d="M 0 0 L 10 0 L 10 10 Z M 20 0 L 30 0 Q 40 0 40 10"/>)"
              R"(<polyline points="0,20 10,20 10,30"/><rect x="50" y="0" width="10" height="5"/>)");
    REQUIRE(p.subpaths.size() == 4);
    CHECK(p.subpaths[0].basis == PathBasis::kPolyline);
    CHECK(p.subpaths[0].points == PointList{{0, 0}, {10, 0}, {10, 10}, {0, 0}});
    CHECK(p.subpaths[1].basis == PathBasis::kBezier);  // a curve in it: every piece a cubic
    CHECK(p.subpaths[1].points.size() == 7);
    CHECK(p.subpaths[2].basis == PathBasis::kPolyline);
    CHECK(p.subpaths[2].points.size() == 3);
    CHECK(p.subpaths[3].basis == PathBasis::kPolyline);
    CHECK(p.subpaths[3].points.size() == 5);
}

TEST_CASE("svg: H and V, absolute and relative", "[svg]") {
    check_points(one("M 10 10 H 30 V 40 h -5 v -10"),
                 lines({{10, 10}, {30, 10}, {30, 40}, {25, 40}, {25, 30}}));
    check_points(one("M10 10H20 30V20 30"),
                 lines({{10, 10}, {20, 10}, {30, 10}, {30, 20}, {30, 30}}));
}

TEST_CASE("svg: C and c keep their control points", "[svg]") {
    check_points(one("M 1 2 C 3 4 5 6 7 8 C 9 10 11 12 13 14"),
                 {{1, 2}, {3, 4}, {5, 6}, {7, 8}, {9, 10}, {11, 12}, {13, 14}});
    // relative: each triple relative to the current point at the start of that curve
    check_points(one("M 1 2 c 2 2 4 4 6 6 2 2 4 4 6 6"),
                 {{1, 2}, {3, 4}, {5, 6}, {7, 8}, {9, 10}, {11, 12}, {13, 14}});
}

TEST_CASE("svg: S and s reflect the previous second control point", "[svg]") {
    check_points(one("M 0 0 C 10 0 20 10 30 10 S 50 30 60 30"),
                 {{0, 0}, {10, 0}, {20, 10}, {30, 10}, {40, 10}, {50, 30}, {60, 30}});
    check_points(one("M 0 0 C 10 0 20 10 30 10 s 20 20 30 20"),
                 {{0, 0}, {10, 0}, {20, 10}, {30, 10}, {40, 10}, {50, 30}, {60, 30}});
    // S after S reflects the S's own second control point
    check_points(one("M 0 0 S 10 10 20 0 S 30 -10 40 0"),
                 {{0, 0}, {0, 0}, {10, 10}, {20, 0}, {30, -10}, {30, -10}, {40, 0}});
    // without a preceding curve the first control point is the current point
    check_points(one("M 0 0 L 10 0 S 20 10 30 0"),
                 {{0, 0}, {10.0 / 3, 0}, {20.0 / 3, 0}, {10, 0}, {10, 0}, {20, 10}, {30, 0}});
    // a quadratic before S does not count
    check_points(one("M 0 0 Q 0 30 30 30 S 40 40 60 30"),
                 {{0, 0}, {0, 20}, {10, 30}, {30, 30}, {30, 30}, {40, 40}, {60, 30}});
}

TEST_CASE("svg: Q and q are degree-elevated exactly", "[svg]") {
    // C1 = P0 + 2/3 (Q - P0), C2 = P2 + 2/3 (Q - P2)
    check_points(one("M 0 0 Q 30 60 60 0"), {{0, 0}, {20, 40}, {40, 40}, {60, 0}});
    check_points(one("M 0 0 q 30 60 60 0 30 -60 60 0"),
                 {{0, 0}, {20, 40}, {40, 40}, {60, 0}, {80, -40}, {100, -40}, {120, 0}});
}

TEST_CASE("svg: T and t reflect the previous quadratic control point", "[svg]") {
    // Q control (30, 60); T reflects it about (60, 0) to (90, -60); the next T about (120, 0) to
    // (150, 60)
    check_points(one("M 0 0 Q 30 60 60 0 T 120 0 T 180 0"), {{0, 0},
                                                             {20, 40},
                                                             {40, 40},
                                                             {60, 0},
                                                             {80, -40},
                                                             {100, -40},
                                                             {120, 0},
                                                             {140, 40},
                                                             {160, 40},
                                                             {180, 0}});
    check_points(one("M 0 0 q 30 60 60 0 t 60 0 60 0"), {{0, 0},
                                                         {20, 40},
                                                         {40, 40},
                                                         {60, 0},
                                                         {80, -40},
                                                         {100, -40},
                                                         {120, 0},
                                                         {140, 40},
                                                         {160, 40},
                                                         {180, 0}});
    // T without a preceding quadratic: control point = current point (a straight, uneven piece)
    check_points(one("M 0 0 T 30 0"), {{0, 0}, {0, 0}, {10, 0}, {30, 0}});
    // a cubic before T does not count
    check_points(one("M 0 0 C 0 10 20 10 20 0 T 50 0"),
                 {{0, 0}, {0, 10}, {20, 10}, {20, 0}, {20, 0}, {30, 0}, {50, 0}});
}

TEST_CASE("svg: Z closes with a straight piece and starts the next subpath at the start", "[svg]") {
    check_points(one("M 10 10 H 40 V 40 Z"), lines({{10, 10}, {40, 10}, {40, 40}, {10, 10}}));
    check_points(one("M 10 10 h 30 v 30 h -30 z"),
                 lines({{10, 10}, {40, 10}, {40, 40}, {10, 40}, {10, 10}}));
    // already at the start: no closing piece
    check_points(one("M 10 10 H 40 L 10 10 Z"), lines({{10, 10}, {40, 10}, {10, 10}}));
    const Path p = parse(R"(<path d="M 10 10 H 40 V 40 Z l 0 20 Z m 50 0 h 5 z"/>)");
    REQUIRE(p.subpaths.size() == 3);
    check_points(p.subpaths[1], lines({{10, 10}, {10, 30}, {10, 10}}));  // after Z: from the start
    check_points(p.subpaths[2],
                 lines({{60, 10}, {65, 10}, {60, 10}}));  // m after z: relative to the start
}

TEST_CASE("svg: the number grammar: signs, dots, exponents, separators", "[svg]") {
    check_points(one("M-.5.5L1e1-2E+1"), lines({{-0.5, 0.5}, {10, -20}}));
    check_points(one("M1.5.5l.5-.5,1e-3,0"), lines({{1.5, 0.5}, {2, 0}, {2.001, 0}}));
    check_points(one("  M\t0\n0\r\nL 3 , 4  "), lines({{0, 0}, {3, 4}}));
    check_points(one("M 0 0 L 1e-400 5"), lines({{0, 0}, {0, 5}}));  // underflow is zero
    check_points(one("M +1 +2 L 4. 6."), lines({{1, 2}, {4, 6}}));
}

TEST_CASE("svg: compact arc flags", "[svg]") {
    const auto same = [](const Subpath& a, const Subpath& b) {
        REQUIRE(a.points.size() == b.points.size());
        for (std::size_t i = 0; i < a.points.size(); ++i) CHECK(a.points[i] == b.points[i]);
    };
    same(one("M0 0a10 10 0 1020 20"),
         one("M 0 0 a 10 10 0 1 0 20 20"));  // large 1, sweep 0, to (20, 20)
    same(one("M0 0A5 5 0 0120 0"), one("M 0 0 A 5 5 0 0 1 20 0"));
    same(one("M0,0A5,5,0,0,1,20,0"), one("M 0 0 A 5 5 0 0 1 20 0"));
}

// ---- arcs ---------------------------------------------------------------------------------

TEST_CASE("svg: the arc flags choose the centre and the direction", "[svg]") {
    // The circles of radius 10 through (0, 0) and (10, 10) are centred at (0, 10) and (10, 0).
    // y points down, so sweep 1 (positive angles) is clockwise on screen.
    struct Case {
        const char* flags;
        Point centre;
        double angle;
    };
    const Case cases[] = {{"0 1", {0, 10}, kPi / 2},
                          {"1 1", {10, 0}, 3 * kPi / 2},
                          {"0 0", {10, 0}, -kPi / 2},
                          {"1 0", {0, 10}, -3 * kPi / 2}};
    for (const Case& c : cases) {
        INFO("flags " << c.flags);
        const Subpath s = one(std::string("M 0 0 A 10 10 0 ") + c.flags + " 10 10");
        CHECK(std::fabs(s.points.front()[0]) <= 1e-12);
        CHECK(std::fabs(s.points.front()[1]) <= 1e-12);
        CHECK(std::fabs(s.points.back()[0] - 10) <= 1e-12);
        CHECK(std::fabs(s.points.back()[1] - 10) <= 1e-12);
        CHECK(swept(s, c.centre) == Approx(c.angle).margin(1e-9));
        CHECK(worst_deviation(s, {c.centre, 10, 10, 0}) <= 0.01);
        // relative form, same arc
        const Subpath r = one(std::string("M 0 0 a 10 10 0 ") + c.flags + " 10 10");
        REQUIRE(r.points.size() == s.points.size());
        for (std::size_t i = 0; i < s.points.size(); ++i) CHECK(r.points[i] == s.points[i]);
    }
}

TEST_CASE("svg: a rotated elliptical arc stays within each tolerance of the true ellipse",
          "[svg]") {
    const Ellipse e{{50, 50}, 40, 20, 30 * kPi / 180};
    const Point from = e.at(10 * kPi / 180), to = e.at(250 * kPi / 180);
    char d[256];
    std::snprintf(d, sizeof d, "M %.17g %.17g A 40 20 30 1 1 %.17g %.17g", from.x, from.y, to.x,
                  to.y);
    std::size_t previous_points = 0;
    for (const double tolerance : {0.5, 0.1, 0.01, 0.001, 1e-4}) {
        INFO("tolerance " << tolerance);
        const Path p = parse(std::string("<path d=\"") + d + "\"/>", tolerance);
        REQUIRE(p.subpaths.size() == 1);
        const Subpath& s = p.subpaths[0];
        CHECK(s.points.size() % 3 == 1);
        CHECK(s.points.size() >= 3 * 3 + 1);  // 240 degrees: at least three pieces
        CHECK(s.points.size() >= previous_points);
        previous_points = s.points.size();
        CHECK(std::hypot(s.points.front()[0] - from.x, s.points.front()[1] - from.y) <= 1e-12);
        CHECK(std::hypot(s.points.back()[0] - to.x, s.points.back()[1] - to.y) <= 1e-12);
        CHECK(worst_deviation(s, e) <= tolerance);
        // the arc passes through the middle of the sweep (130 degrees), not the other way round
        const Point mid = e.at(130 * kPi / 180);
        double nearest = INFINITY;
        for (std::size_t piece = 0; piece < s.points.size() / 3; ++piece) {
            for (int i = 0; i <= 100; ++i) {
                const Point q = bezier(s, piece, i / 100.0);
                nearest = std::min(nearest, std::hypot(q.x - mid.x, q.y - mid.y));
            }
        }
        CHECK(nearest < 1.0);
    }
    CHECK(previous_points >
          3 * 4 + 1);  // the finest tolerance needed more than 90 degrees per piece
}

TEST_CASE("svg: the arc tolerance holds in millimetres after transforms", "[svg]") {
    // user units scaled by 100 and rotated by 90 degrees: the arc is 100 times larger in mm
    const Path p = parse(
        R"~(<g transform="rotate(90) scale(100)"><path d="M 0 0 A 3 1.5 20 0 1 4 1"/></g>)~", 1e-4);
    REQUIRE(p.subpaths.size() == 1);
    const Path unscaled = parse(R"(<path d="M 0 0 A 3 1.5 20 0 1 4 1"/>)", 1e-4);
    CHECK(p.subpaths[0].points.size() > unscaled.subpaths[0].points.size());
    // rebuild the ellipse from the arc's centre in user space (the SVG 2 conversion, by hand)
    const svg::Affine m = svg::parse_transform("rotate(90) scale(100)");
    // centre: solve |R(-phi)(P - C)| on the ellipse for both end points (two equations)
    const double phi = 20 * kPi / 180;
    const auto residual = [&](Point c, Point q) {
        const double x = (q.x - c.x) * std::cos(phi) + (q.y - c.y) * std::sin(phi);
        const double y = -(q.x - c.x) * std::sin(phi) + (q.y - c.y) * std::cos(phi);
        return x * x / 9 + y * y / 2.25 - 1;
    };
    // Newton on the centre, from the midpoint shifted to one side; checked below against the flags
    Point c{2 - 0.5, 0.5 + 2};
    for (int i = 0; i < 50; ++i) {
        const double f1 = residual(c, {0, 0}), f2 = residual(c, {4, 1}), h = 1e-7;
        const double a11 = (residual({c.x + h, c.y}, {0, 0}) - f1) / h,
                     a12 = (residual({c.x, c.y + h}, {0, 0}) - f1) / h;
        const double a21 = (residual({c.x + h, c.y}, {4, 1}) - f2) / h,
                     a22 = (residual({c.x, c.y + h}, {4, 1}) - f2) / h;
        const double det = a11 * a22 - a12 * a21;
        c = {c.x - (a22 * f1 - a12 * f2) / det, c.y - (a11 * f2 - a21 * f1) / det};
    }
    REQUIRE(std::fabs(residual(c, {0, 0})) < 1e-12);
    REQUIRE(std::fabs(residual(c, {4, 1})) < 1e-12);
    // sweep 1, large 0: from `from` to `to` in the positive direction is less than half a turn
    const auto angle = [&](Point q) {
        const double x = (q.x - c.x) * std::cos(phi) + (q.y - c.y) * std::sin(phi);
        const double y = -(q.x - c.x) * std::sin(phi) + (q.y - c.y) * std::cos(phi);
        return std::atan2(y / 1.5, x / 3);
    };
    double turn = angle({4, 1}) - angle({0, 0});
    if (turn < 0) turn += 2 * kPi;
    REQUIRE(turn < kPi);
    const Ellipse e{m(c), 300, 150, phi + kPi / 2};
    CHECK(worst_deviation(p.subpaths[0], e) <= 1e-4);
    CHECK(std::hypot(p.subpaths[0].points.back()[0] - m({4, 1}).x,
                     p.subpaths[0].points.back()[1] - m({4, 1}).y) < 1e-9);
}

TEST_CASE("svg: random arcs under random affine maps stay within the tolerance", "[svg]") {
    std::mt19937 rng(20240611);
    const auto uniform = [&](double lo, double hi) {
        return std::uniform_real_distribution<double>(lo, hi)(rng);
    };
    std::size_t pieces = 0;
    for (int trial = 0; trial < 60; ++trial) {
        const Point c{uniform(-50, 50), uniform(-50, 50)};
        const double rx = uniform(0.5, 40), ry = rx * uniform(0.05, 1),
                     phi_deg = uniform(-180, 180);
        const double theta1 = uniform(-kPi, kPi),
                     delta = uniform(0.05, 2 * kPi - 0.05) * (uniform(0, 1) < 0.5 ? -1 : 1);
        const svg::Affine m{uniform(-3, 3), uniform(-3, 3), uniform(-3, 3),
                            uniform(-3, 3), uniform(-9, 9), uniform(-9, 9)};
        if (std::fabs(m.determinant()) < 0.5) continue;
        const double tolerance = std::pow(10.0, uniform(-4, -1));
        const Ellipse user{c, rx, ry, phi_deg * kPi / 180};
        const Point from = user.at(theta1), to = user.at(theta1 + delta);
        INFO("trial " << trial << ": rx " << rx << " ry " << ry << " phi " << phi_deg << " theta1 "
                      << theta1 << " delta " << delta << " tolerance " << tolerance);
        const auto cubics = svg::arc_to_cubics(from, rx, ry, phi_deg, std::fabs(delta) > kPi,
                                               delta > 0, to, m, tolerance);
        REQUIRE_FALSE(cubics.empty());
        CHECK(cubics.front()[0] == from);
        CHECK(cubics.back()[3] == to);
        Subpath s;
        s.points.push_back({m(from).x, m(from).y});
        for (const svg::Cubic& q : cubics) {
            for (int k = 1; k < 4; ++k) s.points.push_back({m(q[k]).x, m(q[k]).y});
        }
        pieces += cubics.size();
        Ellipse mapped = user;
        mapped.map = m;
        mapped.samples = 360;
        CHECK(worst_deviation(s, mapped, 0, SIZE_MAX, 64) <= tolerance);
    }
    CHECK(pieces > 100);
}

TEST_CASE("svg: radii too small are scaled up, zero radii give a line, equal end points nothing",
          "[svg]") {
    const Subpath s = one("M 0 0 A 1 2 0 0 1 20 0");  // scaled by 10: rx 10, ry 20, centre (10, 0)
    CHECK(worst_deviation(s, {{10, 0}, 10, 20, 0}) <= 0.01);
    CHECK(swept(s, {10, 0}) == Approx(kPi).margin(1e-9));
    check_points(one("M 0 0 A 0 5 0 0 1 9 3"), lines({{0, 0}, {9, 3}}));
    check_points(one("M 0 0 a 5 0 0 1 1 9 3"), lines({{0, 0}, {9, 3}}));
    check_points(one("M 5 5 A 10 10 0 0 1 5 5 L 8 5"), lines({{5, 5}, {8, 5}}));
    // negative radii are taken as absolute values
    const Subpath n = one("M 0 0 A -10 -10 0 0 1 10 10"), a = one("M 0 0 A 10 10 0 0 1 10 10");
    REQUIRE(n.points.size() == a.points.size());
    for (std::size_t i = 0; i < a.points.size(); ++i) CHECK(n.points[i] == a.points[i]);
}

TEST_CASE("svg: arc_to_cubics starts and ends exactly at the given points", "[svg]") {
    const Point from{0.1, 0.7}, to{3.3, -2.9};
    for (const bool large : {false, true}) {
        for (const bool sweep : {false, true}) {
            const auto pieces = svg::arc_to_cubics(from, 2.5, 1.25, 17, large, sweep, to, {}, 1e-3);
            REQUIRE_FALSE(pieces.empty());
            CHECK(pieces.front()[0] == from);
            CHECK(pieces.back()[3] == to);
            for (std::size_t i = 1; i < pieces.size(); ++i) CHECK(pieces[i][0] == pieces[i - 1][3]);
        }
    }
    CHECK(svg::arc_to_cubics(from, 2, 2, 0, false, false, from, {}, 1e-3).empty());
}

// ---- transforms ---------------------------------------------------------------------------

TEST_CASE("svg: each transform kind and lists of them", "[svg]") {
    const auto map = [](const char* t, Point p) { return svg::parse_transform(t)(p); };
    const auto near = [](Point a, Point b) { return std::hypot(a.x - b.x, a.y - b.y) <= 1e-12; };
    CHECK(map("translate(10)", {1, 2}) == Point{11, 2});
    CHECK(map("translate(10 20)", {1, 2}) == Point{11, 22});
    CHECK(map(" translate( 10 , -20 ) ", {1, 2}) == Point{11, -18});
    CHECK(map("scale(2)", {1, 2}) == Point{2, 4});
    CHECK(map("scale(2,3)", {1, 2}) == Point{2, 6});
    CHECK(map("rotate(90)", {1, 0}) == Point{0, 1});  // clockwise on screen (y down)
    CHECK(map("rotate(-90)", {1, 0}) == Point{0, -1});
    CHECK(map("rotate(180)", {1, 2}) == Point{-1, -2});
    CHECK(near(map("rotate(45)", {1, 0}), {std::sqrt(0.5), std::sqrt(0.5)}));
    CHECK(map("rotate(90 10 10)", {20, 10}) == Point{10, 20});
    CHECK(near(map("skewX(45)", {0, 10}), {10, 10}));
    CHECK(near(map("skewY(45)", {10, 0}), {10, 10}));
    CHECK(map("matrix(1 2 3 4 5 6)", {1, 1}) == Point{9, 12});
    CHECK(map("matrix(1,2,3,4,5,6)", {1, 1}) == Point{9, 12});
    // the rightmost transform applies first
    CHECK(map("translate(10,0) scale(2)", {1, 1}) == Point{12, 2});
    CHECK(map("scale(2) translate(10,0)", {1, 1}) == Point{22, 2});
    CHECK(map("translate(10)rotate(90)", {1, 0}) == Point{10, 1});
    CHECK(map("translate(10),scale(2)", {1, 1}) == Point{12, 2});
    CHECK(map("", {1, 2}) == Point{1, 2});
    CHECK(map("   ", {1, 2}) == Point{1, 2});
}

TEST_CASE("svg: transforms compose through nested groups, <a>, <svg> and the element", "[svg]") {
    const Path p = parse(R"~(<g transform="translate(10 20)"><g transform="scale(2)">
        <path d="M 1 1 L 2 1" transform="rotate(90)"/></g></g>)~");
    REQUIRE(p.subpaths.size() == 1);
    // (1, 1) -> rotate (-1, 1) -> scale (-2, 2) -> translate (8, 22); (2, 1) -> (8, 24)
    check_points(p.subpaths[0], lines({{8, 22}, {8, 24}}));
    const Path a =
        parse(R"~(<a href="#x" transform="translate(5)"><line x1="0" y1="0" x2="1" y2="0"/></a>)~");
    check_points(a.subpaths[0], lines({{5, 0}, {6, 0}}));
    // a nested <svg>: x, y place its viewport; its viewBox maps onto width x height
    const Path s = parse(
        R"~(<g transform="translate(1 1)"><svg x="10" y="20" width="40" height="20" viewBox="0 0 4 2">
        <line x1="0" y1="0" x2="4" y2="2"/></svg></g>)~");
    check_points(s.subpaths[0], lines({{11, 21}, {51, 41}}));
    // nested <svg> without viewBox: its user units are its parent's
    const Path n = parse(R"(<svg x="10" y="20"><line x1="0" y1="0" x2="4" y2="2"/></svg>)");
    check_points(n.subpaths[0], lines({{10, 20}, {14, 22}}));
    // <switch> draws its first child whose conditions hold
    const Path w =
        parse(R"(<switch><g requiredExtensions="http://ns.adobe.com/AdobeIllustrator/10.0/">
        <line x2="9"/></g><line x2="1"/><line x2="2"/></switch>)");
    REQUIRE(w.subpaths.size() == 1);
    check_points(w.subpaths[0], lines({{0, 0}, {1, 0}}));
    // a transform that collapses the plane draws nothing
    const Path z = parse(R"~(<g transform="scale(0)"><line x2="9"/></g><line x2="1"/>)~");
    REQUIRE(z.subpaths.size() == 1);
}

// ---- units and the viewBox ----------------------------------------------------------------

namespace {
Path with_root(const std::string& root_attributes, const std::string& body) {
    return parse_svg_path(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" " + root_attributes + ">" + body + "</svg>",
        "t.svg");
}
Point first_end(const Path& p) {
    return {p.subpaths.at(0).points.back()[0], p.subpaths.at(0).points.back()[1]};
}
Point first_start(const Path& p) {
    return {p.subpaths.at(0).points.front()[0], p.subpaths.at(0).points.front()[1]};
}
bool near_point(Point a, Point b) {
    return std::hypot(a.x - b.x, a.y - b.y) <= 1e-9;
}
}  // namespace

TEST_CASE("svg: width in mm with a viewBox scales user units", "[svg]") {
    const Path p = with_root(R"(width="100mm" height="100mm" viewBox="0 0 200 200")",
                             R"(<path d="M 0 0 L 200 100"/>)");
    CHECK(near_point(first_end(p), {100, 50}));  // scale 0.5
    const Path o = with_root(R"(width="100mm" height="100mm" viewBox="-50 -50 100 100")",
                             R"(<path d="M 0 0 L 10 0"/>)");
    CHECK(near_point(first_start(o), {50, 50}));
    // only one dimension given: the other follows the viewBox's aspect ratio
    const Path w =
        with_root(R"(width="100mm" viewBox="0 0 200 100")", R"(<path d="M 0 0 L 200 100"/>)");
    CHECK(near_point(first_end(w), {100, 50}));
    const Path h =
        with_root(R"(height="50mm" viewBox="0 0 200 100")", R"(<path d="M 0 0 L 200 100"/>)");
    CHECK(near_point(first_end(h), {100, 50}));
}

TEST_CASE("svg: px at 96 per inch, no viewBox means one user unit is one px", "[svg]") {
    const Path p = with_root(R"(width="960" height="480")", R"(<path d="M 96 0 L 192 48"/>)");
    CHECK(near_point(first_start(p), {25.4, 0}));
    CHECK(near_point(first_end(p), {50.8, 12.7}));
    const Path px = with_root(R"(width="960px" height="480px")", R"(<path d="M 96 0 L 192 48"/>)");
    CHECK(near_point(first_end(px), {50.8, 12.7}));
    const Path none = with_root("", R"(<path d="M 96 0 L 192 48"/>)");
    CHECK(near_point(first_end(none), {50.8, 12.7}));
    const Path vb = with_root(R"(viewBox="0 0 960 480")", R"(<path d="M 96 0 L 192 48"/>)");
    CHECK(near_point(first_end(vb), {50.8, 12.7}));
    const Path percent = with_root(R"(width="100%" height="100%" viewBox="0 0 960 480")",
                                   R"(<path d="M 96 0 L 192 48"/>)");
    CHECK(near_point(first_end(percent), {50.8, 12.7}));
}

TEST_CASE("svg: every unit of width and height", "[svg]") {
    for (const char* size : {"1in", "25.4mm", "2.54cm", "72pt", "6pc", "96px", "96", " 96 "}) {
        INFO(size);
        const Path p = with_root(
            std::string("width=\"") + size + "\" height=\"" + size + "\" viewBox=\"0 0 1 1\"",
            R"(<path d="M 0 0 L 1 1"/>)");
        CHECK(near_point(first_end(p), {25.4, 25.4}));
    }
}

TEST_CASE("svg: preserveAspectRatio", "[svg]") {
    const std::string size = R"(width="100mm" height="50mm" viewBox="0 0 100 100" )";
    const std::string line = R"(<path d="M 0 0 L 100 100"/>)";
    const Path meet = with_root(size, line);  // default xMidYMid meet: scale 0.5, centred in x
    CHECK(near_point(first_start(meet), {25, 0}));
    CHECK(near_point(first_end(meet), {75, 50}));
    const Path none = with_root(size + R"(preserveAspectRatio="none")", line);
    CHECK(near_point(first_end(none), {100, 50}));
    const Path min = with_root(size + R"(preserveAspectRatio="xMinYMin meet")", line);
    CHECK(near_point(first_start(min), {0, 0}));
    const Path slice = with_root(size + R"(preserveAspectRatio="defer xMaxYMax slice")", line);
    CHECK(near_point(first_start(slice), {0, -50}));  // scale 1, aligned at the bottom
}

TEST_CASE("svg: lengths with units and percentages inside the drawing", "[svg]") {
    // absolute units are CSS units of the user space: 1in = 96 user units
    const Path p = with_root("", R"(<line x2="1in"/>)");
    CHECK(near_point(first_end(p), {25.4, 0}));
    const Path mm =
        parse(R"(<line x2="10mm"/>)");  // here one user unit is 1 mm, so 10mm = 37.8 units
    CHECK(near_point(first_end(mm), {10 * 96 / 25.4, 0}));
    const Path percent = parse(R"(<line x1="10%" y1="0" x2="50%" y2="25%"/>)");
    check_points(percent.subpaths[0], lines({{10, 0}, {50, 25}}));
    const Path r = parse(R"(<circle r="10%"/>)");  // of sqrt((w^2 + h^2) / 2) = 100
    CHECK(near_point(first_start(r), {10, 0}));
}

// ---- shapes -------------------------------------------------------------------------------

TEST_CASE("svg: rect, sharp and rounded", "[svg]") {
    check_points(parse(R"(<rect x="10" y="20" width="30" height="40"/>)").subpaths.at(0),
                 lines({{10, 20}, {40, 20}, {40, 60}, {10, 60}, {10, 20}}));
    const Subpath r =
        parse(R"(<rect x="10" y="20" width="30" height="40" rx="5"/>)").subpaths.at(0);
    REQUIRE(r.points.size() == 8 * 3 + 1);  // four sides, four quarter arcs
    Subpath top = r;
    top.points.clear();
    top.points.append(r.points, 0, 4);
    check_points(top, lines({{15, 20}, {35, 20}}));
    CHECK(near_point({r.points[6][0], r.points[6][1]}, {40, 25}));  // end of the first corner
    CHECK(near_point({r.points[12][0], r.points[12][1]}, {35, 60}));
    CHECK(near_point({r.points[24][0], r.points[24][1]}, {15, 20}));  // back at the start
    CHECK(worst_deviation(r, {{35, 25}, 5, 5, 0}, 1, 2) <= 0.01);
    CHECK(worst_deviation(r, {{15, 55}, 5, 5, 0}, 5, 6) <= 0.01);
    // ry given alone: rx = ry; different radii; radii clamped to half the size
    const Subpath ry = parse(R"(<rect width="30" height="40" ry="4"/>)").subpaths.at(0);
    CHECK(near_point({ry.points[0][0], ry.points[0][1]}, {4, 0}));
    const Subpath both = parse(R"(<rect width="30" height="40" rx="5" ry="10"/>)").subpaths.at(0);
    CHECK(worst_deviation(both, {{25, 10}, 5, 10, 0}, 1, 2) <= 0.01);
    const Subpath clamped =
        parse(R"(<rect width="30" height="40" rx="100" ry="auto"/>)").subpaths.at(0);
    // ry = auto = rx = 100 before clamping: rx 15, ry 20; all four sides vanish
    CHECK(near_point({clamped.points[0][0], clamped.points[0][1]}, {15, 0}));
    CHECK(near_point({clamped.points[3][0], clamped.points[3][1]}, {30, 20}));
    CHECK(clamped.points.size() == 4 * 3 + 1);
    CHECK(worst_deviation(clamped, {{15, 20}, 15, 20, 0}) <= 0.01);
    // zero size: nothing
    CHECK(parse(R"(<rect width="0" height="5"/><line x2="1"/>)").subpaths.size() == 1);
    // One radius zero: square corners (an SVG renderer's test: rx="0" ry="20" drew a diagonal
    // from (180, 160) to (20, 180) instead of the bottom side).
    for (const char* radii : {R"(rx="0" ry="20")", R"(rx="20" ry="0")"}) {
        INFO(radii);
        const Subpath sq =
            parse(std::string(R"(<rect x="20" y="20" width="160" height="160" )") + radii + "/>")
                .subpaths.at(0);
        check_points(sq, lines({{20, 20}, {180, 20}, {180, 180}, {20, 180}, {20, 20}}));
    }
}

TEST_CASE("svg: circle and ellipse as four quarter arcs from (cx + rx, cy)", "[svg]") {
    const Subpath c = parse(R"(<circle cx="50" cy="50" r="20"/>)").subpaths.at(0);
    REQUIRE(c.points.size() == 13);
    const Point quarters[] = {{70, 50}, {50, 70}, {30, 50}, {50, 30}, {70, 50}};
    for (int i = 0; i < 5; ++i)
        CHECK(near_point({c.points[3 * i][0], c.points[3 * i][1]}, quarters[i]));
    CHECK(c.points.back() == c.points.front());
    const double k = 4.0 / 3.0 * (std::sqrt(2.0) - 1) * 20;  // the classic quarter-circle handle
    CHECK(near_point({c.points[1][0], c.points[1][1]}, {70, 50 + k}));
    CHECK(near_point({c.points[2][0], c.points[2][1]}, {50 + k, 70}));
    CHECK(worst_deviation(c, {{50, 50}, 20, 20, 0}) <= 0.01);

    const Subpath e = parse(R"(<ellipse cx="50" cy="40" rx="30" ry="10"/>)", 0.001).subpaths.at(0);
    CHECK(near_point({e.points[0][0], e.points[0][1]}, {80, 40}));
    CHECK(e.points.back() == e.points.front());
    CHECK(worst_deviation(e, {{50, 40}, 30, 10, 0}) <= 0.001);
    const Subpath a = parse(R"(<ellipse cx="5" cy="5" rx="auto" ry="3"/>)").subpaths.at(0);
    CHECK(worst_deviation(a, {{5, 5}, 3, 3, 0}) <= 0.01);
    CHECK(parse(R"(<circle r="0"/><ellipse rx="0" ry="4"/><line x2="1"/>)").subpaths.size() == 1);
}

TEST_CASE("svg: line, polyline and polygon", "[svg]") {
    check_points(parse(R"(<line x1="1" y1="2" x2="3" y2="5"/>)").subpaths.at(0),
                 lines({{1, 2}, {3, 5}}));
    check_points(parse(R"(<polyline points="0,0 10,0 10,10"/>)").subpaths.at(0),
                 lines({{0, 0}, {10, 0}, {10, 10}}));
    check_points(parse(R"(<polygon points="0 0,10 0 10 10"/>)").subpaths.at(0),
                 lines({{0, 0}, {10, 0}, {10, 10}, {0, 0}}));
    check_points(parse(R"(<polygon points="0 0 10 0 10 10 0 0"/>)").subpaths.at(0),
                 lines({{0, 0}, {10, 0}, {10, 10}, {0, 0}}));
    CHECK(parse(R"(<polyline points=""/><polyline points="5 5"/><line x2="1"/>)").subpaths.size() ==
          1);
}

// ---- what is skipped ----------------------------------------------------------------------

TEST_CASE("svg: display none and hidden visibility are skipped", "[svg]") {
    const Path p = parse(R"(
        <path d="M 0 0 L 1 0" display="none"/>
        <path d="M 0 0 L 2 0" style="fill:red; Display : None !important"/>
        <g style="display:none"><path d="M 0 0 L 3 0"/></g>
        <g display="none"><g><path d="M 0 0 L 4 0"/></g></g>
        <path d="M 0 0 L 5 0" display="none" style="display:inline"/>
        <g visibility="hidden"><path d="M 0 0 L 6 0"/><path d="M 0 0 L 7 0" style="visibility:visible"/></g>
        <circle r="3" style="visibility:hidden"/>)");
    REQUIRE(p.subpaths.size() == 2);
    CHECK(p.subpaths[0].points.back() == PathPoint{5, 0});
    CHECK(p.subpaths[1].points.back() == PathPoint{7, 0});
}

TEST_CASE("svg: Inkscape documents: namespaces and non-geometry elements are skipped", "[svg]") {
    const std::string text = R"(<?xml version="1.0" encoding="UTF-8" standalone="no"?>
<!-- Created with Inkscape (http://www.inkscape.org/) -->
<svg width="100mm" height="100mm" viewBox="0 0 100 100" version="1.1" id="svg1"
   inkscape:version="1.3" sodipodi:docname="t.svg"
   xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape"
   xmlns:sodipodi="http://sodipodi.sourceforge.net/DTD/sodipodi-0.dtd"
   xmlns:xlink="http://www.w3.org/1999/xlink" xmlns="http://www.w3.org/2000/svg"
   xmlns:rdf="http://www.w3.org/1999/02/22-rdf-syntax-ns#" xmlns:foo="urn:foo">
  <sodipodi:namedview id="namedview1" pagecolor="#ffffff" inkscape:document-units="mm"/>
  <defs id="defs1"><path id="p" d="M 0 0 L 9 9"/><clipPath id="c"><rect width="5" height="5"/></clipPath></defs>
  <metadata><rdf:RDF/></metadata><title>t</title><desc>d</desc>
  <style>.a { stroke: red }</style>
  <symbol id="s"><circle r="4"/></symbol>
  <use xlink:href="#p" x="10"/>
  <text x="5" y="5">hello <tspan>world</tspan></text>
  <image width="10" height="10" xlink:href="data:,"/>
  <foo:layer><path d="M 0 0 L 8 8"/></foo:layer>
  <g inkscape:groupmode="layer" inkscape:label="Layer 1" id="layer1">
    <path style="fill:none;stroke:#000000" d="m 10,10 h 20" id="path1" sodipodi:nodetypes="cc" inkscape:label="a"/>
  </g>
</svg>
)";
    const Path p = parse_svg_path(text, "t.svg");
    REQUIRE(p.subpaths.size() == 2);
    check_points(p.subpaths[0], lines({{10, 0}, {19, 9}}));  // the <use> of the path in <defs>
    check_points(p.subpaths[1], lines({{10, 10}, {30, 10}}));
    CHECK(p.subpaths[1].location.line == 19);
    CHECK(p.subpaths[1].location.column == 44);  // the d attribute
    // a document whose SVG elements carry a prefix
    const Path prefixed =
        parse_svg_path(R"(<svg:svg xmlns:svg="http://www.w3.org/2000/svg" width="10mm" height="10mm"
        viewBox="0 0 10 10"><svg:g><svg:path d="M 1 1 L 2 2"/></svg:g></svg:svg>)",
                       "t.svg");
    check_points(prefixed.subpaths.at(0), lines({{1, 1}, {2, 2}}));
}

TEST_CASE("svg: <use> draws the element it refers to", "[svg]") {
    const std::string defs = R"~(<defs><path id="p" d="M 0 0 L 1 0"/>
        <g id="g" transform="scale(2)"><line id="l" x2="1"/></g>
        <symbol id="s" viewBox="0 0 10 10"><line x1="0" y1="0" x2="10" y2="10"/></symbol></defs>)~";
    // x and y move the copy, after the use's own transform
    const Path p = parse(defs + R"~(<use href="#p" x="5" y="6" transform="rotate(90)"/>)~");
    REQUIRE(p.subpaths.size() == 1);
    check_points(p.subpaths[0], lines({{-6, 5}, {-6, 6}}));
    // a group with its transform, by the XLink attribute Inkscape writes
    const Path g =
        parse(defs + R"(<use xmlns:xlink="http://www.w3.org/1999/xlink" xlink:href="#g" y="1"/>)");
    check_points(g.subpaths.at(0), lines({{0, 1}, {2, 1}}));
    // a symbol gets a viewport of the use's size
    const Path s = parse(defs + R"(<use href="#s" x="10" y="10" width="20" height="20"/>)");
    check_points(s.subpaths.at(0), lines({{10, 10}, {30, 30}}));
    // a use of a use; hidden uses; references to nothing or to other files draw nothing
    const Path u = parse(
        defs +
        R"(<use id="u1" href="#l" x="1"/><use href="#u1" y="1"/><use href="#p" display="none"/>
        <use href="#missing"/><use href="other.svg#p"/><use/>)");
    REQUIRE(u.subpaths.size() == 2);
    check_points(u.subpaths[1], lines({{1, 1}, {2, 1}}));
    // a use inside what it refers to
    CHECK(body_error(R"(<g id="loop"><line x2="1"/><use href="#loop"/></g>)") ==
          "t.svg:1:124: <use> refers to #loop, which contains this <use> (circular reference)");
    // copies of copies: 10 + 100 + ... + 100000 uses
    std::string tree = R"(<defs><g id="a0"/>)";
    for (int level = 1; level <= 5; ++level) {
        tree += "<g id=\"a" + std::to_string(level) + "\">";
        for (int i = 0; i < 10; ++i) tree += "<use href=\"#a" + std::to_string(level - 1) + "\"/>";
        tree += "</g>";
    }
    tree += R"(</defs><use href="#a5"/>)";
    CHECK_THAT(body_error(tree),
               Catch::Matchers::EndsWith(": too many <use> copies (more than 100000)"));
}

TEST_CASE("svg: zero-length pieces and empty subpaths are dropped", "[svg]") {
    check_points(one("M 0 0 L 0 0 L 10 0"), lines({{0, 0}, {10, 0}}));
    check_points(one("M 5 5 C 5 5 5 5 5 5 L 6 5 Q 6 5 6 5"), lines({{5, 5}, {6, 5}}));
    check_points(one("M 0 0 L 1e-12 0 L 10 0"), lines({{0, 0}, {10, 0}}));
    const Path p = parse(R"(<path d="M 1 1 M 2 2 L 3 3 M 4 4 Z"/>)");
    REQUIRE(p.subpaths.size() == 1);
    check_points(p.subpaths[0], lines({{2, 2}, {3, 3}}));
    CHECK(body_error(R"(<path d="M 5 5"/><path d="M 0 0 Z"/><path d=""/><path/><circle r="0"/>
        <line x1="1" y1="1" x2="1" y2="1"/><rect width="0" height="5"/><polygon points="1 1"/>)") ==
          "t.svg:1:1: no drawable paths");
}

TEST_CASE("svg: subpaths remember where they start", "[svg]") {
    const Path p = parse_svg_path(
        "<svg xmlns=\"http://www.w3.org/2000/svg\">\n  <path\n     id=\"a\"\n"
        "     d=\"M 0 0 L 1 1 M 5 5 L 6 6\" />\n  <rect width=\"1\" height=\"1\"/>\n</svg>",
        "t.svg");
    REQUIRE(p.subpaths.size() == 3);
    CHECK(p.subpaths[0].location.line == 4);
    CHECK(p.subpaths[0].location.column == 6);
    CHECK(p.subpaths[1].location.line == 4);
    CHECK(p.subpaths[2].location.line == 5);
    CHECK(p.subpaths[2].location.column == 3);
}

// ---- errors -------------------------------------------------------------------------------

TEST_CASE("svg: malformed XML and a wrong root name the place", "[svg]") {
    CHECK(error_of("<svg>\n  <g>\n  </svg>") == "t.svg:3:5: invalid XML: start-end tags mismatch");
    CHECK(error_of("<svg>\n  <path d=\"M 0 0/>\n</svg>") ==
          "t.svg:2:12: invalid XML: error parsing element attribute");
    CHECK(error_of("") == "t.svg:1:1: invalid XML: no document element found");
    CHECK(error_of("<svg><!-- x </svg>") == "t.svg:1:18: invalid XML: error parsing comment");
    CHECK(error_of("<?xml version=\"1.0\"?>\n<html><path d=\"M 0 0 L 1 1\"/></html>") ==
          "t.svg:2:1: root element is <html>, expected <svg>");
    // columns count characters, not bytes
    CHECK(error_of("<svg><!-- \xC3\xA9t\xC3\xA9 --><g transform=\"#\"/></svg>") ==
          "t.svg:1:21: transform: expected a transform name (matrix, translate, scale, rotate, "
          "skewX or skewY), "
          "found '#' at character 1");
}

TEST_CASE("svg: path data errors name the attribute and the character", "[svg]") {
    const std::string head =
        "<svg xmlns=\"http://www.w3.org/2000/svg\">\n  <path\n     id=\"p\"\n     d=\"";
    const auto path_error = [&](const std::string& d) {
        return error_of(head + d + "\" />\n</svg>");
    };
    CHECK(path_error("M 0 0 C 1 2 3 4 5") ==
          "t.svg:4:6: path data: expected a number after 'C' at character 18");
    CHECK(path_error("M 0 0 C 1 2 3 4 5 6 7") ==
          "t.svg:4:6: path data: expected a number after 'C' at character 22");
    CHECK(path_error("M 0 0 X 5") == "t.svg:4:6: path data: unknown command 'X' at character 7");
    CHECK(path_error("M 0 0 e 5") == "t.svg:4:6: path data: unknown command 'e' at character 7");
    CHECK(path_error("L 0 0") ==
          "t.svg:4:6: path data: must start with a moveto ('M' or 'm'), found 'L' at character 1");
    CHECK(path_error("10 10") ==
          "t.svg:4:6: path data: must start with a moveto ('M' or 'm'), found a number at "
          "character 1");
    CHECK(path_error("M 0") == "t.svg:4:6: path data: expected a number after 'M' at character 4");
    CHECK(path_error("M 0 0 1") ==
          "t.svg:4:6: path data: expected a number after 'M' at character 8");
    CHECK(path_error("M 0 0 L 1 1 Z 5 5") ==
          "t.svg:4:6: path data: unexpected number after 'Z' (it takes none) at character 15");
    CHECK(path_error("M 0 0 1 1,,2 2") ==
          "t.svg:4:6: path data: unexpected ',' after 'M' at character 11");
    CHECK(path_error("M 0 0 L 1,,1") ==
          "t.svg:4:6: path data: expected a number after 'L' at character 11");
    CHECK(path_error("M 0 0 L 1 1 # 2") ==
          "t.svg:4:6: path data: unexpected character '#' at character 13");
    CHECK(path_error("M 0 0 A 5 5 0 2 0 10 0") ==
          "t.svg:4:6: path data: expected a flag (0 or 1) after 'A' at character 15");
    CHECK(path_error("M 0 0 L 1e999 0") ==
          "t.svg:4:6: path data: number '1e999' is out of range (not finite) at character 9");
    CHECK(path_error("M 0 0 L 1 -") ==
          "t.svg:4:6: path data: expected a number after 'L' at character 11");
}

TEST_CASE("svg: transform errors", "[svg]") {
    CHECK(
        body_error(R"~(<g transform="rotate(45deg)"/>)~") ==
        "t.svg:1:95: transform: expected a number or ')' in 'rotate(', found 'd' at character 10");
    CHECK(body_error(R"~(<g transform="spin(3)"/>)~") ==
          "t.svg:1:95: transform: unknown transform 'spin' (expected matrix, translate, scale, "
          "rotate, skewX or skewY) at character 1");
    CHECK(body_error(R"~(<g transform="translate(1 2 3)"/>)~") ==
          "t.svg:1:95: transform: translate takes 1 or 2 numbers, got 3 at character 1");
    CHECK(body_error(R"~(<g transform="scale(1) matrix(1 2 3)"/>)~") ==
          "t.svg:1:95: transform: matrix takes 6 numbers, got 3 at character 10");
    CHECK(body_error(R"~(<g transform="rotate(1 2)"/>)~") ==
          "t.svg:1:95: transform: rotate takes 1 or 3 numbers, got 2 at character 1");
    CHECK(body_error(R"~(<g transform="skewX()"/>)~") ==
          "t.svg:1:95: transform: skewX takes 1 number, got 0 at character 1");
    CHECK(body_error(R"(<g transform="translate(1 2"/>)") ==
          "t.svg:1:95: transform: expected ')' to close 'translate(' at character 14");
    CHECK(body_error(R"~(<g transform="(1)"/>)~") ==
          "t.svg:1:95: transform: expected a transform name (matrix, translate, scale, rotate, "
          "skewX or skewY), "
          "found '(' at character 1");
    CHECK(body_error(R"(<g transform="translate 1 2"/>)") ==
          "t.svg:1:95: transform: expected '(' after 'translate' at character 11");
    CHECK(body_error(R"~(<g transform="scale(1e999)"/>)~") ==
          "t.svg:1:95: transform: number '1e999' is out of range (not finite) at character 7");
    // on a shape, inside a group: the shape's own attribute
    CHECK(body_error(R"~(<g><circle r="1" transform="scale(,2)"/></g>)~") ==
          "t.svg:1:109: transform: expected a number or ')' in 'scale(', found ',' at character 7");
}

TEST_CASE("svg: size, unit and viewBox errors", "[svg]") {
    CHECK(body_error(R"(<rect width="-5" height="3"/>)") ==
          "t.svg:1:98: <rect> width must not be negative (got -5)");
    CHECK(body_error(R"(<rect width="5" height="-3mm"/>)") ==
          "t.svg:1:108: <rect> height must not be negative (got -3mm)");
    CHECK(body_error(R"(<rect width="5" height="3" rx="-1"/>)") ==
          "t.svg:1:119: <rect> rx must not be negative (got -1)");
    CHECK(body_error(R"(<circle r="-1"/>)") ==
          "t.svg:1:100: <circle> r must not be negative (got -1)");
    CHECK(body_error(R"(<ellipse rx="1" ry="-2"/>)") ==
          "t.svg:1:108: <ellipse> ry must not be negative (got -2)");
    CHECK(body_error(R"(<circle r="1e999"/>)") ==
          "t.svg:1:100: r: number '1e999' is out of range (not finite) at character 1");
    CHECK(body_error(R"(<circle r="two"/>)") ==
          "t.svg:1:100: r: expected a length (a number with an optional unit), found 'two' at "
          "character 1");
    CHECK(body_error(R"(<circle r="2 px"/>)") ==
          "t.svg:1:100: r: unexpected 'p' after the length at character 3");
    CHECK(body_error(R"(<line x2="3em"/>)") ==
          "t.svg:1:98: x2: unknown unit 'em' (expected mm, cm, in, pt, pc, px, % or none) at "
          "character 2");
    CHECK(error_of(R"(<svg width="10em" height="1in"><line x2="1"/></svg>)") ==
          "t.svg:1:6: width: unknown unit 'em' (expected mm, cm, in, pt, pc, px, % or none) at "
          "character 3");
    CHECK(error_of(R"(<svg width="-10" height="10"><line x2="1"/></svg>)") ==
          "t.svg:1:6: <svg> width must not be negative (got -10)");
    CHECK(error_of(R"(<svg viewBox="0 0 0 100"><line x2="1"/></svg>)") ==
          "t.svg:1:6: viewBox: width and height must be positive (got 0 x 100)");
    CHECK(error_of(R"(<svg viewBox="0 0 100 -1"><line x2="1"/></svg>)") ==
          "t.svg:1:6: viewBox: width and height must be positive (got 100 x -1)");
    CHECK(error_of(R"(<svg viewBox="0 0 100"><line x2="1"/></svg>)") ==
          "t.svg:1:6: viewBox: expected 4 numbers (min-x min-y width height), got 3");
    CHECK(error_of(R"(<svg viewBox="0 0 1e999 1"><line x2="1"/></svg>)") ==
          "t.svg:1:6: viewBox: number '1e999' is out of range (not finite) at character 5");
    CHECK(
        error_of(
            R"(<svg viewBox="0 0 10 10" preserveAspectRatio="xMidYMid cover"><line x2="1"/></svg>)") ==
        "t.svg:1:26: preserveAspectRatio: unknown value 'xMidYMid cover' (expected none or "
        "xMinYMin ... xMaxYMax, "
        "then meet or slice)");
    CHECK(error_of(R"(<svg><line x2="50%"/></svg>)") ==
          "t.svg:1:12: x2: a percentage needs a viewport size (give the <svg> a viewBox or a width "
          "and height) at character 3");
    CHECK(error_of(R"(<svg><svg viewBox="0 0 1 1"><line x2="1"/></svg></svg>)") ==
          "t.svg:1:11: a viewBox needs a viewport size (give <svg> a width and height, or the root "
          "<svg> a size)");
    CHECK(body_error(R"(<polyline points="0 0 1 1 2"/>)") ==
          "t.svg:1:102: points: odd number of coordinates (5)");
    CHECK(body_error(R"(<polygon points="0 0 1 x"/>)") ==
          "t.svg:1:101: points: expected a number, found 'x' at character 7");
}

TEST_CASE("svg: coordinates beyond 1e6 mm and bad tolerances", "[svg]") {
    // a line is a polyline of its ends: the end point is the first out of range
    CHECK(body_error(R"(<path d="M 0 0 L 3000000 0"/>)") ==
          "t.svg:1:98: coordinate 3000000 mm is out of range (|value| <= 1e+06 mm after units and "
          "transforms)");
    CHECK(
        body_error(
            R"~(<g transform="scale(1e300)"><g transform="scale(1e300)"><line x2="1e10"/></g></g>)~") ==
        "t.svg:1:148: coordinate is not finite after units and transforms");
    CHECK(body_error(R"(<circle r="600000" cx="500000"/>)") ==
          "t.svg:1:92: coordinate 1100000 mm is out of range (|value| <= 1e+06 mm after units and "
          "transforms)");
    CHECK(error_of(doc(R"(<line x2="1"/>)"), 0) ==
          "t.svg: tolerance must be positive and finite (got 0 mm)");
    CHECK(error_of(doc(R"(<line x2="1"/>)"), -1) ==
          "t.svg: tolerance must be positive and finite (got -1 mm)");
    CHECK(error_of(doc(R"(<line x2="1"/>)"), INFINITY) ==
          "t.svg: tolerance must be positive and finite (got inf mm)");
}

TEST_CASE("svg: a missing file is an input error naming it", "[svg]") {
    CHECK_THROWS_WITH(load_svg_path("/nonexistent/p.svg"), "/nonexistent/p.svg: cannot open file");
}

// ---- the example --------------------------------------------------------------------------

TEST_CASE("svg: examples/landscape.svg", "[svg]") {
    const Path p = load_svg_path(source_dir() + "/examples/landscape.svg");
    CHECK(p.axes == 2);
    CHECK(p.subpaths.size() == 42);
    for (const Subpath& s : p.subpaths) {
        CHECK((s.basis == PathBasis::kBezier || s.basis == PathBasis::kPolyline));
        CHECK_FALSE(s.closed);
        REQUIRE(point_count_problem(s).empty());
        for (const PathPoint& q : s.points) {  // inside the 160 x 120 mm page
            CHECK(q[0] >= 0);
            CHECK(q[0] <= 160);
            CHECK(q[1] >= 0);
            CHECK(q[1] <= 120);
        }
        for (std::size_t i = 0; i + 3 < s.points.size(); i += 3) {  // no zero-length piece
            CHECK_FALSE((s.points[i] == s.points[i + 1] && s.points[i] == s.points[i + 2] &&
                         s.points[i] == s.points[i + 3]));
        }
        CHECK_FALSE((s.points.front() == PathPoint{0, 0}));  // the hidden sketch layer is skipped
    }
    // the sun: circle r = 36 at (530, 100) in a 4-units-per-mm viewBox -> r 9 mm at (132.5, 25)
    bool found = false;
    for (const Subpath& s : p.subpaths) {
        if (std::hypot(s.points[0][0] - 141.5, s.points[0][1] - 25) < 1e-9) {
            found = true;
            CHECK(worst_deviation(s, {{132.5, 25}, 9, 9, 0}) <= 0.01);
        }
    }
    CHECK(found);
    // a coarser tolerance needs no more points (each quarter circle is one piece already), a finer
    // one more
    const auto count = [](const Path& path) {
        std::size_t n = 0;
        for (const Subpath& s : path.subpaths) n += s.points.size();
        return n;
    };
    CHECK(count(load_svg_path(source_dir() + "/examples/landscape.svg", 1.0)) <= count(p));
    CHECK(count(load_svg_path(source_dir() + "/examples/landscape.svg", 1e-4)) > count(p));
}
