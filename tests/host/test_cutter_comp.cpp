// Cutter radius compensation geometry (host/src/gcode/cutter_comp.hpp): hand-computed tool
// paths for squares outside and inside, tangent and inside line/arc corners, full circles and
// the entry arc; LinuxCNC's errors; and a property check on random convex polygons: the tool
// center stays at least the radius from every side and exactly the radius from the nearest.
// Random cases: PATHSTREAM_CUTTER_CASES (default 50), seed PATHSTREAM_CUTTER_SEED (default 1).
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "../../host/src/gcode/cutter_comp.hpp"

using namespace pathstream::host::gcode;

namespace {

constexpr double kPi = std::numbers::pi;

PlaneMove line(Vec2 a, Vec2 b, std::size_t source) {
    return PlaneMove{PlaneMove::kLine, a, b, {}, true, source};
}

PlaneMove arc(Vec2 a, Vec2 b, Vec2 center, bool ccw, std::size_t source) {
    return PlaneMove{PlaneMove::kArc, a, b, center, ccw, source};
}

bool near(Vec2 a, Vec2 b, double eps = 1e-9) {
    return std::hypot(a.x - b.x, a.y - b.y) <= eps;
}

std::string show(Vec2 a) {
    return "(" + std::to_string(a.x) + ", " + std::to_string(a.y) + ")";
}

// Checks one move of the tool path against the expected one.
void check_move(const PlaneMove& got, const PlaneMove& want) {
    INFO("want " << (want.kind == PlaneMove::kLine ? "line " : "arc ") << show(want.start) << " -> "
                 << show(want.end) << " source " << want.source);
    INFO("got " << (got.kind == PlaneMove::kLine ? "line " : "arc ") << show(got.start) << " -> "
                << show(got.end) << " center " << show(got.center) << " source " << got.source);
    CHECK(got.kind == want.kind);
    CHECK(near(got.start, want.start));
    CHECK(near(got.end, want.end));
    CHECK(got.source == want.source);
    if (want.kind == PlaneMove::kArc) {
        CHECK(near(got.center, want.center));
        CHECK(got.ccw == want.ccw);
    }
}

void check_path(const CompResult& result, const std::vector<PlaneMove>& want) {
    REQUIRE(result.moves.size() == want.size());
    for (std::size_t i = 0; i < want.size(); ++i) {
        INFO("tool move " << i);
        check_move(result.moves[i], want[i]);
    }
}

// The moves around a polygon's corners, from `from` (the entry move's start) to corners[0]
// and then round to corners[0] again; sources count from 0.
std::vector<PlaneMove> profile(Vec2 from, const std::vector<Vec2>& corners) {
    std::vector<PlaneMove> moves{line(from, corners[0], 0)};
    for (std::size_t i = 0; i < corners.size(); ++i) {
        moves.push_back(line(corners[i], corners[(i + 1) % corners.size()], i + 1));
    }
    return moves;
}

// Whether compensate throws CompError naming `source` with a message containing `words`.
void check_error(const std::vector<PlaneMove>& moves, Vec2 tool, CompSide side, double radius,
                 std::size_t source, const std::string& words) {
    try {
        compensate(moves, tool, side, radius, 1e-6);
        FAIL("no CompError");
    } catch (const CompError& e) {
        INFO(e.what());
        CHECK(e.source == source);
        CHECK(std::string(e.what()).find(words) != std::string::npos);
    }
}

}  // namespace

TEST_CASE("a square outside with G42 counterclockwise: offset sides, quarter arcs at corners",
          "[gcode][cutter]") {
    const auto moves = profile({-10, 0}, {{0, 0}, {10, 0}, {10, 10}, {0, 10}});
    const CompResult r = compensate(moves, {-10, 0}, CompSide::kRight, 3, 1e-6);
    check_path(r, {line({-10, 0}, {0, -3}, 0), line({0, -3}, {10, -3}, 1),
                   arc({10, -3}, {13, 0}, {10, 0}, true, 2), line({13, 0}, {13, 10}, 2),
                   arc({13, 10}, {10, 13}, {10, 10}, true, 3), line({10, 13}, {0, 13}, 3),
                   arc({0, 13}, {-3, 10}, {0, 10}, true, 4), line({-3, 10}, {-3, 0}, 4)});
}

TEST_CASE("a square outside with G41 clockwise (climb): clockwise quarter arcs",
          "[gcode][cutter]") {
    const auto moves = profile({0, -10}, {{0, 0}, {0, 10}, {10, 10}, {10, 0}});
    const CompResult r = compensate(moves, {0, -10}, CompSide::kLeft, 3, 1e-6);
    check_path(r, {line({0, -10}, {-3, 0}, 0), line({-3, 0}, {-3, 10}, 1),
                   arc({-3, 10}, {0, 13}, {0, 10}, false, 2), line({0, 13}, {10, 13}, 2),
                   arc({10, 13}, {13, 10}, {10, 10}, false, 3), line({13, 10}, {13, 0}, 3),
                   arc({13, 0}, {10, -3}, {10, 0}, false, 4), line({10, -3}, {0, -3}, 4)});
}

TEST_CASE("a square pocket with G41: inside corners cut back, no arcs", "[gcode][cutter]") {
    // Entry from the middle to the middle of the bottom side: LinuxCNC's comp1 puts the tool
    // at (13, 0), then the inside corner with the bottom side backs it off to (13, 3).
    std::vector<PlaneMove> moves{line({10, 10}, {10, 0}, 0), line({10, 0}, {20, 0}, 1),
                                 line({20, 0}, {20, 20}, 2), line({20, 20}, {0, 20}, 3),
                                 line({0, 20}, {0, 0}, 4),   line({0, 0}, {10, 0}, 5)};
    const CompResult r = compensate(moves, {10, 10}, CompSide::kLeft, 3, 1e-6);
    check_path(r,
               {line({10, 10}, {13, 3}, 0), line({13, 3}, {17, 3}, 1), line({17, 3}, {17, 17}, 2),
                line({17, 17}, {3, 17}, 3), line({3, 17}, {3, 3}, 4), line({3, 3}, {10, 3}, 5)});
}

TEST_CASE("a line meeting an arc tangentially joins without an arc", "[gcode][cutter]") {
    // Along +X, a quarter turn left about (10, 10), then up +Y: every corner tangent.
    const std::vector<PlaneMove> moves{line({-10, 0}, {0, 0}, 0), line({0, 0}, {10, 0}, 1),
                                       arc({10, 0}, {20, 10}, {10, 10}, true, 2),
                                       line({20, 10}, {20, 20}, 3)};
    SECTION("G41: inside the arc, radius 7") {
        check_path(compensate(moves, {-10, 0}, CompSide::kLeft, 3, 1e-6),
                   {line({-10, 0}, {0, 3}, 0), line({0, 3}, {10, 3}, 1),
                    arc({10, 3}, {17, 10}, {10, 10}, true, 2), line({17, 10}, {17, 20}, 3)});
    }
    SECTION("G42: outside the arc, radius 13") {
        check_path(compensate(moves, {-10, 0}, CompSide::kRight, 3, 1e-6),
                   {line({-10, 0}, {0, -3}, 0), line({0, -3}, {10, -3}, 1),
                    arc({10, -3}, {23, 10}, {10, 10}, true, 2), line({23, 10}, {23, 20}, 3)});
    }
}

TEST_CASE("a full circle is offset outward and inward and stays a full circle", "[gcode][cutter]") {
    const std::vector<PlaneMove> moves{line({10, -10}, {10, 0}, 0),
                                       arc({10, 0}, {10, 0}, {0, 0}, true, 1)};
    SECTION("G41 inside") {
        const CompResult r = compensate(moves, {10, -10}, CompSide::kLeft, 3, 1e-6);
        check_path(r, {line({10, -10}, {7, 0}, 0), arc({7, 0}, {7, 0}, {0, 0}, true, 1)});
        CHECK(r.moves[1].start == r.moves[1].end);  // exactly: a full turn, not none
    }
    SECTION("G42 outside") {
        const CompResult r = compensate(moves, {10, -10}, CompSide::kRight, 3, 1e-6);
        check_path(r, {line({10, -10}, {13, 0}, 0), arc({13, 0}, {13, 0}, {0, 0}, true, 1)});
        CHECK(r.moves[1].start == r.moves[1].end);
    }
}

TEST_CASE("inside corners between lines and arcs end where the offsets meet", "[gcode][cutter]") {
    const double x = std::sqrt(40.0);  // y = 3 meets the circle of radius 7 about the origin
    SECTION("line then arc, G41") {
        const std::vector<PlaneMove> moves{line({-10, 0}, {0, 0}, 0), line({0, 0}, {10, 0}, 1),
                                           arc({10, 0}, {0, 10}, {0, 0}, true, 2)};
        check_path(compensate(moves, {-10, 0}, CompSide::kLeft, 3, 1e-6),
                   {line({-10, 0}, {0, 3}, 0), line({0, 3}, {x, 3}, 1),
                    arc({x, 3}, {0, 7}, {0, 0}, true, 2)});
    }
    SECTION("arc then line, G42") {
        const std::vector<PlaneMove> moves{line({-10, 10}, {0, 10}, 0),
                                           arc({0, 10}, {10, 0}, {0, 0}, false, 1),
                                           line({10, 0}, {0, 0}, 2)};
        check_path(compensate(moves, {-10, 10}, CompSide::kRight, 3, 1e-6),
                   {line({-10, 10}, {0, 7}, 0), arc({0, 7}, {x, 3}, {0, 0}, false, 1),
                    line({x, 3}, {0, 3}, 2)});
    }
    SECTION("arc then arc, G42: both offsets outward (radius 13) cross") {
        const std::vector<PlaneMove> moves{line({10, -10}, {10, 0}, 0),
                                           arc({10, 0}, {0, 10}, {0, 0}, true, 1),
                                           arc({0, 10}, {-10, 20}, {-10, 10}, true, 2)};
        const double h = std::sqrt(59.5);
        check_path(compensate(moves, {10, -10}, CompSide::kRight, 3, 1e-6),
                   {line({10, -10}, {13, 0}, 0), arc({13, 0}, {-5 + h, 5 + h}, {0, 0}, true, 1),
                    arc({-5 + h, 5 + h}, {-10, 23}, {-10, 10}, true, 2)});
    }
}

TEST_CASE("an entry arc runs from the tool to the offset end about a new center",
          "[gcode][cutter]") {
    // Half a turn about (10, 0) from (0, 0) to (20, 0) under it, G42 (outside): the tool ends
    // at (23, 0); the center on the X axis as far from (0, 0) as from (23, 0).
    const std::vector<PlaneMove> moves{arc({0, 0}, {20, 0}, {10, 0}, true, 0)};
    check_path(compensate(moves, {0, 0}, CompSide::kRight, 3, 1e-6),
               {arc({0, 0}, {23, 0}, {11.5, 0}, true, 0)});
}

TEST_CASE("a move without XY motion keeps the tool at the corner", "[gcode][cutter]") {
    std::vector<PlaneMove> moves{line({10, 10}, {10, 0}, 0), line({10, 0}, {20, 0}, 1),
                                 line({20, 0}, {20, 0}, 2), line({20, 0}, {20, 20}, 3)};
    check_path(compensate(moves, {10, 10}, CompSide::kLeft, 3, 1e-6),
               {line({10, 10}, {13, 3}, 0), line({13, 3}, {17, 3}, 1), line({17, 3}, {17, 3}, 2),
                line({17, 3}, {17, 20}, 3)});
}

TEST_CASE("a corner within the tolerance of tangent is bridged by a line, not an arc",
          "[gcode][cutter]") {
    // A 0.0001 rad turn right with G41 (outside): the offset points are 0.0003 mm apart.
    const Vec2 bend{10 + 10 * std::cos(1e-4), -10 * std::sin(1e-4)};
    const std::vector<PlaneMove> moves{line({-10, 0}, {0, 0}, 0), line({0, 0}, {10, 0}, 1),
                                       line({10, 0}, bend, 2)};
    const CompResult loose = compensate(moves, {-10, 0}, CompSide::kLeft, 3, 1e-3);
    REQUIRE(loose.moves.size() == 4);
    CHECK(loose.moves[2].kind == PlaneMove::kLine);
    CHECK(near(loose.moves[2].start, {10, 3}));
    const CompResult tight = compensate(moves, {-10, 0}, CompSide::kLeft, 3, 1e-5);
    REQUIRE(tight.moves.size() == 4);
    CHECK(tight.moves[2].kind == PlaneMove::kArc);
}

TEST_CASE("radius 0 leaves the path as programmed; broken input is refused", "[gcode][cutter]") {
    const std::vector<PlaneMove> moves{line({0, 0}, {1, 0}, 0),
                                       arc({1, 0}, {3, 0}, {2, 0}, true, 1)};
    check_path(compensate(moves, {0, 0.5}, CompSide::kLeft, 0, 1e-6),
               {line({0, 0.5}, {1, 0}, 0), arc({1, 0}, {3, 0}, {2, 0}, true, 1)});
    CHECK(compensate({}, {0, 0}, CompSide::kLeft, 3, 1e-6).moves.empty());
    CHECK_THROWS_AS(compensate(moves, {0, 0}, CompSide::kLeft, -1, 1e-6), std::invalid_argument);
    CHECK_THROWS_AS(compensate({line({0, 0}, {5, 0}, 0), line({5, 1}, {9, 0}, 1)}, {0, 0},
                               CompSide::kLeft, 1, 1e-6),
                    std::invalid_argument);
}

TEST_CASE("cutter compensation errors name the move at fault", "[gcode][cutter]") {
    SECTION("a concave arc smaller than the tool") {
        const std::vector<PlaneMove> moves{line({-10, 0}, {0, 0}, 7), line({0, 0}, {10, 0}, 8),
                                           arc({10, 0}, {12, 2}, {10, 2}, true, 9)};
        check_error(moves, {-10, 0}, CompSide::kLeft, 3, 9, "Tool radius not less than arc");
        // Outside the same arc the tool fits.
        CHECK_NOTHROW(compensate(moves, {-10, 0}, CompSide::kRight, 3, 1e-6));
    }
    SECTION("an inside step shorter than the tool radius") {
        const std::vector<PlaneMove> moves{line({-10, 0}, {0, 0}, 0), line({0, 0}, {20, 0}, 1),
                                           line({20, 0}, {20, 2}, 2), line({20, 2}, {40, 2}, 3)};
        check_error(moves, {-10, 0}, CompSide::kLeft, 3, 2, "without gouging");
        CHECK_NOTHROW(compensate(moves, {-10, 0}, CompSide::kLeft, 1.5, 1e-6));
    }
    SECTION("an entry move not longer than the radius") {
        const std::vector<PlaneMove> moves{line({0, 0}, {3, 0}, 4), line({3, 0}, {10, 0}, 5)};
        check_error(moves, {0, 0}, CompSide::kLeft, 3, 4,
                    "Length of cutter compensation entry move is not greater than the tool "
                    "radius");
    }
    SECTION("an entry arc ending within the radius of the tool") {
        const std::vector<PlaneMove> moves{arc({0, 0}, {2, 0}, {1, 0}, true, 0)};
        check_error(moves, {0, 0}, CompSide::kRight, 3, 0, "entry arc is not greater");
    }
    SECTION("an inside corner with an arc the tool cannot reach") {
        // A quarter turn left of radius 3.5 right after a side, G41: the offset circle
        // (radius 0.5 about (6.5, 0)) never comes within reach of the offset side (y = 3).
        const std::vector<PlaneMove> moves{line({-10, 0}, {0, 0}, 0), line({0, 0}, {10, 0}, 1),
                                           arc({10, 0}, {6.5, 3.5}, {6.5, 0}, true, 2)};
        check_error(moves, {-10, 0}, CompSide::kLeft, 3, 2, "without gouging");
    }
}

namespace {

double segment_distance(Vec2 p, Vec2 a, Vec2 b) {
    const Vec2 d = b - a;
    const double len2 = d.x * d.x + d.y * d.y;
    const double t = std::clamp(((p.x - a.x) * d.x + (p.y - a.y) * d.y) / len2, 0.0, 1.0);
    const Vec2 q = a + t * d;
    return std::hypot(p.x - q.x, p.y - q.y);
}

// Points along a tool move, its ends included; an arc's turn from the documented rule.
std::vector<Vec2> samples(const PlaneMove& m, int count) {
    std::vector<Vec2> points;
    for (int k = 0; k <= count; ++k) {
        const double f = static_cast<double>(k) / count;
        if (m.kind == PlaneMove::kLine) {
            points.push_back(m.start + f * (m.end - m.start));
            continue;
        }
        const double a0 = std::atan2(m.start.y - m.center.y, m.start.x - m.center.x);
        const double a1 = std::atan2(m.end.y - m.center.y, m.end.x - m.center.x);
        double turn = std::fmod((m.ccw ? a1 - a0 : a0 - a1) + 4 * kPi, 2 * kPi);
        if (turn == 0 || m.start == m.end) turn = 2 * kPi;
        const double a = a0 + (m.ccw ? turn : -turn) * f;
        const double r = std::hypot(m.start.x - m.center.x, m.start.y - m.center.y);
        points.push_back(m.center + r * Vec2{std::cos(a), std::sin(a)});
    }
    return points;
}

double cot_half(Vec2 in, Vec2 out) {
    // The interior angle of a convex polygon's corner is π minus the turn there.
    const double turn =
        std::fabs(std::atan2(in.x * out.y - in.y * out.x, in.x * out.x + in.y * out.y));
    return std::tan(turn / 2);  // cot((π - turn) / 2)
}

}  // namespace

TEST_CASE("random convex polygons: the tool keeps exactly its radius from the sides",
          "[gcode][cutter]") {
    const char* env_cases = std::getenv("PATHSTREAM_CUTTER_CASES");
    const char* env_seed = std::getenv("PATHSTREAM_CUTTER_SEED");
    const int cases = env_cases != nullptr ? std::atoi(env_cases) : 50;
    const unsigned long seed = env_seed != nullptr ? std::strtoul(env_seed, nullptr, 10) : 1;
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> unit(0, 1);
    const auto pick = [&](double lo, double hi) { return lo + (hi - lo) * unit(rng); };
    int checked = 0, refused = 0;
    for (int c = 0; c < cases; ++c) {
        // Corners on an ellipse (convex), in either direction.
        const auto n = static_cast<std::size_t>(pick(3, 11));
        std::vector<double> angles(n);
        for (double& a : angles) a = pick(0, 2 * kPi);
        std::sort(angles.begin(), angles.end());
        const double ax = pick(5, 40), ay = pick(5, 40), cx = pick(-50, 50), cy = pick(-50, 50);
        std::vector<Vec2> corners;
        for (double a : angles) corners.push_back({cx + ax * std::cos(a), cy + ay * std::sin(a)});
        const bool ccw = unit(rng) < 0.5;
        if (!ccw) std::reverse(corners.begin(), corners.end());
        const double radius = pick(0.2, 5);
        const CompSide side = unit(rng) < 0.5 ? CompSide::kLeft : CompSide::kRight;
        const bool inside = ccw == (side == CompSide::kLeft);

        // Entry along the first side's line, the sides, the first side again (so that the
        // corner at corners[0] is made); sides 1 .. n-1 and their corners are checked.
        const Vec2 t0 = (1 / std::hypot(corners[1].x - corners[0].x, corners[1].y - corners[0].y)) *
                        (corners[1] - corners[0]);
        const Vec2 tool = corners[0] - (radius + pick(1, 5)) * t0;
        std::vector<PlaneMove> moves = profile(tool, corners);
        moves.push_back(line(corners[0], corners[1], n + 1));

        // Inside, a side survives when it is longer than the two corners eat from it.
        bool all_fit = true, checked_side_short = false;
        for (std::size_t i = 0; i < n && inside; ++i) {
            const Vec2 a = corners[(i + n - 1) % n], b = corners[i], d = corners[(i + 1) % n],
                       e = corners[(i + 2) % n];
            const double eaten = radius * (cot_half(b - a, d - b) + cot_half(d - b, e - d));
            const double length = std::hypot(d.x - b.x, d.y - b.y);
            if (length <= eaten + 1e-6) all_fit = false;
            if (i > 0 && length < eaten - 1e-6) checked_side_short = true;
        }
        INFO("case " << c << " n " << n << " radius " << radius << (inside ? " inside" : ""));
        if (checked_side_short) {
            CHECK_THROWS_AS(compensate(moves, tool, side, radius, 1e-6), CompError);
            ++refused;
            continue;
        }
        if (!all_fit) continue;
        const CompResult r = compensate(moves, tool, side, radius, 1e-6);
        REQUIRE(!r.moves.empty());
        CHECK(near(r.moves.front().start, tool));
        for (std::size_t i = 1; i < r.moves.size(); ++i) {
            CHECK(near(r.moves[i].start, r.moves[i - 1].end));
        }
        for (const PlaneMove& m : r.moves) {
            if (m.source < 2 || m.source > n) continue;
            for (const Vec2& p : samples(m, 16)) {
                double nearest = 1e300;
                for (std::size_t i = 0; i < n; ++i) {
                    const double d = segment_distance(p, corners[i], corners[(i + 1) % n]);
                    CHECK(d >= radius - 1e-9);
                    nearest = std::min(nearest, d);
                }
                CHECK(nearest == Approx(radius).margin(1e-6));
            }
        }
        ++checked;
    }
    INFO(checked << " checked, " << refused << " refused");
    CHECK(checked + refused > 0);
}
