// The G-code reader: syntax, modal state, exact geometry of lines, arcs and splines, pen
// control, feeds, and each error with its exact message.
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "pathstream/host/gcode_path.hpp"
#include "pathstream/host/geometry.hpp"
#include "pathstream/host/path_order.hpp"
#include "pathstream/host/work_area.hpp"
#include "pathstream/machine/input_error.hpp"
#include "pathstream/machine/machine.hpp"

using namespace pathstream::host;

namespace {

constexpr double kExact = 1e-9;
constexpr double kPi = std::numbers::pi;

Path gcode(const std::string& text, const GcodeOptions& options = {}) {
    return parse_gcode_path(text, "t.ngc", options);
}

std::string error_of(const std::string& text, const GcodeOptions& options = {}) {
    try {
        gcode(text, options);
    } catch (const InputError& e) {
        return e.what();
    }
    return "no error";
}

GcodeOptions spindle() {
    GcodeOptions o;
    o.pen = PenControl::kSpindle;
    return o;
}

struct P2 {
    double x, y;
};

bool near(const PathPoint& p, double x, double y, double eps = kExact) {
    return p.size() == 2 && std::fabs(p[0] - x) <= eps && std::fabs(p[1] - y) <= eps;
}

/// A subpath's Bezier chain: its points, or for a polyline (a run of lines only) its pieces
/// with their control points at the thirds.
std::vector<PathPoint> chain_of(const Subpath& sp) {
    std::vector<PathPoint> out;
    for (std::size_t i = 0; i < sp.points.size(); ++i) {
        const PathPoint p = sp.points[i];
        if (sp.basis == PathBasis::kPolyline && i > 0) {
            const PathPoint a = out.back();
            out.push_back({a[0] + (p[0] - a[0]) / 3, a[1] + (p[1] - a[1]) / 3});
            out.push_back({a[0] + 2 * (p[0] - a[0]) / 3, a[1] + 2 * (p[1] - a[1]) / 3});
        }
        out.push_back(p);
    }
    return out;
}

/// The subpath's Bezier chain must be exactly these points (within 1e-9).
void check_points(const Subpath& sp, const std::vector<P2>& expected) {
    const std::vector<PathPoint> chain = chain_of(sp);
    REQUIRE(chain.size() == expected.size());
    for (std::size_t i = 0; i < expected.size(); ++i) {
        INFO("point " << i << ": " << chain[i][0] << ", " << chain[i][1]);
        CHECK(near(chain[i], expected[i].x, expected[i].y));
    }
}

/// Line pieces a -> b -> ... as a Bezier chain with control points at thirds.
std::vector<P2> line_chain(const std::vector<P2>& corners) {
    std::vector<P2> out{corners.front()};
    for (std::size_t i = 1; i < corners.size(); ++i) {
        const P2 a = corners[i - 1], b = corners[i];
        out.push_back({a.x + (b.x - a.x) / 3, a.y + (b.y - a.y) / 3});
        out.push_back({a.x + 2 * (b.x - a.x) / 3, a.y + 2 * (b.y - a.y) / 3});
        out.push_back(b);
    }
    return out;
}

P2 bezier(const Subpath& sp, std::size_t piece, double t) {
    const auto& q = sp.points;
    const std::size_t k = 3 * piece;
    const double u = 1 - t;
    const double w0 = u * u * u, w1 = 3 * u * u * t, w2 = 3 * u * t * t, w3 = t * t * t;
    return {w0 * q[k][0] + w1 * q[k + 1][0] + w2 * q[k + 2][0] + w3 * q[k + 3][0],
            w0 * q[k][1] + w1 * q[k + 1][1] + w2 * q[k + 2][1] + w3 * q[k + 3][1]};
}

double wrap(double a) {
    while (a > kPi) a -= 2 * kPi;
    while (a < -kPi) a += 2 * kPi;
    return a;
}

/// Pieces [first, first + count) of `sp` follow the arc about `c` whose radius goes from r0 to
/// r1 (a circle when equal) within `tolerance`, sampled densely; each piece turns at most 90
/// degrees, always the same way, and together they turn `sweep` radians.
void check_arc(const Subpath& sp, std::size_t first, std::size_t count, P2 c, double r0, double r1,
               double sweep, double tolerance) {
    REQUIRE(sp.points.size() >= 3 * (first + count) + 1);
    constexpr int kSamples = 2000;
    double turned = 0;
    int backwards = 0;
    P2 previous = bezier(sp, first, 0);
    for (std::size_t k = first; k < first + count; ++k) {
        double piece_turn = 0;
        for (int s = 1; s <= kSamples; ++s) {
            const P2 p = bezier(sp, k, static_cast<double>(s) / kSamples);
            const double step = wrap(std::atan2(p.y - c.y, p.x - c.x) -
                                     std::atan2(previous.y - c.y, previous.x - c.x));
            if (!(step * sweep > 0)) ++backwards;  // always turning the arc's way
            piece_turn += step;
            turned += step;
            const double expected = r0 + (r1 - r0) * turned / sweep;
            const double distance = std::hypot(p.x - c.x, p.y - c.y);
            if (std::fabs(distance - expected) > tolerance) {
                FAIL("piece " << k << " sample " << s << " is " << distance - expected
                              << " mm off the arc");
            }
            previous = p;
        }
        CHECK(std::fabs(piece_turn) <= kPi / 2 + 1e-12);
    }
    CHECK(backwards == 0);
    CHECK(turned == Approx(sweep).margin(1e-9));
}

std::string source_dir() {
#ifdef PATHSTREAM_SOURCE_DIR
    return PATHSTREAM_SOURCE_DIR;
#else
    const std::string here = __FILE__;
    return here.substr(0, here.rfind("/tests/host/"));
#endif
}

const double kQuarter = 4.0 / 3.0 * std::tan(kPi / 8);  // a quarter circle's tangent length

}  // namespace

// ---- syntax and modal state ---------------------------------------------------------------

TEST_CASE(
    "G-code: a run of lines is a polyline; with a curve, a Bezier chain with control points at "
    "thirds",
    "[host][gcode]") {
    const Path p = gcode("G21 G90 G17\nG0 X0 Y0\nG1 Z-1 F600\nG1 X30 Y0\nX30 Y30\nG0 Z5\nM2\n");
    REQUIRE(p.axes == 2);
    REQUIRE(p.subpaths.size() == 1);
    const Subpath& sp = p.subpaths[0];
    CHECK(sp.basis == PathBasis::kPolyline);
    CHECK(sp.points == PointList{{0, 0}, {30, 0}, {30, 30}});
    // An arc after lines: the whole run becomes one Bezier chain, the lines at thirds.
    const Path m = gcode("G0 X0 Y0\nG1 Z-1\nG1 X30\nX30 Y30\nG2 X40 Y40 I10 J0\nG1 X50\n");
    REQUIRE(m.subpaths.size() == 1);
    CHECK(m.subpaths[0].basis == PathBasis::kBezier);
    REQUIRE(m.subpaths[0].points.size() == 3 * 4 + 1);
    const std::vector<P2> lines = line_chain({{0, 0}, {30, 0}, {30, 30}});
    for (std::size_t i = 0; i < lines.size(); ++i)
        CHECK(near(m.subpaths[0].points[i], lines[i].x, lines[i].y));
    CHECK(near(m.subpaths[0].points[12], 50, 40));
    CHECK(near(m.subpaths[0].points[10], 40 + 10.0 / 3, 40));
    CHECK_FALSE(sp.closed);
    CHECK(sp.feed == 10.0);  // 600 mm/min
    CHECK(sp.location.line == 4);
    CHECK(sp.location.column == 1);
    check_points(sp, line_chain({{0, 0}, {30, 0}, {30, 30}}));
    // A modal move (no G word) is located at its block's first word, the N word if any.
    const Path q = gcode("G0 Z-1\nG1\n  N7 X1 Y2\n");
    CHECK(q.subpaths[0].location.line == 3);
    CHECK(q.subpaths[0].location.column == 3);
}

TEST_CASE("G-code: words need no spaces, case, comments, line numbers and % are ignored",
          "[host][gcode]") {
    const Path p = gcode(
        "%\n(header comment)\r\nn10 g21g90 ; set up\nN20 G0X1Y2(move)Z1\nN30G1z0f120\n"
        "  N40 g1 x 4 y6 ; draw (not a comment)\n%\n");
    REQUIRE(p.subpaths.size() == 1);
    CHECK(p.subpaths[0].feed == 2.0);
    CHECK(p.subpaths[0].location.line == 6);
    CHECK(p.subpaths[0].location.column == 7);  // the G1 word: the move's motion code
    check_points(p.subpaths[0], line_chain({{1, 2}, {4, 6}}));
}

TEST_CASE("G-code: the motion mode persists, G0 is travel and ends the run", "[host][gcode]") {
    const Path p = gcode("G0 Z-1\nG1 X10\nY10\nG0 X20\nX30\nG1 Y20\nX40\n");
    REQUIRE(p.subpaths.size() == 2);
    check_points(p.subpaths[0], line_chain({{0, 0}, {10, 0}, {10, 10}}));
    check_points(p.subpaths[1], line_chain({{30, 10}, {30, 20}, {40, 20}}));
    CHECK(p.subpaths[1].location.line == 6);
}

TEST_CASE("G-code: pen by Z: down at Z <= z_down_max, up above it and before any Z",
          "[host][gcode]") {
    // No Z yet: the pen counts as up, so the first line is travel.
    const Path a = gcode("G1 X5\nZ0\nX10\nZ0.1\nX20\nZ-3\nX30\n");
    REQUIRE(a.subpaths.size() == 2);
    check_points(a.subpaths[0], line_chain({{5, 0}, {10, 0}}));
    check_points(a.subpaths[1], line_chain({{20, 0}, {30, 0}}));

    GcodeOptions raised;
    raised.z_down_max = 0.5;
    const Path b = gcode("G0 Z0.5\nG1 X10\nZ0.6\nX20\n", raised);
    REQUIRE(b.subpaths.size() == 1);
    check_points(b.subpaths[0], line_chain({{0, 0}, {10, 0}}));

    // A move that changes Z is drawn only when it stays down all the way.
    const Path c = gcode("G0 Z5\nG1 X10 Z-1\nX20 Z-2\nX30 Z1\nX40 Z-1\nX50\n");
    REQUIRE(c.subpaths.size() == 2);
    check_points(c.subpaths[0], line_chain({{10, 0}, {20, 0}}));
    check_points(c.subpaths[1], line_chain({{40, 0}, {50, 0}}));

    // M3/M5 do nothing in Z mode.
    const Path d = gcode("G0 Z-1\nM5\nG1 X10\nM3\nX20\n");
    REQUIRE(d.subpaths.size() == 1);
    check_points(d.subpaths[0], line_chain({{0, 0}, {10, 0}, {20, 0}}));
}

TEST_CASE("G-code: pen by spindle: down between M3/M4 and M5, Z ignored", "[host][gcode]") {
    const Path p = gcode(
        "G0 X0 Y0 Z5\nM3 S1000\nG1 X10\nM5\nG1 X20\nM4\nG1 Y10\nG0 Y20\nG1 X30\nM5 G1 X40\n"
        "M3 G1 Y30\nM5 M2\n",
        spindle());
    REQUIRE(p.subpaths.size() == 4);
    check_points(p.subpaths[0], line_chain({{0, 0}, {10, 0}}));
    check_points(p.subpaths[1], line_chain({{20, 0}, {20, 10}}));
    check_points(p.subpaths[2], line_chain({{20, 20}, {30, 20}}));
    check_points(p.subpaths[3], line_chain({{40, 20}, {40, 30}}));
    CHECK(p.subpaths[3].location.line == 11);
}

TEST_CASE("G-code: inches (G20) and millimetres (G21) convert coordinates and feeds",
          "[host][gcode]") {
    const Path p = gcode("G20 G0 X1 Y0 Z-0.1\nG1 X2 F10\nG21 X60 F600\n");
    REQUIRE(p.subpaths.size() == 2);
    check_points(p.subpaths[0], line_chain({{25.4, 0}, {50.8, 0}}));
    CHECK(p.subpaths[0].feed == Approx(10 * 25.4 / 60));
    check_points(p.subpaths[1], line_chain({{50.8, 0}, {60, 0}}));
    CHECK(p.subpaths[1].feed == 10.0);
}

TEST_CASE("G-code: incremental distances (G91) and back to absolute (G90)", "[host][gcode]") {
    const Path p = gcode("G91 G0 X10 Y10 Z-1\nG1 X5\nY5\nX-5 Y-5\nG90 X0 Y0\n");
    REQUIRE(p.subpaths.size() == 1);
    check_points(p.subpaths[0], line_chain({{10, 10}, {15, 10}, {15, 15}, {10, 10}, {0, 0}}));
}

TEST_CASE("G-code: feeds in mm/s, a new F in a pen-down run starts a new subpath",
          "[host][gcode]") {
    const Path p = gcode(
        "G0 Z-1\nG1 X10 F600\nX20\nX30 F1200\nX40 F1200\nF600\nX50\nG0 Z1\nF300\nG0 X60\nG1 "
        "Z-1\nX70\n");
    REQUIRE(p.subpaths.size() == 4);
    check_points(p.subpaths[0], line_chain({{0, 0}, {10, 0}, {20, 0}}));
    check_points(p.subpaths[1], line_chain({{20, 0}, {30, 0}, {40, 0}}));
    check_points(p.subpaths[2], line_chain({{40, 0}, {50, 0}}));
    check_points(p.subpaths[3], line_chain({{60, 0}, {70, 0}}));
    CHECK(p.subpaths[0].feed == 10.0);
    CHECK(p.subpaths[1].feed == 20.0);
    CHECK(p.subpaths[1].location.line == 4);
    CHECK(p.subpaths[2].feed == 10.0);
    CHECK(p.subpaths[2].location.line == 7);
    CHECK(p.subpaths[3].feed == 5.0);

    // An F that changes and changes back before the next piece splits nothing; no F: feed 0.
    const Path q = gcode("G0 Z-1\nG1 X10\nF100\nF200\nX20\n");
    REQUIRE(q.subpaths.size() == 2);
    CHECK(q.subpaths[0].feed == 0.0);
    const Path r = gcode("G0 Z-1\nG1 X10 F60\nF100\nF60\nX20\n");
    REQUIRE(r.subpaths.size() == 1);
    CHECK(r.subpaths[0].feed == 1.0);
}

TEST_CASE("G-code: zero-length pieces are dropped and empty runs skipped", "[host][gcode]") {
    const Path p =
        gcode("G0 Z-1\nG1 X0 Y0\nG1 Z-2\nG1\nG0 Z5\nG0 X10\nG1 Z-1\nG1 X10\nX20\nX20 Y0\n");
    REQUIRE(p.subpaths.size() == 1);
    check_points(p.subpaths[0], line_chain({{10, 0}, {20, 0}}));
    CHECK(p.subpaths[0].location.line == 9);
}

TEST_CASE("G-code: accepted codes change no geometry, M2 and M30 end the program",
          "[host][gcode]") {
    const Path p = gcode(
        "G17 G21 G40 G49 G54 G61 G80 G90 G94 G91.1 T1 S500\nG4 P0.5\nG64 P0.01 Q0.01\nG61.1\n"
        "M3 S100\nM5\nG0 Z-1\nG1 X10\nM30\nthis is @ not G-code\n");
    REQUIRE(p.subpaths.size() == 1);
    check_points(p.subpaths[0], line_chain({{0, 0}, {10, 0}}));
    const Path q = gcode("G0 Z-1\nG1 X10 M2\nG1 X20\n");
    check_points(q.subpaths[0], line_chain({{0, 0}, {10, 0}}));
}

// ---- arcs ---------------------------------------------------------------------------------

TEST_CASE("G-code: a quarter circle (G3, I J) is one cubic with the standard control points",
          "[host][gcode]") {
    const Path p = gcode("G0 X10 Y0 Z-1\nG3 X0 Y10 I-10 J0\n");
    REQUIRE(p.subpaths.size() == 1);
    check_points(p.subpaths[0], {{10, 0}, {10, 10 * kQuarter}, {10 * kQuarter, 10}, {0, 10}});
    check_arc(p.subpaths[0], 0, 1, {0, 0}, 10, 10, kPi / 2, 0.01);
    // The same arc with an absolute center (G90.1), and clockwise back (G2).
    const Path q = gcode("G90.1 G0 X10 Y0 Z-1\nG3 X0 Y10 I0 J0\nG2 X10 Y0 I0 J0\n");
    check_points(q.subpaths[0], {{10, 0},
                                 {10, 10 * kQuarter},
                                 {10 * kQuarter, 10},
                                 {0, 10},
                                 {10 * kQuarter, 10},
                                 {10, 10 * kQuarter},
                                 {10, 0}});
}

TEST_CASE("G-code: arcs split into pieces of at most 90 degrees within the tolerance",
          "[host][gcode]") {
    for (const double tolerance : {0.01, 1e-4, 1e-6}) {
        GcodeOptions o;
        o.arc_tolerance_mm = tolerance;
        // Clockwise semicircle over the top, radius 100.
        const Path p = gcode("G0 X0 Y0 Z-1\nG2 X200 Y0 I100 J0\n", o);
        REQUIRE(p.subpaths.size() == 1);
        const Subpath& sp = p.subpaths[0];
        const std::size_t pieces = (sp.points.size() - 1) / 3;
        INFO("tolerance " << tolerance << ", " << pieces << " pieces");
        CHECK(pieces >= 2);
        CHECK(near(sp.points.front(), 0, 0, 0));
        CHECK(near(sp.points.back(), 200, 0, 0));
        check_arc(sp, 0, pieces, {100, 0}, 100, 100, -kPi, tolerance);
        CHECK(bezier(sp, pieces / 2, pieces % 2 ? 0.5 : 0).y > 99.99);  // over the top
    }
    // The same points counterclockwise go under.
    const Path q = gcode("G0 X0 Y0 Z-1\nG3 X200 Y0 I100 J0\n");
    const std::size_t pieces = (q.subpaths[0].points.size() - 1) / 3;
    check_arc(q.subpaths[0], 0, pieces, {100, 0}, 100, 100, kPi, 0.01);
}

TEST_CASE("G-code: full circles with I J, several turns with P", "[host][gcode]") {
    const Path p = gcode("G0 X10 Y0 Z-1\nG2 X10 Y0 I-10 J0\nG3 I-10 P2\n");
    REQUIRE(p.subpaths.size() == 1);
    const Subpath& sp = p.subpaths[0];
    REQUIRE(sp.points.size() == 3 * 12 + 1);  // 4 quarter pieces clockwise, 8 counterclockwise
    check_arc(sp, 0, 4, {0, 0}, 10, 10, -2 * kPi, 0.01);
    check_arc(sp, 4, 8, {0, 0}, 10, 10, 4 * kPi, 0.01);
    CHECK(near(sp.points[12], 10, 0, 0));
    CHECK(near(sp.points.back(), 10, 0, 0));
}

TEST_CASE("G-code: R arcs: positive R the short way, negative R the long way", "[host][gcode]") {
    struct Case {
        const char* move;
        P2 center;
        double sweep;
    } cases[] = {
        {"G2 X10 Y10 R10", {10, 0}, -kPi / 2},
        {"G2 X10 Y10 R-10", {0, 10}, -3 * kPi / 2},
        {"G3 X10 Y10 R10", {0, 10}, kPi / 2},
        {"G3 X10 Y10 R-10", {10, 0}, 3 * kPi / 2},
    };
    for (const Case& c : cases) {
        INFO(c.move);
        const Path p = gcode(std::string("G0 X0 Y0 Z-1\n") + c.move + "\n");
        const std::size_t pieces = (p.subpaths[0].points.size() - 1) / 3;
        CHECK(pieces == (std::fabs(c.sweep) > kPi ? 3u : 1u));
        check_arc(p.subpaths[0], 0, pieces, c.center, 10, 10, c.sweep, 0.01);
        CHECK(near(p.subpaths[0].points.back(), 10, 10, 0));
    }
    // A semicircle by R, and an R slightly too short for the chord (within LinuxCNC's 0.00127 mm).
    const Path s = gcode("G0 X0 Y0 Z-1\nG3 X20 Y0 R10\nG3 X0 Y0 R9.999\n");
    check_arc(s.subpaths[0], 0, 2, {10, 0}, 10, 10, kPi, 0.01);
    check_arc(s.subpaths[0], 2, 2, {10, 0}, 10, 10, kPi, 0.01);
}

TEST_CASE("G-code: arcs in incremental mode and in inches", "[host][gcode]") {
    const Path p = gcode("G91 G0 X10 Y0 Z-1\nG3 X-10 Y10 I-10 J0\nG20 G2 X0.5 Y0.5 I0.5\n");
    REQUIRE(p.subpaths.size() == 1);
    check_arc(p.subpaths[0], 0, 1, {0, 0}, 10, 10, kPi / 2, 0.01);
    const std::size_t pieces = (p.subpaths[0].points.size() - 1) / 3 - 1;
    check_arc(p.subpaths[0], 1, pieces, {12.7, 10}, 12.7, 12.7, -kPi / 2, 0.01);
    CHECK(near(p.subpaths[0].points.back(), 12.7, 22.7));
}

TEST_CASE("G-code: an end point slightly off the circle gives a spiral through both ends",
          "[host][gcode]") {
    const Path p = gcode("G0 X10 Y0 Z-1\nG3 X0 Y10.005 I-10 J0\n");
    REQUIRE(p.subpaths.size() == 1);
    CHECK(near(p.subpaths[0].points.back(), 0, 10.005, 0));
    const std::size_t pieces = (p.subpaths[0].points.size() - 1) / 3;
    check_arc(p.subpaths[0], 0, pieces, {0, 0}, 10, 10.005, kPi / 2, 0.01);
}

/// A quarter arc about the origin from (r0, 0) to (0, r1): accepted or the error message.
std::string quarter(const std::string& units, const std::string& r0, const std::string& r1) {
    return error_of(units + " G0 X" + r0 + " Y0 Z-1\nG3 X0 Y" + r1 + " I-" + r0);
}

TEST_CASE("G-code: end radius small bound and 0.1 %", "[host][gcode]") {
    // Both the small absolute bound (0.028284 mm) and 0.1 % must be exceeded.
    CHECK(quarter("G21", "10", "10.0282") == "no error");  // 0.28 % but under 0.028284 mm
    CHECK(quarter("G21", "10", "10.0284") ==
          "t.ngc:2:1: radius to end of arc differs from radius to start: 10.000000 mm vs "
          "10.028400 mm, difference 0.028400 mm is more than 0.028284 mm and more than 0.1% "
          "(0.2832%)");
    CHECK(quarter("G21", "50", "50.0499") == "no error");  // over 0.028 mm, 0.0997 %
    CHECK(quarter("G21", "50", "50.0502").find("more than 0.1% (0.1003%)") != std::string::npos);
    CHECK(quarter("G20", "1", "1.0028") == "no error");  // 0.0028 in < 0.0028284 in
    CHECK(quarter("G20", "1", "1.0029") ==
          "t.ngc:2:1: radius to end of arc differs from radius to start: 1.000000 in vs "
          "1.002900 in, difference 0.002900 in is more than 0.002828 in and more than 0.1% "
          "(0.2892%)");
    CHECK(quarter("G20", "10", "10.0099") == "no error");  // 0.0099 in, 0.099 %
    CHECK(quarter("G20", "10", "10.0102").find("0.1% (0.1019%)") != std::string::npos);
}

TEST_CASE("G-code: end radius large bound", "[host][gcode]") {
    // Above 100 times the small bound an arc fails however large its radius.
    CHECK(quarter("G21", "3000", "3002.8") == "no error");  // 0.093 %
    CHECK(quarter("G21", "3000", "3002.83") ==
          "t.ngc:2:1: radius to end of arc differs from radius to start: 3000.000000 mm vs "
          "3002.830000 mm, difference 2.830000 mm is more than 2.828427 mm");
    CHECK(quarter("G20", "300", "300.28") == "no error");
    CHECK(quarter("G20", "300", "300.29") ==
          "t.ngc:2:1: radius to end of arc differs from radius to start: 300.000000 in vs "
          "300.290000 in, difference 0.290000 in is more than 0.282843 in");
}

TEST_CASE("G-code: tiny arcs rounded to 4 decimals", "[host][gcode]") {
    // A 0.01 mm arc whose end was rounded: 0.4 % off, far under 0.028 mm (the rule before
    // LinuxCNC 2.8, either bound alone, refused it).
    const Path p = gcode(
        "G0 X0.01 Y0 Z-1\nG3 X0.0071 Y0.0071 I-0.01 J0\nG3 X-0.0071 Y0.0071 "
        "I-0.0071 J-0.0071\nG2 X-0.0213 Y0.0071 I-0.0071 J0\n");
    REQUIRE(p.subpaths.size() == 1);
    CHECK(near(p.subpaths[0].points.back(), -0.0213, 0.0071));
}

// ---- splines ------------------------------------------------------------------------------

TEST_CASE("G-code: G5 cubics, I J omitted after a G5 reflect the previous control point",
          "[host][gcode]") {
    const Path p =
        gcode("G0 X0 Y0 Z-1\nG5 X10 Y0 I2 J3 P-2 Q3\nG5 X20 Y0 P-2 Q-3\nF60\nX30 Y5 P0 Q1\n");
    REQUIRE(p.subpaths.size() == 2);
    check_points(p.subpaths[0], {{0, 0}, {2, 3}, {8, 3}, {10, 0}, {12, -3}, {18, -3}, {20, 0}});
    check_points(p.subpaths[1], {{20, 0}, {22, 3}, {30, 6}, {30, 5}});
    // Incremental end points; I J P Q are offsets either way.
    const Path q = gcode("G91 G0 X1 Y1 Z-1\nG5 X10 Y0 I2 J3 P-2 Q3\n");
    check_points(q.subpaths[0], {{1, 1}, {3, 4}, {9, 4}, {11, 1}});
}

TEST_CASE("G-code: G5.1 quadratics become their exact cubics", "[host][gcode]") {
    const Path p = gcode("G0 Z-1\nG5.1 X10 Y0 I5 J5\nG5.1 X20 J-3\n");
    check_points(p.subpaths[0], {{0, 0},
                                 {10.0 / 3, 10.0 / 3},
                                 {20.0 / 3, 10.0 / 3},
                                 {10, 0},
                                 {10, -2},
                                 {40.0 / 3, -2},
                                 {20, 0}});
}

TEST_CASE("G-code: the example drawing uses G1, G2, G3 and G5", "[host][gcode]") {
    const Path p = load_gcode_path(source_dir() + "/examples/leaf.ngc");
    REQUIRE(p.axes == 2);
    REQUIRE(p.subpaths.size() == 5);
    for (const Subpath& sp : p.subpaths) {
        CHECK(sp.basis == PathBasis::kBezier);
        CHECK(sp.points.size() % 3 == 1);
    }
    // The frame: a full circle, 40 mm/s.
    const Subpath& frame = p.subpaths[0];
    CHECK(frame.feed == 40.0);
    CHECK(frame.location.line == 9);
    check_arc(frame, 0, (frame.points.size() - 1) / 3, {50, 50}, 45, 45, -2 * kPi, 0.01);
    // The outline: two G5 pieces, 20 mm/s.
    CHECK(p.subpaths[1].feed == 20.0);
    check_points(p.subpaths[1],
                 {{50, 85}, {15, 70}, {25, 50}, {50, 25}, {75, 50}, {85, 70}, {50, 85}});
    // Midrib and stem: a line, then a quarter circle about (50, 8).
    const Subpath& rib = p.subpaths[2];
    REQUIRE(rib.points.size() == 7);
    check_arc(rib, 1, 1, {50, 8}, 6, 6, kPi / 2, 0.01);
    // The veins continue smoothly through the midrib.
    check_points(p.subpaths[3],
                 {{32, 55}, {40, 49}, {42, 45}, {50, 45}, {58, 45}, {60, 49}, {68, 55}});
    check_points(p.subpaths[4],
                 {{36, 70}, {42, 65}, {44, 62}, {50, 62}, {56, 62}, {58, 65}, {64, 70}});
}

// ---- errors -------------------------------------------------------------------------------

TEST_CASE("G-code: syntax errors name line, column and the problem", "[host][gcode]") {
    CHECK(error_of("G0 Z-1\nG1 A10") == "t.ngc:2:4: axis A is not one of this machine's axes (XY)");
    CHECK(error_of("G1 x1 k2") == "t.ngc:1:7: word K is not used by any command in this block");
    CHECK(error_of("G1 X10 @") == "t.ngc:1:8: missing number after @");
    CHECK(error_of("G1 X10 !") ==
          "t.ngc:1:8: unexpected character '!' (expected a word: letter and number)");
    CHECK(error_of("G1 X10 15") ==
          "t.ngc:1:8: unexpected character '1' (expected a word: letter and number)");
    CHECK(error_of("G1 X1.2.3") == "t.ngc:1:4: malformed number \"1.2.3\" after X");
    CHECK(error_of("G1 X-") == "t.ngc:1:4: malformed number \"-\" after X");
    CHECK(error_of("G1 X1-2") == "t.ngc:1:4: malformed number \"1-2\" after X");
    CHECK(error_of("G1 X1e3") ==
          "t.ngc:1:6: unsupported word letter 'E' (supported: G M N O A B C D F H I J K L P Q "
          "R S T U V W X Y Z)");
    CHECK(error_of("G1 X Y2") == "t.ngc:1:4: missing number after X");
    CHECK(error_of("G1 X" + std::string(400, '9')) ==
          "t.ngc:1:4: number after X is out of range (not finite as a double)");
    CHECK(error_of("/G1 X1") == "t.ngc:1:1: block delete '/' is not supported");
    CHECK(error_of("G1 (oops X1") == "t.ngc:1:4: unclosed comment '('");
    CHECK(error_of("G1 [1]") ==
          "t.ngc:1:4: unexpected character '[' (expected a word: letter and number)");
    CHECK(error_of("G1 X1 o100 sub") == "t.ngc:1:7: an O-word must be the first word of its line");
    CHECK(error_of("o100") ==
          "t.ngc:1:1: O-word without a keyword (sub, endsub, call, return, if, elseif, else, "
          "endif, while, endwhile, do, repeat, endrepeat, break, continue)");
    CHECK(error_of("o100 loop") == "t.ngc:1:6: unknown O-word keyword \"loop\"");
    CHECK(error_of("G1 N10 X1") == "t.ngc:1:4: line number N must start the block");
    CHECK(error_of("G1 X1\xC3\xA9") ==
          "t.ngc:1:6: unexpected character byte \\xC3 (expected a word: letter and number)");
}

TEST_CASE("G-code: code and word errors", "[host][gcode]") {
    CHECK(error_of("G1 X1 X2") == "t.ngc:1:7: repeated word X in one block");
    CHECK(error_of("G0 G1 X1") ==
          "t.ngc:1:4: G0 and G1 are in the same modal group (one per block)");
    CHECK(error_of("G20 G21") ==
          "t.ngc:1:5: G20 and G21 are in the same modal group (one per block)");
    CHECK(error_of("M3 M5") == "t.ngc:1:4: M3 and M5 are in the same modal group (one per block)");
    CHECK(error_of("G41 D2") == "t.ngc:1:1: G41/G42: no tool table (give one with --tool-table)");
    CHECK(error_of("G0 Z0\nG52 X0") == "t.ngc:2:1: unsupported G code G52");
    CHECK(error_of("G1.5") == "t.ngc:1:1: unsupported G code G1.5");
    CHECK(error_of("G1.25") == "t.ngc:1:1: unsupported G code G1.25");
    CHECK(error_of("G0 X0\nG19 G2 X1 I1") ==
          "t.ngc:2:11: I is no center offset of a G19 arc (it "
          "takes J and K)");
    CHECK(error_of("M62 P1") ==
          "t.ngc:1:1: unsupported M code M62 (skip it with --ignore-code M62 if it means nothing "
          "here)");
    CHECK(error_of("M3.5") == "t.ngc:1:1: unsupported M code M3.5");
    CHECK(error_of("X10") ==
          "t.ngc:1:1: axis word X with no motion mode (give G0, G1, G2, G3, G5, G5.1, G5.2 or a "
          "canned "
          "cycle first)");
    CHECK(error_of("G1 X1\nG80 Y1") == "t.ngc:2:5: axis words cannot be used with G80");
    CHECK(error_of("G1 X1 I2") == "t.ngc:1:7: word I is not used by any command in this block");
    CHECK(error_of("G0 X1 R2") == "t.ngc:1:7: word R is not used by any command in this block");
    CHECK(error_of("G1 X1 Q2") == "t.ngc:1:7: word Q is not used by any command in this block");
    CHECK(error_of("G2 X1 I1 Q2") == "t.ngc:1:10: word Q is not used by any command in this block");
    CHECK(error_of("G1 X1\nI2") == "t.ngc:2:1: word I is not used by any command in this block");
    CHECK(error_of("G4") == "t.ngc:1:1: G4 needs P (the dwell time in seconds)");
    CHECK(error_of("G4 P-1") == "t.ngc:1:4: G4 dwell time P must not be negative");
    CHECK(error_of("G1 X1 F0") == "t.ngc:1:7: feed F0 is out of range (0 < F <= 1e+09 mm/min)");
    CHECK(error_of("G1 X1 F-5") == "t.ngc:1:7: feed F-5 is out of range (0 < F <= 1e+09 mm/min)");
    CHECK(error_of("G20 G1 X1 F40000000") ==
          "t.ngc:1:11: feed F40000000 is out of range (0 < F <= 1e+09 mm/min)");
}

TEST_CASE("G-code: out-of-range coordinates", "[host][gcode]") {
    CHECK(error_of("G1 X2000000") == "t.ngc:1:4: X 2e+06 mm is out of range (|value| <= 1e+06 mm)");
    CHECK(error_of("G20 G1 Y40000") ==
          "t.ngc:1:8: Y 1.016e+06 mm is out of range (|value| <= 1e+06 mm)");
    CHECK(error_of("G91 G0 X900000\nX900000") ==
          "t.ngc:2:1: X 1.8e+06 mm is out of range (|value| <= 1e+06 mm)");
    CHECK(error_of("G0 X900000 Z-1\nG5 X0 I2000000 J0 P0 Q0") ==
          "t.ngc:2:7: I 2e+06 mm is out of range (|value| <= 1e+06 mm)");
    CHECK(error_of("G0 X900000 Z-1\nG5 X900000 Y10 I200000 J0 P0 Q0") ==
          "t.ngc:2:1: curve point X 1.1e+06 mm is out of range (|value| <= 1e+06 mm)");
}

TEST_CASE("G-code: arc errors", "[host][gcode]") {
    CHECK(error_of("G0 Z-1\nG2 X10") ==
          "t.ngc:2:1: G2 needs I and J (the center) or R (the radius)");
    CHECK(error_of("G0 Z-1\nG3 X10\n") ==
          "t.ngc:2:1: G3 needs I and J (the center) or R (the radius)");
    CHECK(error_of("G2 X10 I5 R5") ==
          "t.ngc:1:11: give either I and J (the center) or R (the radius), not both");
    CHECK(error_of("G0 X10 Y0\nG3 X0 Y11 I-10") ==
          "t.ngc:2:1: radius to end of arc differs from radius to start: 10.000000 mm vs "
          "11.000000 mm, difference 1.000000 mm is more than 0.028284 mm and more than 0.1% "
          "(9.0909%)");
    CHECK(error_of("G0 X5 Y5\nG2 X5 Y5 R3") ==
          "t.ngc:2:10: R arc with the end point equal to the start point (use I and J for a full "
          "circle)");
    CHECK(error_of("G2 X10 R4") ==
          "t.ngc:1:8: arc radius R4 is too small to reach the end point (half the chord is 5.0000 "
          "mm)");
    CHECK(error_of("G2 X0.001 R0") == "t.ngc:1:11: zero-radius arc (R0)");
    CHECK(error_of("G2 X10 I0 J0") ==
          "t.ngc:1:1: zero-radius arc (the center is at the start or end point)");
    CHECK(error_of("G2 X10 I10") ==
          "t.ngc:1:1: zero-radius arc (the center is at the start or end point)");
    CHECK(error_of("G0 Z-1\nG2 X10 I5 Z-2") ==
          "t.ngc:2:11: Z changes during G2 but is not a motion axis here (a helix needs a Z axis)");
    CHECK(error_of("G90.1 G2 X10 I5") ==
          "t.ngc:1:14: G2 with absolute centers (G90.1) needs both I and J");
    CHECK(error_of("G2 I5 P0") ==
          "t.ngc:1:7: P (number of turns) must be a whole number from 1 to 100");
    CHECK(error_of("G2 I5 P1.5") ==
          "t.ngc:1:7: P (number of turns) must be a whole number from 1 to 100");
    // A Z word that does not change Z is fine.
    CHECK(gcode("G0 Z-1\nG2 X10 I5 Z-1\n").subpaths.size() == 1);
}

TEST_CASE("G-code: spline errors", "[host][gcode]") {
    CHECK(error_of("G0 X0\nG5 X10 P1 Q1") ==
          "t.ngc:2:1: G5 without I and J must follow another G5 (I and J give the first control "
          "point)");
    CHECK(error_of("G5 X1 I1 J1 P1 Q1\nG1 X2\nG5 X3 P1 Q1") ==
          "t.ngc:3:1: G5 without I and J must follow another G5 (I and J give the first control "
          "point)");
    CHECK(error_of("G5 X1 I1 J1 P1 Q1\nX3 P1 Q1\nY3 P1 Q1\nG5.1 X5 I1\nG5 X3 P1 Q1") ==
          "t.ngc:5:1: G5 without I and J must follow another G5 (I and J give the first control "
          "point)");
    CHECK(error_of("G5 X10 I1 P1 Q1") ==
          "t.ngc:1:8: G5 needs both I and J, or neither right after another G5");
    CHECK(error_of("G5 X1 I1 J1 P1") ==
          "t.ngc:1:13: G5 needs both P and Q (the second control point)");
    CHECK(error_of("G5 X1 I1 J1") == "t.ngc:1:1: G5 needs both P and Q (the second control point)");
    CHECK(error_of("G5 X1 Z1 I1 J1 P1 Q1") ==
          "t.ngc:1:7: Z is not allowed with G5 (XY plane only)");
    CHECK(error_of("G5 I1 J1 P1 Q1") == "t.ngc:1:1: G5 needs X or Y (the end point)");
    CHECK(error_of("G5.1 X1 I0 J0") ==
          "t.ngc:1:1: G5.1 needs a nonzero I or J (the control point)");
    CHECK(error_of("G5.1 X1 I1 P1") ==
          "t.ngc:1:12: word P is not used by any command in this block");
    CHECK(error_of("G5.1 X1 Z0 I1") == "t.ngc:1:9: Z is not allowed with G5.1 (XY plane only)");
}

TEST_CASE("G-code: a program that draws nothing is an error", "[host][gcode]") {
    CHECK(error_of("G0 X10\nG1 X20\nM2\n") ==
          "t.ngc: no pen-down moves (the pen is down during G1, G2, G3, G5, G5.1 and G5.2 moves at "
          "Z <= "
          "0 mm)");
    CHECK(error_of("") ==
          "t.ngc: no pen-down moves (the pen is down during G1, G2, G3, G5, G5.1 and G5.2 moves at "
          "Z <= "
          "0 mm)");
    CHECK(error_of("G0 Z-1\nG1 X10\n", spindle()) ==
          "t.ngc: no pen-down moves (the pen is down during G1, G2, G3, G5, G5.1 and G5.2 moves "
          "between M3 "
          "or M4 and M5)");
    CHECK(error_of("M3\nG0 X10\nM2\nG1 X20\n", spindle()).rfind("t.ngc: no pen-down moves", 0) ==
          0);
}

TEST_CASE("G-code: bad options and missing files", "[host][gcode]") {
    GcodeOptions o;
    o.arc_tolerance_mm = 0;
    CHECK_THROWS_AS(gcode("G0 Z-1\nG1 X1", o), std::invalid_argument);
    o.arc_tolerance_mm = NAN;
    CHECK_THROWS_AS(gcode("G0 Z-1\nG1 X1", o), std::invalid_argument);
    GcodeOptions z;
    z.z_down_max = INFINITY;
    CHECK_THROWS_AS(gcode("G0 Z-1\nG1 X1", z), std::invalid_argument);
    CHECK_THROWS_WITH(load_gcode_path("/nonexistent/p.ngc"),
                      "/nonexistent/p.ngc: cannot open file");
}

TEST_CASE("G-code keeps each move's line: a travel error names the move that crosses",
          "[gcode][workarea]") {
    MachineProfile m;
    m.tick_hz = 1000;
    m.mm_per_lsb = 0.001;
    m.axes = {{"x", 200, 2000, true, 0, 430}, {"y", 200, 2000, true, 0, 297}};
    m.source = "m.json";
    const Path path = parse_gcode_path(
        "G21 G90\nG0 X10 Y10\nG1 Z-1 F1000\nG1 X50 Y10\nG2 X90 Y10 I20 J0\n"
        "G1 X500 Y10\nG1 X10 Y20\n",
        "t.ngc");
    REQUIRE(path.subpaths.size() == 1);
    const Subpath& run = path.subpaths[0];
    REQUIRE(run.segment_lines.size() == chain_segments(run));
    CHECK(run.segment_lines.front() == 4);
    CHECK(run.segment_lines.back() == 7);
    try {
        check_work_area(to_bezier_segments(path), path, m, "t.ngc");
        FAIL("x 500 mm passed a 430 mm travel");
    } catch (const InputError& e) {
        CHECK_THAT(e.what(), Catch::StartsWith("t.ngc:6:1: subpath 1 leaves the work area"));
    }
    // Reversed, each segment keeps its line: the first crossing met is now line 7's move, which
    // leaves x 500 mm (line 6's comes after it).
    Path reversed = path;
    reversed.subpaths[0] = reversed_subpath(run);
    CHECK(reversed.subpaths[0].segment_lines.front() == 7);
    try {
        check_work_area(to_bezier_segments(reversed), reversed, m, "t.ngc");
        FAIL("x 500 mm passed a 430 mm travel");
    } catch (const InputError& e) {
        CHECK_THAT(e.what(), Catch::StartsWith("t.ngc:7:1:"));
    }
}
