// One model-space Bezier curve (polynomial or rational, degree 1 to 3) onto the drawing: the
// exact projected cubic where the view keeps it polynomial, else a fitted chain.
#pragma once

#include <vector>

#include "pathstream/host/surface.hpp"

namespace pathstream::host::surface {

/// The drawing's open Bezier chain (2 axes, P0 C C P1 ...) for the curve with control points
/// `q` and, when not empty, positive `weights` (a rational curve). Exact (degree raised to 3)
/// when the view is orthographic and the curve polynomial, or when it is a line; otherwise the
/// projected rational curve fitted with a proven bound within `tolerance_mm` (the function-
/// curve fitter on its ratio of Bernstein sums; `exact` says which). The fit evaluates at most
/// `*fit_cells_left` interval cells (nullptr: the fitter's own limit) and lowers it by those
/// used. Throws std::domain_error when a control point is not in front of the eye,
/// std::length_error when the fit needs more than 100,000 cubics or more cells.
std::vector<PathPoint> project_curve(const std::vector<Point3>& q,
                                     const std::vector<double>& weights, const ViewFrame& frame,
                                     double tolerance_mm, bool& exact,
                                     std::size_t* fit_cells_left = nullptr);

/// The drawing's chains of the curve `q` (with `weights` as in project_curve): the whole
/// curve, or with `occluder` each part it does not hide. Adds to figures' curves, exact
/// curves, hidden and split counts.
std::vector<std::vector<PathPoint>> draw_curve(const std::vector<Point3>& q,
                                               const std::vector<double>& weights,
                                               const ViewFrame& frame, double tolerance_mm,
                                               const Occluder* occluder, WireframeFigures& figures,
                                               std::size_t* fit_cells_left = nullptr);

/// `q` (degree 1 to 3) raised to degree 3: the same curve, four control points. O(1).
std::vector<Point3> raise_to_cubic(const std::vector<Point3>& q);

}  // namespace pathstream::host::surface
