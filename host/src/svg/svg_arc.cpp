// Lines, quadratics and elliptical arcs as cubic pieces; arcs within a tolerance in mm.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "pathstream/host/svg_path.hpp"

namespace pathstream::host::svg {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr int kSamples = 32;      // deviation checked at t = i / kSamples, 0 < i < kSamples
constexpr double kMargin = 0.97;  // samples may miss the true maximum by a little
constexpr int kMaxDepth = 16;     // halvings per quarter; far below any sane tolerance

Point lerp(Point p, Point q, double t) {
    return {p.x + (q.x - p.x) * t, p.y + (q.y - p.y) * t};
}

// (cos, sin) of theta, exact at multiples of 90 degrees so quarter points land on the axes.
Point unit(double theta) {
    const double quarters = theta / (kPi / 2);
    if (quarters == std::round(quarters) && std::fabs(quarters) < 1e9) {
        switch (((static_cast<long long>(quarters) % 4) + 4) % 4) {
            case 0:
                return {1, 0};
            case 1:
                return {0, 1};
            case 2:
                return {-1, 0};
            default:
                return {0, -1};
        }
    }
    return {std::cos(theta), std::sin(theta)};
}

// The standard cubic for the unit circle arc from angle a to b (|b - a| <= 90 degrees).
Cubic unit_arc(double a, double b) {
    const double k = 4.0 / 3.0 * std::tan((b - a) / 4);
    const Point p0 = unit(a), p3 = unit(b);
    return {p0, Point{p0.x - k * p0.y, p0.y + k * p0.x}, Point{p3.x + k * p3.y, p3.y - k * p3.x},
            p3};
}

Point bezier(const Cubic& c, double t) {
    const double s = 1 - t;
    const double b0 = s * s * s, b1 = 3 * s * s * t, b2 = 3 * s * t * t, b3 = t * t * t;
    return {b0 * c[0].x + b1 * c[1].x + b2 * c[2].x + b3 * c[3].x,
            b0 * c[0].y + b1 * c[1].y + b2 * c[2].y + b3 * c[3].y};
}

// Largest distance, in mm, from the mapped unit cubic to the mapped unit circle, at samples.
// `m` maps the unit circle to mm. Each sample's distance is found by Newton's method on the
// angle, starting from the sample's own angle; the best of the iterates is kept, so the value
// is always an upper bound of the true distance at that sample.
double deviation_mm(const Cubic& u, const Affine& m) {
    double worst = 0;
    for (int i = 1; i < kSamples; ++i) {
        const Point q = bezier(u, static_cast<double>(i) / kSamples);
        double theta = std::atan2(q.y, q.x);
        double best = INFINITY;
        for (int iteration = 0; iteration < 4; ++iteration) {
            const double cs = std::cos(theta), sn = std::sin(theta);
            // d = L (u(theta) - q); t1 = L u'(theta); t2 = L u''(theta) = -L u(theta)
            const double ux = cs - q.x, uy = sn - q.y;
            const double dx = m.a * ux + m.c * uy, dy = m.b * ux + m.d * uy;
            best = std::min(best, std::hypot(dx, dy));
            const double t1x = -m.a * sn + m.c * cs, t1y = -m.b * sn + m.d * cs;
            const double t2x = -(m.a * cs + m.c * sn), t2y = -(m.b * cs + m.d * sn);
            const double g1 = dx * t1x + dy * t1y;
            const double g2 = t1x * t1x + t1y * t1y + dx * t2x + dy * t2y;
            if (!(g2 > 0)) break;
            theta -= g1 / g2;
        }
        worst = std::max(worst, best);
    }
    return worst;
}

void refine(double a, double b, int depth, const Affine& to_user, const Affine& to_mm_unit,
            double tolerance_mm, std::vector<Cubic>& out) {
    const Cubic u = unit_arc(a, b);
    if (depth < kMaxDepth && deviation_mm(u, to_mm_unit) > tolerance_mm * kMargin) {
        const double mid = a + (b - a) / 2;
        refine(a, mid, depth + 1, to_user, to_mm_unit, tolerance_mm, out);
        refine(mid, b, depth + 1, to_user, to_mm_unit, tolerance_mm, out);
        return;
    }
    out.push_back({to_user(u[0]), to_user(u[1]), to_user(u[2]), to_user(u[3])});
}

}  // namespace

Cubic line_cubic(Point from, Point to) {
    return {from, lerp(from, to, 1.0 / 3.0), lerp(from, to, 2.0 / 3.0), to};
}

Cubic quadratic_cubic(Point from, Point control, Point to) {
    return {from, lerp(from, control, 2.0 / 3.0), lerp(to, control, 2.0 / 3.0), to};
}

std::vector<Cubic> ellipse_arc_cubics(Point center, double rx, double ry, double phi_radians,
                                      double theta1, double delta, const Affine& to_mm,
                                      double tolerance_mm) {
    const Point axis = unit(phi_radians);
    // unit circle -> user space: translate(center) rotate(phi) scale(rx, ry)
    const Affine to_user{axis.x * rx, axis.y * rx, -axis.y * ry, axis.x * ry, center.x, center.y};
    const Affine to_mm_unit = to_mm * to_user;
    const int quarters =
        std::clamp(static_cast<int>(std::ceil(std::fabs(delta) / (kPi / 2) - 1e-9)), 1, 4);
    std::vector<Cubic> out;
    double a = theta1;
    for (int i = 1; i <= quarters; ++i) {
        const double b = i == quarters ? theta1 + delta : theta1 + delta * i / quarters;
        refine(a, b, 0, to_user, to_mm_unit, tolerance_mm, out);
        a = b;
    }
    return out;
}

std::vector<Cubic> arc_to_cubics(Point from, double rx, double ry, double angle_degrees,
                                 bool large_arc, bool sweep, Point to, const Affine& to_mm,
                                 double tolerance_mm) {
    // SVG 2, appendix "Implementation notes", elliptical arcs: out-of-range parameters.
    if (from == to) return {};
    if (rx == 0 || ry == 0) return {line_cubic(from, to)};
    rx = std::fabs(rx);
    ry = std::fabs(ry);
    const double phi = std::fmod(angle_degrees, 360.0) * kPi / 180.0;
    const Point axis = unit(phi);
    const double cs = axis.x, sn = axis.y;
    // Step 1: (x1', y1'), the half chord in the ellipse's axes.
    const double hx = (from.x - to.x) / 2, hy = (from.y - to.y) / 2;
    const double x1 = cs * hx + sn * hy, y1 = -sn * hx + cs * hy;
    // Radii too small to span the chord are scaled up until they just do.
    const double lambda = (x1 / rx) * (x1 / rx) + (y1 / ry) * (y1 / ry);
    double coef = 0;
    if (lambda > 1) {
        const double grow = std::sqrt(lambda);
        rx *= grow;
        ry *= grow;
    } else {
        coef = std::sqrt(std::max(0.0, (1 - lambda) / lambda));
        if (large_arc == sweep) coef = -coef;
    }
    // Step 2 and 3: the centre.
    const double cx1 = coef * (y1 / ry) * rx, cy1 = -coef * (x1 / rx) * ry;
    const Point center{cs * cx1 - sn * cy1 + (from.x + to.x) / 2,
                       sn * cx1 + cs * cy1 + (from.y + to.y) / 2};
    // Step 4: start angle and sweep.
    const double theta1 = std::atan2((y1 - cy1) / ry, (x1 - cx1) / rx);
    const double theta2 = std::atan2((-y1 - cy1) / ry, (-x1 - cx1) / rx);
    double delta = theta2 - theta1;
    if (sweep && delta < 0) delta += 2 * kPi;
    if (!sweep && delta > 0) delta -= 2 * kPi;
    if (!std::isfinite(center.x) || !std::isfinite(center.y) || !std::isfinite(delta) ||
        delta == 0) {
        // Only with radii or chords near the limits of double: the arc is a straight line then.
        return {line_cubic(from, to)};
    }
    std::vector<Cubic> out =
        ellipse_arc_cubics(center, rx, ry, phi, theta1, delta, to_mm, tolerance_mm);
    out.front()[0] = from;
    out.back()[3] = to;
    return out;
}

std::vector<Cubic> ellipse_cubics(Point center, double rx, double ry, const Affine& to_mm,
                                  double tolerance_mm) {
    std::vector<Cubic> out = ellipse_arc_cubics(center, rx, ry, 0, 0, 2 * kPi, to_mm, tolerance_mm);
    out.back()[3] = out.front()[0];
    return out;
}

std::vector<Cubic> rect_cubics(double x, double y, double width, double height, double rx,
                               double ry, const Affine& to_mm, double tolerance_mm) {
    // A corner with one zero radius is square (an arc of radius 0 is a straight line): only
    // then do the sides meet. rx="0" ry="20" once drew a diagonal instead of the bottom side.
    if (!(rx > 0) || !(ry > 0)) rx = ry = 0;
    const double x0 = x, x1 = x + rx, x2 = x + width - rx, x3 = x + width;
    const double y0 = y, y1 = y + ry, y2 = y + height - ry, y3 = y + height;
    std::vector<Cubic> out;
    const auto corner = [&](Point c, double a, Point from, Point to) {
        if (rx == 0 || ry == 0) return;
        std::vector<Cubic> arc = ellipse_arc_cubics(c, rx, ry, 0, a, kPi / 2, to_mm, tolerance_mm);
        arc.front()[0] = from;
        arc.back()[3] = to;
        out.insert(out.end(), arc.begin(), arc.end());
    };
    out.push_back(line_cubic({x1, y0}, {x2, y0}));
    corner({x2, y1}, -kPi / 2, {x2, y0}, {x3, y1});
    out.push_back(line_cubic({x3, y1}, {x3, y2}));
    corner({x2, y2}, 0, {x3, y2}, {x2, y3});
    out.push_back(line_cubic({x2, y3}, {x1, y3}));
    corner({x1, y2}, kPi / 2, {x1, y3}, {x0, y2});
    out.push_back(line_cubic({x0, y2}, {x0, y1}));
    corner({x1, y1}, kPi, {x0, y1}, {x1, y0});
    return out;
}

std::vector<Cubic> polyline_cubics(const std::vector<Point>& points, bool closed) {
    std::vector<Cubic> out;
    for (std::size_t i = 1; i < points.size(); ++i)
        out.push_back(line_cubic(points[i - 1], points[i]));
    if (closed && points.size() > 1 && !(points.back() == points.front())) {
        out.push_back(line_cubic(points.back(), points.front()));
    }
    return out;
}

}  // namespace pathstream::host::svg
