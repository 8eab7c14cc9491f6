// NURBS curves (any dimension, degree 1 to 5, clamped or unclamped knots, optional weights)
// as cubic Bezier chains: exact where a cubic can be exact, else within a tolerance.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "pathstream/host/path.hpp"

namespace pathstream::host::nurbs {

constexpr int kMaxDegree = 5;

/// A NURBS curve. The curve runs over the knots' domain [knots[degree], knots[n]] (n: the
/// number of control points), as usual for clamped and unclamped knot vectors alike.
struct Nurbs {
    int degree = 3;
    std::vector<PathPoint> points;  ///< control points, one dimension for all
    std::vector<double> weights;    ///< one per point, > 0; empty: all 1 (non-rational)
    std::vector<double> knots;      ///< non-decreasing, points.size() + degree + 1 values
};

/// Empty when `curve` is usable; else what is wrong ("degree must be 1 to 5", "needs 7 knots
/// (points + degree + 1), got 6", "knots must not decrease", "knot 0.5 is repeated 4 times
/// (at most degree = 3 inside the curve)", "weight 2 must be positive and finite", ...).
std::string nurbs_problem(const Nurbs& curve);

/// The clamped knot vector with evenly spaced inner knots that LinuxCNC gives G5.2 curves:
/// degree + 1 zeros, 1, 2, ..., then degree + 1 copies of the last value.
std::vector<double> clamped_uniform_knots(std::size_t points, int degree);

/// The curve as an open cubic Bezier chain (P0 C C P1 ... , 3k + 1 points). Non-rational
/// curves of degree 1 to 3 are exact (knot insertion to Bezier spans, lines and quadratics
/// raised to cubics); rational curves and degrees 4 and 5 are approximated with cubic
/// pieces that stay within `tolerance` of the curve (checked at 31 points per piece against
/// the same parameter, which bounds the distance). Spans of zero length are dropped; the
/// result is empty when the whole curve is a point. `curve` must pass nurbs_problem.
/// Throws std::length_error past `max_pieces` pieces.
std::vector<PathPoint> nurbs_to_bezier(const Nurbs& curve, double tolerance,
                                       std::size_t max_pieces = 1'000'000);

}  // namespace pathstream::host::nurbs
