// NURBS input (JSON "basis": "nurbs" and G-code G5.2/G5.3) against an independent de Boor
// evaluation: exact where the reader claims exactness, within the tolerance elsewhere.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "pathstream/host/gcode_path.hpp"
#include "pathstream/host/json_path.hpp"
#include "pathstream/machine/input_error.hpp"

using namespace pathstream::host;

namespace {

struct Curve {
    int degree;
    std::vector<std::vector<double>> points;  // 2-D
    std::vector<double> weights;              // empty: all 1
    std::vector<double> knots;
};

/// de Boor's algorithm on homogeneous points: the curve at u (knots[degree] <= u <= knots[n]).
std::vector<double> de_boor(const Curve& c, double u) {
    const std::size_t p = static_cast<std::size_t>(c.degree), n = c.points.size();
    std::size_t k = p;
    while (k + 1 < n && c.knots[k + 1] <= u) ++k;  // knots[k] <= u < knots[k + 1]
    std::vector<std::vector<double>> d(p + 1);
    for (std::size_t j = 0; j <= p; ++j) {
        const std::size_t i = j + k - p;
        const double w = c.weights.empty() ? 1.0 : c.weights[i];
        d[j] = {w * c.points[i][0], w * c.points[i][1], w};
    }
    for (std::size_t r = 1; r <= p; ++r) {
        for (std::size_t j = p; j >= r; --j) {
            const std::size_t i = j + k - p;
            const double alpha = (u - c.knots[i]) / (c.knots[i + p + 1 - r] - c.knots[i]);
            for (int a = 0; a < 3; ++a) d[j][a] = (1 - alpha) * d[j - 1][a] + alpha * d[j][a];
        }
    }
    return {d[p][0] / d[p][2], d[p][1] / d[p][2]};
}

std::vector<double> bezier_at(const PointList& q, std::size_t piece, double t) {
    const std::size_t k = 3 * piece;
    const double s = 1 - t;
    const double b[4] = {s * s * s, 3 * s * s * t, 3 * s * t * t, t * t * t};
    std::vector<double> r(2, 0);
    for (int i = 0; i < 4; ++i) {
        for (int a = 0; a < 2; ++a) r[a] += b[i] * q[k + static_cast<std::size_t>(i)][a];
    }
    return r;
}

double dist(const std::vector<double>& a, const std::vector<double>& b) {
    return std::hypot(a[0] - b[0], a[1] - b[1]);
}

double segment_distance(const std::vector<double>& p, const std::vector<double>& a,
                        const std::vector<double>& b) {
    const double dx = b[0] - a[0], dy = b[1] - a[1], len2 = dx * dx + dy * dy;
    double t = len2 > 0 ? ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / len2 : 0;
    t = std::clamp(t, 0.0, 1.0);
    return std::hypot(p[0] - a[0] - t * dx, p[1] - a[1] - t * dy);
}

/// Largest distance from any point of one dense polyline to the other (both directions).
double hausdorff(const std::vector<std::vector<double>>& a,
                 const std::vector<std::vector<double>>& b) {
    auto one_way = [](const auto& from, const auto& to) {
        double worst = 0;
        for (const auto& p : from) {
            double best = std::numeric_limits<double>::infinity();
            for (std::size_t i = 0; i + 1 < to.size(); ++i)
                best = std::min(best, segment_distance(p, to[i], to[i + 1]));
            worst = std::max(worst, best);
        }
        return worst;
    };
    return std::max(one_way(a, b), one_way(b, a));
}

std::vector<std::vector<double>> dense_curve(const Curve& c, std::size_t samples) {
    const double lo = c.knots[static_cast<std::size_t>(c.degree)], hi = c.knots[c.points.size()];
    std::vector<std::vector<double>> out;
    for (std::size_t s = 0; s <= samples; ++s) {
        out.push_back(
            de_boor(c, lo + (hi - lo) * static_cast<double>(s) / static_cast<double>(samples)));
    }
    return out;
}

std::vector<std::vector<double>> dense_chain(const PointList& q, std::size_t per_piece) {
    std::vector<std::vector<double>> out;
    const std::size_t pieces = (q.size() - 1) / 3;
    for (std::size_t k = 0; k < pieces; ++k) {
        for (std::size_t s = 0; s < per_piece; ++s)
            out.push_back(bezier_at(q, k, static_cast<double>(s) / static_cast<double>(per_piece)));
    }
    out.push_back({q.back()[0], q.back()[1]});
    return out;
}

std::string list(const std::vector<double>& v) {
    std::string s = "[";
    for (std::size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + std::to_string(v[i]);
    return s + "]";
}

std::string json_of(const Curve& c) {
    std::string pts = "[";
    for (std::size_t i = 0; i < c.points.size(); ++i) pts += (i ? ", " : "") + list(c.points[i]);
    pts += "]";
    std::string s =
        "{\"subpaths\": [{\"basis\": \"nurbs\", \"degree\": " + std::to_string(c.degree) +
        ", \"knots\": " + list(c.knots) + ", \"points\": " + pts;
    if (!c.weights.empty()) s += ", \"weights\": " + list(c.weights);
    return s + "}]}";
}

Path read_json(const Curve& c, double tolerance) {
    return parse_json_path(json_of(c), "t.json", tolerance);
}

/// The exact case: piece j of the chain is knot span j, linearly reparameterised.
double exact_error(const Curve& c, const PointList& chain) {
    std::vector<double> breaks;
    for (std::size_t i = static_cast<std::size_t>(c.degree); i <= c.points.size(); ++i) {
        if (breaks.empty() || breaks.back() != c.knots[i]) breaks.push_back(c.knots[i]);
    }
    REQUIRE((chain.size() - 1) / 3 == breaks.size() - 1);
    double worst = 0;
    for (std::size_t j = 0; j + 1 < breaks.size(); ++j) {
        for (int s = 0; s <= 20; ++s) {
            const double t = s / 20.0;
            worst = std::max(worst, dist(bezier_at(chain, j, t),
                                         de_boor(c, breaks[j] + t * (breaks[j + 1] - breaks[j]))));
        }
    }
    return worst;
}

const Curve kUnclampedCubic{3,
                            {{0, 0}, {10, 20}, {20, -10}, {30, 15}, {45, 0}, {50, 30}},
                            {},
                            {0, 1, 2, 3, 4, 5, 6, 7, 8, 9}};
const Curve kDoubleKnotCubic{
    3, {{0, 0}, {5, 10}, {10, 0}, {15, 10}, {20, 0}, {25, 10}}, {}, {0, 0, 0, 0, 1, 1, 2, 2, 2, 2}};
const Curve kQuarterCircle{
    2, {{10, 0}, {10, 10}, {0, 10}}, {1, std::sqrt(0.5), 1}, {0, 0, 0, 1, 1, 1}};
const Curve kQuintic{
    5,
    {{0, 0}, {10, 30}, {20, -30}, {30, 30}, {40, -30}, {50, 30}, {60, 0}, {70, 10}},
    {},
    {0, 0, 0, 0, 0, 0, 1, 2, 3, 3, 3, 3, 3, 3}};
const Curve kRationalQuartic{4,
                             {{0, 0}, {20, 40}, {40, -20}, {60, 40}, {80, 0}, {100, 20}},
                             {1, 3, 0.5, 2, 1, 1},
                             {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10}};

}  // namespace

TEST_CASE("NURBS: non-rational cubics are exact", "[gcode][nurbs]") {
    for (const Curve& c : {kUnclampedCubic, kDoubleKnotCubic}) {
        const Path p = read_json(c, 0.01);
        REQUIRE(p.subpaths.size() == 1);
        CHECK(p.subpaths[0].basis == PathBasis::kBezier);
        CHECK(exact_error(c, p.subpaths[0].points) < 1e-9);
    }
    // Degrees 1 and 2 are raised exactly.
    const Curve line{1, {{0, 0}, {10, 0}, {10, 10}}, {}, {0, 0, 1, 2, 2}};
    CHECK(exact_error(line, read_json(line, 0.01).subpaths[0].points) < 1e-9);
    const Curve quad{2, {{0, 0}, {10, 10}, {20, 0}, {30, 10}}, {}, {0, 0, 0, 1, 2, 2, 2}};
    CHECK(exact_error(quad, read_json(quad, 0.01).subpaths[0].points) < 1e-9);
}

TEST_CASE("NURBS: rational and quintic curves within the tolerance", "[gcode][nurbs]") {
    for (const double tolerance : {0.01, 0.001}) {
        for (const Curve& c : {kQuarterCircle, kQuintic, kRationalQuartic}) {
            const Path p = read_json(c, tolerance);
            const auto& chain = p.subpaths[0].points;
            const double deviation = hausdorff(dense_curve(c, 3000), dense_chain(chain, 200));
            INFO("degree " << c.degree << ", " << (chain.size() - 1) / 3 << " pieces");
            CHECK(deviation <= tolerance);
            CHECK(dist({chain.front()[0], chain.front()[1]},
                       de_boor(c, c.knots[static_cast<std::size_t>(c.degree)])) < 1e-9);
        }
    }
    // The quarter circle against the circle itself: every sample within 0.001 of radius 10.
    const Path p = read_json(kQuarterCircle, 0.001);
    for (const auto& q : dense_chain(p.subpaths[0].points, 100))
        CHECK(std::fabs(std::hypot(q[0], q[1]) - 10) <= 0.001);
}

TEST_CASE("NURBS: JSON errors", "[gcode][nurbs]") {
    auto error = [](const std::string& subpath) {
        try {
            parse_json_path("{\"subpaths\": [" + subpath + "]}", "t.json");
        } catch (const InputError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    const std::string pts = "\"points\": [[0, 0], [1, 1], [2, 0], [3, 1]]";
    CHECK(error("{\"basis\": \"nurbs\", " + pts + "}") == "no error");  // cubic, clamped uniform
    CHECK(error("{\"basis\": \"nurbs\", \"degree\": 6, " + pts + "}") ==
          "t.json:1:44: degree must be a whole number from 1 to 5");
    CHECK(error("{\"basis\": \"nurbs\", \"knots\": [0, 0, 0, 1, 1, 1], " + pts + "}")
              .find("nurbs: needs 8 knots (points + degree + 1), got 6") != std::string::npos);
    CHECK(error("{\"basis\": \"nurbs\", \"knots\": [0, 0, 0, 0, 2, 1, 1, 1], " + pts + "}")
              .find("knots must not decrease") != std::string::npos);
    CHECK(error("{\"basis\": \"nurbs\", \"weights\": [1, 0, 1, 1], " + pts + "}")
              .find("weight 0 must be positive and finite") != std::string::npos);
    CHECK(error("{\"basis\": \"nurbs\", \"closed\": true, " + pts + "}")
              .find("a nurbs subpath is open") != std::string::npos);
    CHECK(error("{\"basis\": \"nurbs\", \"degree\": 1, \"knots\": [0, 0, 1, 1, 2, 2], " + pts + "}")
              .find("knot 1 is repeated 2 times (at most degree = 1 inside the curve)") !=
          std::string::npos);
    CHECK(
        error(
            "{\"basis\": \"bezier\", \"knots\": [0], \"points\": [[0, 0], [1, 1], [2, 0], [3, 1]]}")
            .find("unknown key") != std::string::npos);
}

TEST_CASE("NURBS: G5.2 with weights and order", "[gcode][nurbs]") {
    // LinuxCNC's clamped uniform knots; the start point is the first control point.
    const Path p = parse_gcode_path(
        "G0 X0 Y0 Z-1\nG5.2 X10 Y20 P1 L4\nX20 Y-20 P2\nX30 Y0\nX40 Y10\nG5.3\nG1 X50\n", "t.ngc");
    REQUIRE(p.subpaths.size() == 1);
    const Curve c{3,
                  {{0, 0}, {10, 20}, {20, -20}, {30, 0}, {40, 10}},
                  {1, 1, 2, 1, 1},
                  {0, 0, 0, 0, 1, 2, 2, 2, 2}};
    PointList chain = p.subpaths[0].points;
    for (int k = 0; k < 3; ++k) chain.pop_back();  // the G1 after the curve
    CHECK(hausdorff(dense_curve(c, 3000), dense_chain(chain, 200)) <= 0.01);
    CHECK(chain.back() == PathPoint{40, 10});
    // Equal weights, order 4: exact, one span per knot interval.
    const Path q = parse_gcode_path(
        "G0 X0 Y0 Z-1\nG5.2 X10 Y20 L4\nX20 Y-20\nX30 Y0\nX40 Y10\nG5.3\n", "t.ngc");
    const Curve e{3, c.points, {}, c.knots};
    CHECK(exact_error(e, q.subpaths[0].points) < 1e-9);
    // Without L (or with L3 or less, as LinuxCNC) the order is 3: a quadratic. L may come on
    // any line of the curve, and a second G5.2 continues it.
    const Path r = parse_gcode_path("G0 X0 Y0 Z-1\nG5.2 X10 Y20 L2\nX20 Y0\nG5.3\n", "t.ngc");
    const Curve quad{2, {{0, 0}, {10, 20}, {20, 0}}, {}, {0, 0, 0, 1, 1, 1}};
    CHECK(exact_error(quad, r.subpaths[0].points) < 1e-9);
    const Path late = parse_gcode_path(
        "G0 X0 Y0 Z-1\nG5.2 X10 Y20\nG5.2 X20 Y-20 P1\nX30 Y0 L4\nX40 Y10\nG5.3\n", "t.ngc");
    CHECK(exact_error(e, late.subpaths[0].points) < 1e-9);
}

TEST_CASE("NURBS: G5.2 errors", "[gcode][nurbs]") {
    auto error = [](const std::string& text) {
        try {
            parse_gcode_path(text, "t.ngc");
        } catch (const InputError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    CHECK(error("G0 Z-1\nG5.2 X1 Y1 L4\nX2 Y0\nG5.3\n") ==
          "t.ngc:2:1: G5.2 curve of order L4 needs at least 4 control points (the start point "
          "included), got 3");
    CHECK(error("G5.2 X1 Y1 L7\n") ==
          "t.ngc:1:12: G5.2 order L must be a whole number up to 6 (degree + 1; 3 or less leaves "
          "the order at 3)");
    CHECK(error("G5.2 X1 Y1\nX2\nG5.3\n") == "t.ngc:2:1: a G5.2 control point needs both X and Y");
    CHECK(error("G5.2 X1 Y1\nG5.2 P2\nG5.3\n") ==
          "t.ngc:2:1: a G5.2 control point needs X and Y (P alone weighs only the start point)");
    CHECK(error("G5.2 X1 Y1 Z1\n") == "t.ngc:1:12: Z is not allowed with G5.2 (XY plane only)");
    CHECK(error("G5.2 X1 Y1 P0\n") == "t.ngc:1:12: G5.2 weight P must be positive");
    CHECK(error("G5.2 X1 Y1\nG1 X2\n") ==
          "t.ngc:2:1: the G5.2 curve must end with G5.3 before other motion or G4, G10, G28, G30, "
          "G53, "
          "G92");
    CHECK(error("G5.2 X1 Y1\nX2 Y0\nM2\n") ==
          "t.ngc:3:1: program ends inside a G5.2 curve (no G5.3)");
    CHECK(error("G5.3\n") == "t.ngc:1:1: G5.3 without a G5.2 curve to end");
}
