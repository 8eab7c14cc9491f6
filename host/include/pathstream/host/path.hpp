// A geometric path as the user describes it, before timing: subpaths of control points in
// the path's units (millimetres after loading).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "pathstream/host/point_list.hpp"
#include "pathstream/machine/source_location.hpp"

namespace pathstream::host {

/// How a subpath's points define the curve.
enum class PathBasis {
    kBSpline,     ///< uniform cubic B-spline; open ends clamped with phantom points 2P0 - P1
    kCatmullRom,  ///< uniform Catmull-Rom through every point
    kBezier,      ///< cubic Bezier chain: P0 C C P1 C C P2 ... (3k + 1 points open, 3k closed)
    kPolyline,    ///< straight segments between points
};

/// What the planner may do at the vertices inside a subpath (G-code's path control modes).
enum class CornerMode {
    kBlend,      ///< round vertices within Subpath::blend_tolerance (G64, the default)
    kExactPath,  ///< go through every vertex exactly, slowing as the turn needs (G61)
    kExactStop,  ///< also come to rest at the joints in Subpath::stops (G61.1: each block's end)
};

/// A connected piece of the path, drawn pen-down (or, when `travel`, moved along pen-up).
struct Subpath {
    PathBasis basis = PathBasis::kBSpline;
    bool closed = false;
    PointList points;         ///< flat: every point has Path::axes coordinates
    double feed = 0;          ///< requested speed along it, mm/s; 0: the machine profile's feed
    SourceLocation location;  ///< where the subpath starts in the file
    std::size_t layer = 0;    ///< index into Path::layers (0 when the file has no layers)
    /// The machine pauses before drawing this subpath: it lifts the pen, comes to rest where
    /// the previous subpath ended and holds until the operator resumes (a pen change between
    /// layers, G-code M0/M1). Path order never moves a subpath across a pause.
    bool pause_before = false;
    /// Seconds the machine rests at this subpath's start before drawing it (G-code G4), with
    /// the pen down (after the pen-down delay) or up (before the pen goes down).
    double dwell_before = 0;
    bool dwell_pen_down = false;
    CornerMode corner_mode = CornerMode::kBlend;
    /// kBlend: a rounded vertex stays within this many mm of it (G64 P), on top of the planner's
    /// own bound (PlanOptions::corner_blend of the chord tolerance), which it can only tighten;
    /// 0: the planner's bound alone.
    double blend_tolerance = 0;
    /// kExactStop: the joints where the motion rests, ascending; joint k (1 <= k < segments) is
    /// where the subpath's curve segment k starts (a polyline's point k, a Bezier chain's
    /// point 3k). Other bases and modes: empty.
    std::vector<std::uint32_t> stops{};
    /// G-code: the program line of each curve segment (chain_segments of them), so that an
    /// error names the move, not the subpath's first line. Empty from the other readers, and
    /// after an order step that rotates or joins the subpath (reversing keeps them).
    std::vector<std::uint32_t> segment_lines{};
    /// A pen-up move whose route the file gives (G-code rapids on a machine: G0 waypoints, a
    /// canned cycle's retracts): planned along its points with the pen up, at `feed` (0: the
    /// profile's travel_feed); never reordered, reversed or joined. False: drawn pen-down.
    bool travel = false;
    /// Why the machine pauses before this subpath when the file says (G-code: "tool change to
    /// T2 (3 mm drill), line 6", "program stop (M0), line 9"); empty: a pen change.
    std::string pause_note{};
    /// The machine functions in force while the machine moves along it, from its start
    /// (kOutputMachineMask bits: G-code M3/M4/M5, M7/M8/M9 on a machine); 0 from the other
    /// readers. The planner changes them where the motion rests before the subpath, with a
    /// still span of the profile's spindle spin_up when that turns the spindle on or reverses it.
    std::uint8_t outputs = 0;
    /// With pause_before: those in force while the machine holds at the pause (a program may
    /// stop the spindle before it, M5 M0 or a tool change, or start it after, M0 then M3).
    std::uint8_t pause_outputs = 0;
};

/// Curve segments of a polyline or Bezier chain: the joints Subpath::stops counts lie between
/// them. O(1).
inline std::size_t chain_segments(const Subpath& s) {
    const std::size_t m = s.points.size();
    if (s.basis == PathBasis::kBezier) return s.closed ? m / 3 : (m > 0 ? (m - 1) / 3 : 0);
    return s.closed ? m : (m > 0 ? m - 1 : 0);
}

/// A named group of subpaths plotted with one pen (an Inkscape layer, a stroke colour).
struct PathLayer {
    std::string name;         ///< the layer's label, or the colour ("#ff0000"), or "1", "2"...
    SourceLocation location;  ///< where the layer starts in the file (line 0: no element)
    double feed = 0;          ///< mm/s for its subpaths that set none; 0: the profile's
    /// The pen it needs: its subpaths' stroke colour ("#rrggbb"), "" when none of them has
    /// one (any pen), "mixed" when they have several.
    std::string pen;
};

/// A whole path. Every point of every subpath has `axes` coordinates.
struct Path {
    std::size_t axes = 2;
    std::vector<Subpath> subpaths;
    std::vector<PathLayer> layers;  ///< empty: one unnamed layer; else every subpath's layer
    std::string units = "mm";       ///< the file's own unit, for output in it ("mm" or "in")
    double mm_per_unit = 1.0;       ///< coordinates above are already in mm; this converts back
};

/// A path with everything of `path` (axes, layers, units) but its subpaths: what the
/// reordering steps start from, without copying every point first. O(layers).
Path without_subpaths(const Path& path);

/// Name used in files and messages ("bspline", "catmull-rom", "bezier", "polyline").
const char* basis_name(PathBasis basis);

/// Empty when the subpath has a usable number of points for its basis (bezier: 3k + 1 open,
/// 3k closed, k >= 1; others: at least 2 open, 3 closed); else the message every reader uses,
/// e.g. "open bezier needs 3k + 1 points (k >= 1), got 3".
std::string point_count_problem(const Subpath& subpath);

}  // namespace pathstream::host
