// A grbl-style reference planner for bench_plan (bench code: pathstream does not use it).
//
// The rules, as grbl's planner applies them to a buffer of G1 lines (restated, with the whole
// job as the buffer, which can only make it faster than grbl's 16-36 block buffer):
//   * each move's nominal speed is its feed, capped so that no axis exceeds its velocity limit
//     along the move's direction (min over axes of v_i / |u_i|); its acceleration likewise
//     (min over axes of a_i / |u_i|);
//   * a junction between two moves with unit directions u1, u2 turning by angle theta may be
//     crossed at v_j^2 = a_j * d * sin(theta/2) / (1 - sin(theta/2)): the speed at which a
//     circle tangent to both moves, whose closest point is d (the junction deviation) from
//     the vertex, is followed with centripetal acceleration a_j; a_j is the acceleration limit
//     along the direction u2 - u1. A reversal gets 0, a straight continuation no limit;
//     v_j is capped by both moves' nominal speeds;
//   * held (JunctionRule::per_tick; not grbl's rule, the bench's fair form): v_j is also capped
//     so that no axis's velocity steps by more than one tick of its acceleration;
//   * a backward pass from the end (at rest) lowers each entry speed to what the move can
//     brake from within its length; a forward pass from the start (at rest) lowers it to what
//     the previous move can reach;
//   * each move then runs a trapezoid: accelerate at its acceleration from its entry speed,
//     cruise at its nominal speed (or peak lower when the move is short), decelerate to the
//     next move's entry speed.
// The machine follows the polyline exactly, so at every junction crossed above zero the
// velocity vector steps instantly: bench_plan samples these profiles at the device tick and
// reports that step.
#pragma once

#include "line_moves.hpp"

namespace pathstream::bench {

/// grbl's default junction deviation, mm ($11 = 0.010).
constexpr double kGrblJunctionDeviation = 0.01;

/// The junction speed squared (mm^2/s^2) between moves with unit directions `from` and `to`,
/// before the nominal-speed caps. Cost: O(axes).
double grbl_junction_speed2(const host::PathPoint& from, const host::PathPoint& to,
                            const host::MachineProfile& profile, double junction_deviation);

/// Plans `moves` (flatten_to_lines) with the rules above; with JunctionRule::per_tick every
/// junction speed is also capped by per_tick_junction_speed2 before the passes. O(moves).
PeerPlan plan_grbl_style(std::vector<LineMove> moves, const host::MachineProfile& profile,
                         JunctionRule rule = JunctionRule::peer,
                         double junction_deviation = kGrblJunctionDeviation);

}  // namespace pathstream::bench
