// Drawing order of a path's subpaths: fewer and shorter pen-up moves (docs/path-order.md).
#pragma once

#include <cstddef>

#include "pathstream/host/path.hpp"

namespace pathstream::host {

/// Knobs of order_path. The defaults are what the CLI uses.
struct OrderOptions {
    /// Where the pen is before the first subpath (mm per axis); empty: the origin.
    PathPoint start;
    /// Open polyline or Bezier subpaths whose ends are this close (mm) are joined into one, and
    /// an open polyline or Bezier chain whose ends are this close may start at any vertex.
    /// Negative: never join.
    double merge_tolerance = 0.01;
    /// Local improvement (2-opt with reversal, then Or-opt) after the greedy order.
    bool improve = true;
    /// Most candidate moves the improvement evaluates in all (a work limit, not a time limit:
    /// the same input always gets the same result, and hostile input costs bounded time).
    std::size_t work_limit = 60'000'000;
};

/// Figures of one ordering run.
struct OrderReport {
    double travel_before = 0;  ///< mm of pen-up travel in document order, from the start point
    double travel_after = 0;   ///< mm of pen-up travel in the new order, from the start point
    std::size_t subpaths_before = 0, subpaths_after = 0;
    std::size_t merged = 0;  ///< subpaths joined onto another (subpaths_before - subpaths_after)
    std::size_t work = 0;    ///< candidate moves evaluated (<= work_limit plus one pass)
};

/// Where the curve of `subpath` starts and ends (mm); a closed one ends where it starts.
/// Open B-spline and Catmull-Rom subpaths are clamped, so these are their end points; a
/// closed B-spline starts at (P[m-1] + 4 P0 + P1) / 6.
PathPoint curve_start(const Subpath& subpath);
PathPoint curve_end(const Subpath& subpath);

/// Straight-line pen-up distance (mm) of drawing the subpaths in order from `start` (empty:
/// the origin): start to the first subpath's start, then each end to the next start.
double pen_up_travel(const Path& path, const PathPoint& start = {});

/// The same curve drawn the other way. Exact for every basis: open lists are reversed; closed
/// ones keep their first point (where the curve starts) and reverse the rest.
Subpath reversed_subpath(const Subpath& subpath);

/// A closed subpath starting at another point of the same curve: the point list rotated left
/// by `shift` (a multiple of 3 for a Bezier chain, whose starts are its on-curve points).
/// Throws std::invalid_argument for an open subpath or a shift not allowed for the basis.
Subpath rotated_subpath(const Subpath& subpath, std::size_t shift);

/// Joins open polyline and Bezier subpaths of the same feed whose ends lie within `tolerance`
/// mm (reversing one where that makes them meet); the joint keeps the first one's point. A
/// polyline joined to a Bezier chain becomes a Bezier chain first (straight pieces, control
/// points at the thirds). B-spline and Catmull-Rom subpaths are never joined: their curve near an
/// end depends on the clamping, so concatenating the point lists would change the curve at the
/// joint. Deterministic: the first subpath in document order absorbs the lowest-index match.
Path merge_touching(const Path& path, double tolerance, std::size_t* merged = nullptr);

/// The path with its subpaths reordered, reversed, rotated (closed ones) and joined to cut
/// pen-up travel: touching ends are joined, then a nearest-neighbour order from the start
/// point, then 2-opt and Or-opt within the work limit. The result's travel is never more than
/// the document order's. Same input and options, same output.
Path order_path(const Path& path, const OrderOptions& options = {}, OrderReport* report = nullptr);

}  // namespace pathstream::host
