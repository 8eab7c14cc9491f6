// Projection of model curves: affine views keep polynomial curves polynomial; a perspective
// view makes them rational (weight: the eye's distance ahead), which the NURBS fitter takes.
#include "project_curve.hpp"

#include <algorithm>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "../curves/fit_function.hpp"
#include "pathstream/host/hidden_lines.hpp"

namespace pathstream::host::surface {
namespace {

// sum_i c[i] B_i(t), the Bernstein basis of degree c.size() - 1, as an expression in t with
// every coefficient printed so that it reads back as the same double.
std::string bernstein_sum(const std::vector<double>& c) {
    static const char* const basis[4][4] = {
        {"1", "", "", ""},
        {"(1-t)", "t", "", ""},
        {"(1-t)^2", "2*t*(1-t)", "t^2", ""},
        {"(1-t)^3", "3*t*(1-t)^2", "3*t^2*(1-t)", "t^3"},
    };
    std::string out;
    char number[40];
    for (std::size_t i = 0; i < c.size(); ++i) {
        std::snprintf(number, sizeof number, "%.17g", c[i]);
        out += (i ? " + (" : "(") + std::string(number) + ")*" + basis[c.size() - 1][i];
    }
    return out;
}

}  // namespace

std::vector<Point3> raise_to_cubic(const std::vector<Point3>& q) {
    auto mix = [](const Point3& a, double wa, const Point3& b, double wb) {
        return Point3{(wa * a[0] + wb * b[0]) / 3, (wa * a[1] + wb * b[1]) / 3,
                      (wa * a[2] + wb * b[2]) / 3};
    };
    switch (q.size()) {
        case 2:
            return {q[0], mix(q[0], 2, q[1], 1), mix(q[0], 1, q[1], 2), q[1]};
        case 3:
            return {q[0], mix(q[0], 1, q[1], 2), mix(q[1], 2, q[2], 1), q[2]};
        case 4:
            return q;
        default:
            throw std::invalid_argument("a curve of degree 1 to 3 has 2 to 4 control points");
    }
}

std::vector<PathPoint> project_curve(const std::vector<Point3>& q,
                                     const std::vector<double>& weights, const ViewFrame& frame,
                                     double tolerance_mm, bool& exact,
                                     std::size_t* fit_cells_left) {
    const bool ortho = frame.view.projection == SurfaceView::Projection::kOrthographic;
    // A straight line stays straight under any projection: its end points say it all.
    const bool line = q.size() == 2 && weights.empty();
    if ((ortho && weights.empty()) || line) {
        exact = true;
        std::vector<PathPoint> out;
        for (const Point3& p : raise_to_cubic(q)) {
            const auto xy = project_point(frame, p);
            out.push_back({xy[0], xy[1]});
        }
        return out;
    }
    exact = false;
    // The projected curve is rational: each coordinate is a ratio of Bernstein sums, which
    // the function-curve fitter takes as an expression and fits with a proven bound.
    const std::size_t n = q.size() - 1;
    std::vector<double> w(q.size()), wx(q.size()), wy(q.size());
    for (std::size_t i = 0; i <= n; ++i) {
        const auto xy = project_point(frame, q[i]);
        w[i] = weights.empty() ? 1.0 : weights[i];
        if (!ortho) {
            w[i] *= (frame.view.eye_distance - view_depth(frame, q[i])) / frame.view.eye_distance;
        }
        wx[i] = w[i] * xy[0];
        wy[i] = w[i] * xy[1];
    }
    const std::string denominator = bernstein_sum(w);
    curves::FunctionCurve curve;
    curve.coordinates.push_back(
        curves::parse_expression("(" + bernstein_sum(wx) + ")/(" + denominator + ")"));
    curve.coordinates.push_back(
        curves::parse_expression("(" + bernstein_sum(wy) + ")/(" + denominator + ")"));
    curve.t0 = 0;
    curve.t1 = 1;
    curves::FitLimits limits;
    // No projected iso-curve of a real drawing needs this many cubics; the caps bound what a
    // curve grazing the eye can cost.
    limits.max_pieces = 100'000;
    if (fit_cells_left) limits.max_cells = *fit_cells_left;
    curves::FitFigures figures;
    try {
        std::vector<PathPoint> out =
            curves::fit_function_curve(curve, tolerance_mm, &figures, limits);
        if (fit_cells_left) *fit_cells_left -= std::min(*fit_cells_left, figures.cells);
        return out;
    } catch (const curves::FitError& e) {
        throw std::length_error(std::string("a projected curve cannot be fitted: ") + e.what());
    }
}

std::vector<std::vector<PathPoint>> draw_curve(const std::vector<Point3>& q,
                                               const std::vector<double>& weights,
                                               const ViewFrame& frame, double tolerance_mm,
                                               const Occluder* occluder, WireframeFigures& figures,
                                               std::size_t* fit_cells_left) {
    std::vector<std::vector<PathPoint>> out;
    auto add = [&](const std::vector<Point3>& piece, const std::vector<double>& w) {
        bool exact = false;
        std::vector<PathPoint> chain =
            project_curve(piece, w, frame, tolerance_mm, exact, fit_cells_left);
        if (chain.size() < 4) return;  // fitted to nothing: a point on the page
        ++figures.curves;
        if (exact) ++figures.exact_curves;
        out.push_back(std::move(chain));
    };
    if (!occluder) {
        add(q, weights);
        return out;
    }
    const auto intervals = visible_intervals(q, weights, frame, *occluder, tolerance_mm);
    if (intervals.empty()) {
        ++figures.hidden;
        return out;
    }
    if (intervals.size() > 1 || intervals[0][0] > 0 || intervals[0][1] < 1) ++figures.split;
    for (const auto& iv : intervals) {
        std::vector<double> w = weights;
        const std::vector<Point3> piece = bezier_piece(q, w, iv[0], iv[1]);
        add(piece, w);
    }
    return out;
}

}  // namespace pathstream::host::surface
