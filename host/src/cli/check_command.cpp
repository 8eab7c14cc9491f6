#include "check_command.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <limits>

#include "pathstream/host/geometry.hpp"

namespace pathstream::host {

void add_check_command(CLI::App& app, CheckOptions& o) {
    CLI::App* cmd = app.add_subcommand("check", "Validate a path file and print a summary: subpaths, spans, length, bounding box");
    add_path_options(*cmd, o.path);
}

namespace {

/// Arc length of a segment: 8-point Gauss-Legendre on each of 8 sub-intervals (exact to
/// ~1e-12 relative for the smooth speed of a cubic).
double segment_length(const BezierSegment& s) {
    static const double x[4] = {0.1834346424956498, 0.5255324099163290, 0.7966664774136267, 0.9602898564975363};
    static const double w[4] = {0.3626837833783620, 0.3137066458778873, 0.2223810344533745, 0.1012285362903763};
    double total = 0;
    constexpr int kPieces = 8;
    for (int piece = 0; piece < kPieces; ++piece) {
        const double a = static_cast<double>(piece) / kPieces, half = 0.5 / kPieces, mid = a + half;
        for (int i = 0; i < 4; ++i) {
            for (const double sign : {-1.0, 1.0}) {
                const PathPoint d = bezier_d1(s, mid + sign * half * x[i]);
                double speed = 0;
                for (double c : d) speed += c * c;
                total += w[i] * half * std::sqrt(speed);
            }
        }
    }
    return total;
}

/// Exact per-axis extent of a cubic: its ends and the roots of its derivative in (0, 1).
void extend_box(const BezierSegment& s, std::vector<double>& lo, std::vector<double>& hi) {
    for (std::size_t a = 0; a < lo.size(); ++a) {
        const double p0 = s.p[0][a], p1 = s.p[1][a], p2 = s.p[2][a], p3 = s.p[3][a];
        // derivative / 3 = A u^2 + B u + C
        const double A = -p0 + 3 * p1 - 3 * p2 + p3, B = 2 * (p0 - 2 * p1 + p2), C = p1 - p0;
        std::vector<double> us{0.0, 1.0};
        if (std::fabs(A) > 1e-15) {
            const double disc = B * B - 4 * A * C;
            if (disc >= 0) {
                us.push_back((-B + std::sqrt(disc)) / (2 * A));
                us.push_back((-B - std::sqrt(disc)) / (2 * A));
            }
        } else if (std::fabs(B) > 1e-15) {
            us.push_back(-C / B);
        }
        for (double u : us) {
            if (u < 0 || u > 1) continue;
            const double v = bezier_point(s, u)[a];
            lo[a] = std::min(lo[a], v);
            hi[a] = std::max(hi[a], v);
        }
    }
}

}  // namespace

int run_check(const CheckOptions& o) {
    const Path path = load_path(o.path);
    const std::vector<BezierSegment> segments = to_bezier_segments(path);
    double drawn = 0, travel = 0;
    std::size_t drawing_segments = 0;
    std::vector<double> lo(path.axes, std::numeric_limits<double>::infinity());
    std::vector<double> hi(path.axes, -std::numeric_limits<double>::infinity());
    for (const auto& s : segments) {
        const double length = segment_length(s);
        if (s.pen_down) {
            drawn += length;
            ++drawing_segments;
            extend_box(s, lo, hi);
        } else {
            travel += length;
        }
    }
    std::printf("%s: valid, %zu axes, units %s\n", o.path.file.c_str(), path.axes, path.units.c_str());
    std::printf("  subpaths: %zu\n", path.subpaths.size());
    for (std::size_t i = 0; i < path.subpaths.size() && i < 20; ++i) {
        const Subpath& sp = path.subpaths[i];
        std::printf("    %zu: %s, %s, %zu points%s\n", i, basis_name(sp.basis), sp.closed ? "closed" : "open",
                    sp.points.size(), sp.feed > 0 ? (", feed " + std::to_string(sp.feed) + " mm/s").c_str() : "");
    }
    if (path.subpaths.size() > 20) std::printf("    ... %zu more\n", path.subpaths.size() - 20);
    std::printf("  spans: %zu drawing, %zu travel\n", drawing_segments, segments.size() - drawing_segments);
    std::printf("  length: %.3f mm drawn, %.3f mm pen-up travel\n", drawn, travel);
    std::printf("  bounding box (drawing):");
    for (std::size_t a = 0; a < path.axes; ++a) {
        std::printf(" %s %.3f .. %.3f mm%s", axis_column_name(a), lo[a], hi[a], a + 1 < path.axes ? "," : "\n");
    }
    return 0;
}

}  // namespace pathstream::host
