// Surfaces drawn as wireframes of iso-parameter curves, seen through a view: tensor-product
// Bezier patches and surfaces of revolution, projected onto the drawing plane.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "pathstream/host/geometry.hpp"
#include "pathstream/host/path.hpp"

namespace pathstream::host {

using Point3 = std::array<double, 3>;

/// How the drawing sees the model (z up). The eye looks at the origin from the direction
/// (azimuth about z from +x, elevation above the xy plane); roll turns the drawing about the
/// line of sight. Drawing x runs to the viewer's right and drawing y down the page, as the
/// plotter's axes and SVG's do.
struct SurfaceView {
    enum class Projection { kOrthographic, kPerspective };
    Projection projection = Projection::kOrthographic;
    double azimuth_deg = -30;
    double elevation_deg = 25;
    double roll_deg = 0;
    double scale = 1;  ///< drawing mm per model unit (at the origin's depth under perspective)
    /// kPerspective: the eye's distance from the origin, model units; every point drawn must
    /// lie nearer the origin than the eye along the line of sight.
    double eye_distance = 0;
};

/// The view as an orthonormal frame: right, up and toward the eye, in model coordinates.
struct ViewFrame {
    Point3 right{}, up{}, toward_eye{};
    SurfaceView view;
};

/// The frame of `view`. O(1). Throws std::invalid_argument for non-finite angles, a scale
/// that is not positive, or a perspective eye distance that is not positive.
ViewFrame view_frame(const SurfaceView& view);

/// Where `p` lands on the drawing (mm) and its depth (model units toward the eye). Throws
/// std::domain_error under perspective when `p` is not in front of the eye.
std::array<double, 2> project_point(const ViewFrame& frame, const Point3& p);
double view_depth(const ViewFrame& frame, const Point3& p);

/// A tensor-product Bezier patch of degree 1 to 3 in each direction. Control point P(i, j)
/// (i along u, j along v) is points[j * (degree_u + 1) + i].
struct BezierPatch {
    int degree_u = 3;
    int degree_v = 3;
    std::vector<Point3> points;
    SourceLocation location;  ///< where the patch is given, for errors and subpaths
};

/// A profile turned about an axis: the profile's first coordinate is the distance from the
/// axis, its second the height along it.
struct RevolutionSurface {
    std::vector<BezierSegment> profile;  ///< 2-D cubic pieces, in model units
    Point3 axis_point{0, 0, 0};
    Point3 axis_direction{0, 0, 1};  ///< not zero; normalised when used
    double angle_deg = 360;          ///< (0, 360]: from the axis's frame's first direction
    SourceLocation location;
};

/// How many iso-curves: per patch, `u` lines of constant u at u = k/u (k = 0..u) and `v`
/// lines of constant v (0: none of that family). For a revolution surface, `u` meridians
/// over the angle and `v` parallels per profile piece.
struct IsoCounts {
    std::size_t u = 6;
    std::size_t v = 6;
};

class Occluder;

/// The wireframe's figures.
struct WireframeFigures {
    std::size_t curves = 0;        ///< iso-curves drawn
    std::size_t exact_curves = 0;  ///< of them, projected exactly (no fitting)
    std::size_t seams_merged = 0;  ///< boundary curves a neighbouring patch had drawn already
    std::size_t degenerate = 0;    ///< iso-curves that are a single point, not drawn
    std::size_t hidden = 0;        ///< iso-curves hidden whole by the surfaces
    std::size_t split = 0;         ///< iso-curves drawn in parts, the rest hidden
};

/// The iso-curves of `patches` seen through `frame`, as open Bezier subpaths (2 axes, mm),
/// in patch order. Under an orthographic view each curve is the exact projection of the
/// surface's iso-curve (degree raised to 3); under perspective it is the projected rational
/// curve fitted within `tolerance_mm`. A boundary curve equal to one drawn already (either
/// direction, within 1e-9 of the drawing's extent) is drawn once. Fitted curves carry a proven
/// bound and evaluate at most `*fit_cells_left` interval cells in all (nullptr: the fitter's
/// limit per curve), which they lower. With `occluder`, only the
/// parts it does not hide are drawn, each an exact piece of the curve (visible_intervals).
/// Cost O(patches x counts), times the samples' questions with an occluder. Throws
/// std::domain_error when a point is behind the eye.
std::vector<Subpath> patch_wireframe(const std::vector<BezierPatch>& patches,
                                     const IsoCounts& counts, const ViewFrame& frame,
                                     double tolerance_mm, WireframeFigures* figures = nullptr,
                                     const Occluder* occluder = nullptr,
                                     std::size_t* fit_cells_left = nullptr);

/// The meridians and parallels of `surface` through `frame`: meridians are exact under an
/// orthographic view, parallels (circles) are fitted within `tolerance_mm` with a proven
/// bound. Throws as
/// patch_wireframe, and std::invalid_argument for a zero axis or an angle out of range.
std::vector<Subpath> revolution_wireframe(const RevolutionSurface& surface, const IsoCounts& counts,
                                          const ViewFrame& frame, double tolerance_mm,
                                          WireframeFigures* figures = nullptr,
                                          const Occluder* occluder = nullptr,
                                          std::size_t* fit_cells_left = nullptr);

/// One surface of a drawing: Bezier patches, or a surface of revolution, and its iso lines.
struct SurfaceInput {
    std::vector<BezierPatch> patches;
    std::optional<RevolutionSurface> revolution;  ///< set: this, not patches
    IsoCounts counts;
};

/// What the surfaces of one drawing may cost (the readers' limits; smaller ones suit a fuzzer
/// or a service reading untrusted files).
struct SurfaceBudget {
    std::size_t curves = 200'000;                    ///< iso-curves, estimated before drawing
    std::size_t points = 5'000'000;                  ///< control points of the wireframes
    std::size_t hidden_line_questions = 20'000'000;  ///< points judged for hidden lines
    std::size_t fit_cells = 20'000'000;  ///< interval cells the fitted curves' proofs evaluate
};

/// Why draw_surfaces failed, and on which surface (an index into its input).
class SurfaceError : public std::runtime_error {
public:
    SurfaceError(std::size_t surface_index, const std::string& message)
        : std::runtime_error(message), surface(surface_index) {}
    std::size_t surface;
};

/// An estimate of the iso-curves `surface` draws, for the budget before any is drawn.
double estimated_curves(const SurfaceInput& surface);

/// The wireframes of `surfaces` through `frame`, in order, each with the parts any of them
/// hides removed when `hidden_lines`; `figures` summed over all. Throws SurfaceError for a
/// point behind the eye, an axis or angle out of range, and past `budget`.
std::vector<Subpath> draw_surfaces(const std::vector<SurfaceInput>& surfaces,
                                   const ViewFrame& frame, bool hidden_lines, double tolerance_mm,
                                   const SurfaceBudget& budget, WireframeFigures& figures);

/// The point of `patch` at (u, v) in [0, 1]^2 (de Casteljau in u, then in v). O(degree^2).
Point3 patch_point(const BezierPatch& patch, double u, double v);

}  // namespace pathstream::host
