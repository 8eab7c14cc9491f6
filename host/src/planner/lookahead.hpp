// The lookahead (lookahead.cpp): per-node speed caps, the TOPP-RA backward pass that bounds
// the speed from which the rest of a piece can still stop, and the continuous forward pass
// that gives the time-optimal reference.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "grid.hpp"
#include "limits.hpp"
#include "pathstream/host/planner.hpp"
#include "pathstream/machine/machine.hpp"

namespace pathstream::host::planner_detail {

/// Per-node squared-speed caps: per-axis velocity, feed, chord tolerance, corner rule, with
/// the velocity and feed margins of `options`.
std::vector<double> speed_caps(const PathGrid& g, const Limits& limits,
                               const MachineProfile& profile, const PlanOptions& options);

/// With jerk limits: lowers `caps` (squared speeds) for the curvature's change (kappa' s^3 and
/// curvature steps at joints), for tangent jumps crossed inside spans, and erodes every cap over
/// the distance the jerk stage's box filter of `filter_ticks` averages (docs/planner.md §12).
void jerk_caps(const PathGrid& g, const Limits& limits, const MachineProfile& profile,
               std::uint32_t filter_ticks, std::vector<double>& caps);

/// A span that crosses a corner at speed v turns on axis i at up to 4 v |J_i| / span_time:
/// caps the lookahead's acceleration factor within two spans' travel of every crossed corner
/// to 1 minus that share (at most half), so that the deceleration into it leaves room for it.
/// `caps` are the squared-speed caps (the corner speed is the corner node's cap); span_time is
/// the node's regular span (the profile's, longer at a feed far below an LSB per span).
void reserve_for_corners(const PathGrid& g, const Limits& limits, const std::vector<double>& caps,
                         const MachineProfile& profile, std::vector<double>& factor);

/// TOPP-RA backward pass over one piece: beta[k] (k = first..last, indexed by node) is the
/// largest squared speed at node k from which the rest of the piece can still be run to a stop
/// at its end with accelerations limits * accel_factor[k], speed changes costing
/// 1 / tangential_margin times their acceleration. beta[last] = 0.
/// With span_time > 0, dips of the speed caps (dip[k]: squared speed, scratch of the same size)
/// are also approached no faster than spans of that duration can slow down from a knot
/// (x = s^2 falling by at most 1.9 s / span_time per mm), except dips within `end_zone` mm of
/// the piece's end: the motion stops there anyway, and the final span is checked against them.
/// Incremental use: only nodes below `top` are recomputed (beta[top] must be valid), and the
/// pass stops at the first node below `unchanged_below` whose value does not change. Returns
/// the lowest node recomputed.
std::size_t backward_pass(const PathGrid& g, const Piece& piece, const Limits& limits,
                          const std::vector<double>& accel_factor, double tangential_margin,
                          const std::vector<double>& caps, double span_time, double end_zone,
                          std::vector<double>& dip, std::vector<double>& beta,
                          std::size_t top = static_cast<std::size_t>(-1),
                          std::size_t unchanged_below = 0);

/// TOPP-RA forward pass of one piece on its own grid (continuous time, piecewise constant path
/// acceleration between nodes): the optimum's motion time in seconds.
double topp_piece_time(const PathGrid& g, const Piece& piece, const Limits& limits,
                       const std::vector<double>& accel_factor, const std::vector<double>& beta);

}  // namespace pathstream::host::planner_detail
