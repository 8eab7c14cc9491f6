// Surfaces of revolution: a meridian is the profile placed in a plane through the axis (an
// affine image of it, so exact), a parallel is a circle, drawn as rational quadratic arcs of
// at most 90 degrees, which only a fit can turn into cubics.
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "pathstream/host/hidden_lines.hpp"
#include "pathstream/host/surface.hpp"
#include "project_curve.hpp"
#include "seam_set.hpp"

namespace pathstream::host {
namespace {

struct AxisFrame {
    Point3 origin{}, along{}, e1{}, e2{};
};

Point3 cross(const Point3& a, const Point3& b) {
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

AxisFrame axis_frame(const RevolutionSurface& s) {
    const Point3& d = s.axis_direction;
    const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (!(len > 0) || !std::isfinite(len)) {
        throw std::invalid_argument("the axis direction must be a finite, non-zero vector");
    }
    AxisFrame f;
    f.origin = s.axis_point;
    f.along = {d[0] / len, d[1] / len, d[2] / len};
    // The angle starts from the world axis least aligned with the axis, made perpendicular.
    int least = 0;
    for (int k = 1; k < 3; ++k) {
        if (std::abs(f.along[k]) < std::abs(f.along[least])) least = k;
    }
    Point3 w{0, 0, 0};
    w[least] = 1;
    const Point3 e2 = cross(f.along, w);
    const double l2 = std::sqrt(e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2]);
    f.e2 = {e2[0] / l2, e2[1] / l2, e2[2] / l2};
    f.e1 = cross(f.e2, f.along);
    return f;
}

// The model point at profile coordinates (radius r, height h) turned by `theta` radians.
Point3 place(const AxisFrame& f, double r, double h, double theta) {
    const double c = r * std::cos(theta), s = r * std::sin(theta);
    Point3 p;
    for (int k = 0; k < 3; ++k) p[k] = f.origin[k] + h * f.along[k] + c * f.e1[k] + s * f.e2[k];
    return p;
}

// Chains drawn one after another become one subpath while each starts where the last ended.
void add_chains(std::vector<Subpath>& out, const std::vector<std::vector<PathPoint>>& chains,
                const SourceLocation& at) {
    bool joined = false;
    for (const std::vector<PathPoint>& chain : chains) {
        if (joined && out.back().points.back() == chain.front()) {
            for (std::size_t i = 1; i < chain.size(); ++i) out.back().points.push_back(chain[i]);
            continue;
        }
        Subpath sp;
        sp.basis = PathBasis::kBezier;
        sp.location = at;
        for (const PathPoint& p : chain) sp.points.push_back(p);
        out.push_back(std::move(sp));
        joined = true;
    }
}

}  // namespace

std::vector<Subpath> revolution_wireframe(const RevolutionSurface& surface, const IsoCounts& counts,
                                          const ViewFrame& frame, double tolerance_mm,
                                          WireframeFigures* figures, const Occluder* occluder,
                                          std::size_t* fit_cells_left) {
    if (!(surface.angle_deg > 0 && surface.angle_deg <= 360)) {
        throw std::invalid_argument("the angle of revolution must be in (0, 360] degrees");
    }
    const AxisFrame axis = axis_frame(surface);
    const double angle = surface.angle_deg * std::numbers::pi / 180.0;
    double extent = 1e-300;
    for (const BezierSegment& s : surface.profile) {
        for (const PathPoint& p : s.p) extent = std::max({extent, std::abs(p[0]), std::abs(p[1])});
    }
    for (const double c : axis.origin) extent = std::max(extent, std::abs(c));
    const double resolution = 1e-9 * extent;
    surface::SeamSet drawn(resolution);
    WireframeFigures f;
    std::vector<Subpath> out;
    for (std::size_t k = 0; counts.u > 0 && k <= counts.u; ++k) {  // meridians
        const double theta = angle * static_cast<double>(k) / static_cast<double>(counts.u);
        std::vector<std::vector<PathPoint>> chains;
        for (const BezierSegment& s : surface.profile) {
            std::vector<Point3> q;
            for (const PathPoint& p : s.p) q.push_back(place(axis, p[0], p[1], theta));
            if (surface::is_point(q, resolution)) continue;
            if (drawn.seen_or_add(q)) {
                ++f.seams_merged;
                continue;
            }
            for (auto& chain :
                 surface::draw_curve(q, {}, frame, tolerance_mm, occluder, f, fit_cells_left)) {
                chains.push_back(std::move(chain));
            }
        }
        add_chains(out, chains, surface.location);
    }
    const std::size_t arcs = static_cast<std::size_t>(std::ceil(angle / (std::numbers::pi / 2)));
    const double step = angle / static_cast<double>(arcs);
    for (const BezierSegment& s : surface.profile) {  // parallels
        for (std::size_t k = 0; counts.v > 0 && k <= counts.v; ++k) {
            const double t = static_cast<double>(k) / static_cast<double>(counts.v);
            const PathPoint rh = bezier_point(s, t);
            if (std::abs(rh[0]) <= resolution) {
                ++f.degenerate;
                continue;
            }
            // One key per circle: its start, middle and end, so that the parallel at a joint of
            // two profile pieces is drawn once.
            if (drawn.seen_or_add({place(axis, rh[0], rh[1], 0),
                                   place(axis, rh[0], rh[1], angle / 2),
                                   place(axis, rh[0], rh[1], angle)})) {
                ++f.seams_merged;
                continue;
            }
            std::vector<std::vector<PathPoint>> chains;
            for (std::size_t a = 0; a < arcs; ++a) {
                const double t0 = step * static_cast<double>(a), half = step / 2;
                const std::vector<Point3> q{place(axis, rh[0], rh[1], t0),
                                            place(axis, rh[0] / std::cos(half), rh[1], t0 + half),
                                            place(axis, rh[0], rh[1], t0 + step)};
                for (auto& chain : surface::draw_curve(q, {1.0, std::cos(half), 1.0}, frame,
                                                       tolerance_mm, occluder, f, fit_cells_left)) {
                    chains.push_back(std::move(chain));
                }
            }
            add_chains(out, chains, surface.location);
        }
    }
    if (figures) *figures = f;
    return out;
}

std::vector<SurfaceSheet> sheets_of(const RevolutionSurface& surface) {
    if (!(surface.angle_deg > 0 && surface.angle_deg <= 360)) {
        throw std::invalid_argument("the angle of revolution must be in (0, 360] degrees");
    }
    const AxisFrame axis = axis_frame(surface);
    const double angle = surface.angle_deg * std::numbers::pi / 180.0;
    std::vector<SurfaceSheet> out;
    for (const BezierSegment& s : surface.profile) {
        out.push_back([axis, angle, s](double u, double v) {
            const PathPoint rh = bezier_point(s, v);
            return place(axis, rh[0], rh[1], angle * u);
        });
    }
    return out;
}

}  // namespace pathstream::host
