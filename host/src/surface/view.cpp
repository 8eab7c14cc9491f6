// The view's frame and the projection of model points onto the drawing.
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "pathstream/host/surface.hpp"

namespace pathstream::host {
namespace {

double dot(const Point3& a, const Point3& b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

double radians(double degrees) {
    return degrees * std::numbers::pi / 180.0;
}

}  // namespace

ViewFrame view_frame(const SurfaceView& view) {
    if (!std::isfinite(view.azimuth_deg) || !std::isfinite(view.elevation_deg) ||
        !std::isfinite(view.roll_deg)) {
        throw std::invalid_argument("view angles must be finite");
    }
    if (!(view.scale > 0) || !std::isfinite(view.scale)) {
        throw std::invalid_argument("view scale must be positive and finite");
    }
    if (view.projection == SurfaceView::Projection::kPerspective &&
        (!(view.eye_distance > 0) || !std::isfinite(view.eye_distance))) {
        throw std::invalid_argument("a perspective view needs a positive eye distance");
    }
    const double az = radians(view.azimuth_deg), el = radians(view.elevation_deg);
    const double roll = radians(view.roll_deg);
    ViewFrame f;
    f.view = view;
    f.toward_eye = {std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el)};
    const Point3 right{-std::sin(az), std::cos(az), 0};
    const Point3 up{-std::sin(el) * std::cos(az), -std::sin(el) * std::sin(az), std::cos(el)};
    // Roll turns the drawing's axes about the line of sight, counter-clockwise on the page.
    const double c = std::cos(roll), s = std::sin(roll);
    for (int k = 0; k < 3; ++k) {
        f.right[k] = c * right[k] + s * up[k];
        f.up[k] = -s * right[k] + c * up[k];
    }
    return f;
}

double view_depth(const ViewFrame& frame, const Point3& p) {
    return dot(frame.toward_eye, p);
}

std::array<double, 2> project_point(const ViewFrame& frame, const Point3& p) {
    // The page's y runs down, as on the plotter and in SVG: up in the view is -y.
    const double x = dot(frame.right, p), y = -dot(frame.up, p);
    const SurfaceView& v = frame.view;
    if (v.projection == SurfaceView::Projection::kOrthographic) return {v.scale * x, v.scale * y};
    const double ahead = v.eye_distance - view_depth(frame, p);
    if (!(ahead > 0)) {
        throw std::domain_error("a point is not in front of the eye (eye distance " +
                                std::to_string(v.eye_distance) + ")");
    }
    const double k = v.scale * v.eye_distance / ahead;
    return {k * x, k * y};
}

}  // namespace pathstream::host
