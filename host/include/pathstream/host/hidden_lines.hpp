// Visibility against the surfaces themselves: which points of a wireframe a surface hides
// from the eye, for drawing only what can be seen.
#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <vector>

#include "pathstream/host/surface.hpp"

namespace pathstream::host {

/// A surface sheet: its point at (u, v) in [0, 1]^2, continuous and smooth inside.
using SurfaceSheet = std::function<Point3(double u, double v)>;

/// The sheets of Bezier patches (one each) and of a surface of revolution (one per profile
/// piece: u along the angle, v along the piece). Throws as revolution_wireframe.
std::vector<SurfaceSheet> sheets_of(const std::vector<BezierPatch>& patches);
std::vector<SurfaceSheet> sheets_of(const RevolutionSurface& surface);

/// Answers "does a surface hide this point?" for points seen through one view. Built once
/// (a mesh of cells x cells quads per sheet, binned on the drawing); each question looks at
/// the mesh triangles over the point's place on the drawing and, for each in front of it,
/// finds the exact surface point there by Newton's method on the sheet, comparing exact
/// depths. So the answer does not depend on the mesh except where a sheet's outline passes
/// within the mesh's chord error of the point.
class Occluder {
public:
    /// Throws std::invalid_argument for `cells` outside 2..256 or no sheets; std::domain_error
    /// when a sheet's point is behind the eye. `max_questions` bounds the work of hidden().
    Occluder(std::vector<SurfaceSheet> sheets, const ViewFrame& frame, std::size_t cells = 16,
             std::size_t max_questions = 20'000'000);
    ~Occluder();
    Occluder(const Occluder&) = delete;
    Occluder& operator=(const Occluder&) = delete;

    /// True when some sheet lies between `p` (a point on or near the surfaces) and the eye,
    /// by more than 1e-7 of the model's extent. Cost: the triangles over p's bin, a Newton
    /// solve (at most 20 steps) for each in front. Throws std::length_error once asked more
    /// than max_questions times.
    bool hidden(const Point3& p) const;

    /// Questions asked and Newton solves run so far (figures, not needed for answers).
    std::size_t questions() const;
    std::size_t solves() const;

private:
    struct Mesh;
    std::unique_ptr<Mesh> mesh_;
};

/// The parts of the cubic model curve `q` (4 control points; with `weights`, a rational one)
/// that `occluder` does not hide, as parameter intervals [t0, t1] in order. The curve is
/// sampled so that neighbouring samples are at most `sample_mm` apart on the drawing, and
/// each change between seen and hidden is located by bisection to within `tolerance_mm` on
/// the drawing, on the hidden side's edge. Pieces shorter on the drawing than `tolerance_mm`
/// are dropped.
std::vector<std::array<double, 2>> visible_intervals(const std::vector<Point3>& q,
                                                     const std::vector<double>& weights,
                                                     const ViewFrame& frame,
                                                     const Occluder& occluder, double tolerance_mm,
                                                     double sample_mm = 0.25);

/// The piece of the (rational) Bezier curve `q` over [t0, t1], exactly, by de Casteljau in
/// homogeneous coordinates; `weights` (empty: polynomial) is replaced by the piece's.
std::vector<Point3> bezier_piece(const std::vector<Point3>& q, std::vector<double>& weights,
                                 double t0, double t1);

}  // namespace pathstream::host
