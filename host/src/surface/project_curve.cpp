// Projection of model curves: affine views keep polynomial curves polynomial; a perspective
// view makes them rational (weight: the eye's distance ahead), which the NURBS fitter takes.
#include "project_curve.hpp"

#include <stdexcept>

#include "../nurbs/nurbs.hpp"
#include "pathstream/host/hidden_lines.hpp"

namespace pathstream::host::surface {

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
                                     double tolerance_mm, bool& exact) {
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
    nurbs::Nurbs curve;
    curve.degree = static_cast<int>(q.size()) - 1;
    for (std::size_t i = 0; i < q.size(); ++i) {
        const auto xy = project_point(frame, q[i]);
        curve.points.push_back({xy[0], xy[1]});
        double w = weights.empty() ? 1.0 : weights[i];
        if (!ortho) {
            w *= (frame.view.eye_distance - view_depth(frame, q[i])) / frame.view.eye_distance;
        }
        curve.weights.push_back(w);
    }
    curve.knots.assign(q.size(), 0.0);
    curve.knots.insert(curve.knots.end(), q.size(), 1.0);
    // No projected iso-curve of a real drawing needs this many cubics; the cap bounds what a
    // curve grazing the eye can cost.
    return nurbs::nurbs_to_bezier(curve, tolerance_mm, 100'000);
}

std::vector<std::vector<PathPoint>> draw_curve(const std::vector<Point3>& q,
                                               const std::vector<double>& weights,
                                               const ViewFrame& frame, double tolerance_mm,
                                               const Occluder* occluder,
                                               WireframeFigures& figures) {
    std::vector<std::vector<PathPoint>> out;
    auto add = [&](const std::vector<Point3>& piece, const std::vector<double>& w) {
        bool exact = false;
        std::vector<PathPoint> chain = project_curve(piece, w, frame, tolerance_mm, exact);
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
