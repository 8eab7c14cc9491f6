// The G-code corpus (tests/data/gcode/): each program's drawn length and bounding box against
// figures computed here from the shapes the program describes, not from the reader.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <numbers>
#include <string>

#include "pathstream/host/gcode_path.hpp"

using namespace pathstream::host;

namespace {

constexpr double kPi = std::numbers::pi;

std::string corpus(const std::string& name) {
    return std::string(PATHSTREAM_SOURCE_DIR) + "/tests/data/gcode/" + name;
}

struct Figures {
    double length = 0;
    double x_min = std::numeric_limits<double>::infinity(), x_max = -x_min;
    double y_min = x_min, y_max = -x_min;

    void add(double x, double y) {
        x_min = std::min(x_min, x);
        x_max = std::max(x_max, x);
        y_min = std::min(y_min, y);
        y_max = std::max(y_max, y);
    }
};

/// Drawn length (Gauss-Legendre on each cubic) and bounding box (64 samples per cubic).
Figures measure(const Path& path) {
    static const double gx[4] = {0.1834346424956498, 0.5255324099163290, 0.7966664774136267,
                                 0.9602898564975363};
    static const double gw[4] = {0.3626837833783620, 0.3137066458778873, 0.2223810344533745,
                                 0.1012285362903763};
    Figures f;
    for (const Subpath& sp : path.subpaths) {
        // A run of lines is a polyline: its Bezier chain has the control points at the thirds.
        std::vector<PathPoint> q;
        for (std::size_t i = 0; i < sp.points.size(); ++i) {
            const PathPoint p = sp.points[i];
            if (sp.basis == PathBasis::kPolyline && i > 0) {
                const PathPoint a = q.back();
                q.push_back({a[0] + (p[0] - a[0]) / 3, a[1] + (p[1] - a[1]) / 3});
                q.push_back({a[0] + 2 * (p[0] - a[0]) / 3, a[1] + 2 * (p[1] - a[1]) / 3});
            }
            q.push_back(p);
        }
        for (std::size_t k = 0; k + 3 < q.size(); k += 3) {
            auto at = [&](double t, int axis) {
                const double s = 1 - t;
                return s * s * s * q[k][axis] + 3 * s * s * t * q[k + 1][axis] +
                       3 * s * t * t * q[k + 2][axis] + t * t * t * q[k + 3][axis];
            };
            auto speed = [&](double t) {
                const double s = 1 - t;
                double v2 = 0;
                for (int a = 0; a < 2; ++a) {
                    const double d = 3 * s * s * (q[k + 1][a] - q[k][a]) +
                                     6 * s * t * (q[k + 2][a] - q[k + 1][a]) +
                                     3 * t * t * (q[k + 3][a] - q[k + 2][a]);
                    v2 += d * d;
                }
                return std::sqrt(v2);
            };
            for (int piece = 0; piece < 8; ++piece) {
                const double mid = (piece + 0.5) / 8, half = 0.5 / 8;
                for (int i = 0; i < 4; ++i) {
                    f.length +=
                        gw[i] * half * (speed(mid - half * gx[i]) + speed(mid + half * gx[i]));
                }
            }
            for (int s = 0; s <= 64; ++s) f.add(at(s / 64.0, 0), at(s / 64.0, 1));
        }
    }
    return f;
}

/// Arcs and NURBS within 1e-4 mm: a convex curve that close to a circle of radius r is
/// between 2 pi (r - 1e-4) and 2 pi (r + 1e-4) long.
constexpr double kTolerance = 1e-4;

Figures read(const std::string& name) {
    GcodeOptions options;
    options.arc_tolerance_mm = kTolerance;
    return measure(load_gcode_path(corpus(name), options));
}

void check_box(const Figures& f, double x0, double x1, double y0, double y1, double eps) {
    CHECK(f.x_min == Approx(x0).margin(eps));
    CHECK(f.x_max == Approx(x1).margin(eps));
    CHECK(f.y_min == Approx(y0).margin(eps));
    CHECK(f.y_max == Approx(y1).margin(eps));
}

/// What "%.4f" makes of v, read back: the rounding the generator script applies.
double four_decimals(double v) {
    char text[64];
    std::snprintf(text, sizeof text, "%.4f", v);
    return std::strtod(text, nullptr);
}

}  // namespace

TEST_CASE("G-code corpus: subroutines", "[gcode][corpus]") {
    double length = 0, x = 0, right = 0;
    for (int n = 1; n <= 4; ++n) {
        length += 4 * 10.0 * n;
        right = x + 10.0 * n;
        x += 10.0 * n + 5;
    }
    const Figures f = read("subroutines.ngc");
    CHECK(f.length == Approx(length).margin(1e-9));
    check_box(f, 0, right, 0, 40, 1e-9);
}

TEST_CASE("G-code corpus: loops", "[gcode][corpus]") {
    const Figures f = read("loops.ngc");
    CHECK(f.length == Approx(2 * kPi * (5 + 10 + 15 + 20)).margin(4 * 2 * kPi * kTolerance));
    check_box(f, 30, 70, 30, 70, 2e-3);  // 64 samples of a 90-degree piece of radius 20
}

TEST_CASE("G-code corpus: parameters", "[gcode][corpus]") {
    Figures expected;
    const double r = 40, step = 144;
    for (int k = 0; k <= 5; ++k) {
        const double a = (90 + k * step) * kPi / 180;
        expected.add(100 + r * std::cos(a), 100 + r * std::sin(a));
    }
    expected.add(60, 50);  // the underline, 2r long
    expected.add(140, 50);
    const Figures f = read("parameters.ngc");
    CHECK(f.length == Approx(5 * 2 * r * std::sin(72 * kPi / 180) + 2 * r).margin(1e-9));
    check_box(f, expected.x_min, expected.x_max, expected.y_min, expected.y_max, 1e-9);
}

TEST_CASE("G-code corpus: NURBS", "[gcode][corpus]") {
    // A quarter of the circle of radius 10, then the parabola (20 + 20t, 40t(1 - t)).
    const double parabola = (20 * std::sqrt(2000.0) + 200 * std::asinh(2.0)) / 40;
    const Figures f = read("nurbs.ngc");
    CHECK(f.length == Approx(5 * kPi + parabola).margin(2 * kPi * kTolerance / 4));
    check_box(f, 0, 40, 0, 10, 1e-3);
}

TEST_CASE("G-code corpus: tiny arcs", "[gcode][corpus]") {
    // 25 circles of radius 0.04 mm on a 0.2 mm grid from (1, 1); ends rounded to 0.0001 mm.
    const Figures f = read("tiny_arcs.ngc");
    CHECK(f.length == Approx(25 * 2 * kPi * 0.04).margin(0.002));
    check_box(f, 0.96, 1.84, 0.96, 1.84, 2e-4);
}

TEST_CASE("G-code corpus: no pen codes", "[gcode][corpus]") {
    GcodeOptions options;
    options.pen = PenControl::kAuto;
    GcodeReadInfo info;
    const Figures f = measure(load_gcode_path(corpus("no_pen.ngc"), options, &info));
    CHECK(info.pen == PenControl::kMotion);
    CHECK(info.warnings.size() == 4);  // $H, M2000, M888, M300
    CHECK(f.length == Approx(4 * 40 + 20 + 2 * std::hypot(10, 20)).margin(1e-9));
    check_box(f, 10, 80, 10, 50, 1e-9);
}

TEST_CASE("G-code corpus: generated rose", "[gcode][corpus]") {
    // make_rose.py: r = 40 cos(4t) about (100, 100), 3600 steps, "%.4f".
    Figures expected;
    double px = 0, py = 0;
    for (int k = 0; k <= 3600; ++k) {
        const double t = 2 * kPi * k / 3600, r = 40 * std::cos(4 * t);
        const double x = four_decimals(100 + r * std::cos(t)),
                     y = four_decimals(100 + r * std::sin(t));
        if (k > 0) expected.length += std::hypot(x - px, y - py);
        expected.add(x, y);
        px = x;
        py = y;
    }
    const Figures f = read("rose.ngc");
    CHECK(f.length == Approx(expected.length).margin(1e-6));
    check_box(f, expected.x_min, expected.x_max, expected.y_min, expected.y_max, 1e-9);
}
