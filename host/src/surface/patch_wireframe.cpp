// Iso-curves of Bezier patches: fixing v = v0 leaves a Bezier curve in u whose control points
// are the columns' de Casteljau points at v0 (and likewise for u), so every iso-curve is an
// exact polynomial curve of the patch's degree before it is projected.
#include <algorithm>
#include <cmath>
#include <string>

#include "pathstream/host/hidden_lines.hpp"
#include "pathstream/host/surface.hpp"
#include "project_curve.hpp"
#include "seam_set.hpp"

namespace pathstream::host {
namespace {

// de Casteljau at t of the control points q (degree q.size() - 1).
Point3 casteljau(std::vector<Point3> q, double t) {
    for (std::size_t r = q.size() - 1; r > 0; --r) {
        for (std::size_t i = 0; i < r; ++i) {
            for (int k = 0; k < 3; ++k) q[i][k] = (1 - t) * q[i][k] + t * q[i + 1][k];
        }
    }
    return q[0];
}

const Point3& at(const BezierPatch& p, int i, int j) {
    return p.points[static_cast<std::size_t>(j * (p.degree_u + 1) + i)];
}

// The curve in u at v = v0 (along_u) or the curve in v at u = u0.
std::vector<Point3> iso_curve(const BezierPatch& p, bool along_u, double fixed) {
    const int n = along_u ? p.degree_u : p.degree_v, m = along_u ? p.degree_v : p.degree_u;
    std::vector<Point3> out;
    for (int a = 0; a <= n; ++a) {
        std::vector<Point3> column;
        for (int b = 0; b <= m; ++b) column.push_back(along_u ? at(p, a, b) : at(p, b, a));
        out.push_back(casteljau(column, fixed));
    }
    return out;
}

// The largest model coordinate: equality of seams is judged relative to it.
double extent(const std::vector<BezierPatch>& patches) {
    double e = 1e-300;
    for (const BezierPatch& p : patches) {
        for (const Point3& q : p.points) {
            for (const double c : q) e = std::max(e, std::abs(c));
        }
    }
    return e;
}

}  // namespace

Point3 patch_point(const BezierPatch& patch, double u, double v) {
    // The hidden-line search asks this millions of times: de Casteljau on fixed arrays, the
    // columns at v first, then the row they make at u.
    std::array<Point3, 4> row{};
    for (int i = 0; i <= patch.degree_u; ++i) {
        std::array<Point3, 4> column{};
        for (int j = 0; j <= patch.degree_v; ++j)
            column[static_cast<std::size_t>(j)] = at(patch, i, j);
        for (int r = patch.degree_v; r > 0; --r) {
            for (int k = 0; k < r; ++k) {
                for (std::size_t c = 0; c < 3; ++c) {
                    column[static_cast<std::size_t>(k)][c] =
                        (1 - v) * column[static_cast<std::size_t>(k)][c] +
                        v * column[static_cast<std::size_t>(k + 1)][c];
                }
            }
        }
        row[static_cast<std::size_t>(i)] = column[0];
    }
    for (int r = patch.degree_u; r > 0; --r) {
        for (int k = 0; k < r; ++k) {
            for (std::size_t c = 0; c < 3; ++c) {
                row[static_cast<std::size_t>(k)][c] =
                    (1 - u) * row[static_cast<std::size_t>(k)][c] +
                    u * row[static_cast<std::size_t>(k + 1)][c];
            }
        }
    }
    return row[0];
}

std::vector<SurfaceSheet> sheets_of(const std::vector<BezierPatch>& patches) {
    std::vector<SurfaceSheet> out;
    for (const BezierPatch& p : patches) {
        out.push_back([p](double u, double v) { return patch_point(p, u, v); });
    }
    return out;
}

std::vector<Subpath> patch_wireframe(const std::vector<BezierPatch>& patches,
                                     const IsoCounts& counts, const ViewFrame& frame,
                                     double tolerance_mm, WireframeFigures* figures,
                                     const Occluder* occluder, std::size_t* fit_cells_left) {
    WireframeFigures f;
    const double resolution = 1e-9 * extent(patches);
    surface::SeamSet drawn(resolution);
    std::vector<Subpath> out;
    for (const BezierPatch& patch : patches) {
        for (const bool along_u : {true, false}) {
            // Curves along u sit at fixed v: the v count says how many.
            const std::size_t n = along_u ? counts.v : counts.u;
            for (std::size_t k = 0; n > 0 && k <= n; ++k) {
                const double fixed = static_cast<double>(k) / static_cast<double>(n);
                const std::vector<Point3> q = iso_curve(patch, along_u, fixed);
                if (surface::is_point(q, resolution)) {
                    ++f.degenerate;
                    continue;
                }
                if (drawn.seen_or_add(surface::raise_to_cubic(q))) {
                    ++f.seams_merged;
                    continue;
                }
                for (const auto& chain :
                     surface::draw_curve(q, {}, frame, tolerance_mm, occluder, f, fit_cells_left)) {
                    Subpath sp;
                    sp.basis = PathBasis::kBezier;
                    sp.location = patch.location;
                    for (const PathPoint& point : chain) sp.points.push_back(point);
                    out.push_back(std::move(sp));
                }
            }
        }
    }
    if (figures) *figures = f;
    return out;
}

}  // namespace pathstream::host
