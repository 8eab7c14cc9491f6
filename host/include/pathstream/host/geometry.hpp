// The geometric path as one list of cubic Bezier segments in millimetres: the form the
// planner works on, whatever the input format was.
#pragma once

#include <array>
#include <cstddef>
#include <functional>
#include <vector>

#include "pathstream/host/path.hpp"

namespace pathstream::host {

/// One cubic Bezier piece, control points in mm (each PathPoint has Path::axes coordinates).
struct BezierSegment {
    std::array<PathPoint, 4> p;
    bool pen_down = true;       ///< false: pen-up travel between subpaths
    std::size_t subpath = 0;    ///< index into Path::subpaths (travel: the subpath it leads to)
    std::uint32_t segment = 0;  ///< the subpath's curve segment it is (0 for travel)
    double feed = 0;            ///< requested speed, mm/s (Subpath::feed); 0: the machine profile's
                                ///< feed (travel_feed for pen-up travel)
    /// Set on a subpath's first drawing segment only (Subpath's fields of the same names): a
    /// programmed pause, and a rest in seconds with the pen down or up, before it draws.
    bool pause_before = false;
    double dwell_before = 0;
    bool dwell_pen_down = false;
    /// Subpath::outputs (every segment of the subpath, and the travel leading to it) and, on
    /// the first drawing segment, Subpath::pause_outputs.
    std::uint8_t outputs = 0;
    std::uint8_t pause_outputs = 0;
    /// The vertex at this segment's start, inside its subpath: < 0 may be rounded within the
    /// planner's own bound, > 0 within the smaller of that and this many mm (G64 P), 0 not at
    /// all (G61, G61.1). From Subpath::corner_mode and blend_tolerance.
    double blend_tolerance = -1;
    /// The motion comes to rest at this segment's start (a joint in Subpath::stops: G61.1).
    bool stop_before = false;
};

/// Converts every subpath to Bezier segments (B-spline and Catmull-Rom spans exactly, with the
/// same clamped open ends as the core spans; polylines as straight segments) and inserts a
/// straight pen-up travel segment between consecutive subpaths. Consecutive segments share
/// end points exactly.
std::vector<BezierSegment> to_bezier_segments(const Path& path);

/// The segments to_bezier_segments returns, in the same order and equal, handed to `visit` one
/// at a time instead of stored: memory O(one subpath's B-spline windows), not O(segments).
/// For readers of the whole path that keep nothing per segment (check's figures). Throws as
/// to_bezier_segments.
void for_each_bezier_segment(const Path& path,
                             const std::function<void(const BezierSegment&)>& visit);

/// Puts a straight pen-up move from `from` (mm per axis: where the machine rests, e.g. after
/// homing) to the first segment's start in front of `segments` (control points at thirds,
/// subpath 0). Nothing when `from` is that point already or `segments` is empty. Throws
/// std::invalid_argument when `from` has another axis count.
void prepend_lead_in(std::vector<BezierSegment>& segments, const PathPoint& from);

/// Point of a segment at parameter u in [0, 1] (de Casteljau), and its first and second
/// derivatives with respect to u.
PathPoint bezier_point(const BezierSegment& s, double u);

/// The parameters in [0, 1] where axis `axis` of `s` can be extreme: 0, 1 and the roots of its
/// derivative inside (0, 1). Evaluating there gives the segment's exact extent on that axis.
std::vector<double> extreme_parameters(const BezierSegment& s, std::size_t axis);
PathPoint bezier_d1(const BezierSegment& s, double u);
PathPoint bezier_d2(const BezierSegment& s, double u);

}  // namespace pathstream::host
