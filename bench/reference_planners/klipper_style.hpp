// A Klipper-style reference planner for bench_plan (bench code: pathstream does not use it).
//
// The rules, as Klipper's toolhead applies them to its move queue (restated; the whole job is
// one queue flushed at the end, which can only make it faster than Klipper's timed flushes):
//   * limits per move: cruise speed the feed, capped per axis along the move's direction as
//     grbl_style does (Klipper has one XY acceleration; giving each move the largest
//     acceleration its direction allows is the most generous reading of per-axis limits);
//   * square corner velocity V (default 5 mm/s) sets a junction deviation
//     d = V^2 (sqrt 2 - 1) / a_max (a_max the smallest axis acceleration), so that a 90 degree
//     corner of moves at a_max is crossed at V. At a junction turning by theta, with
//     R = sin(theta/2) / (1 - sin(theta/2)), the start speed of a move is capped by
//       - R d a for the acceleration a of each of the two moves (the junction deviation term),
//       - L a tan(theta/2) / 2 for each move's length L ("the approximated circle touches the
//         moves no further than mid-move": the centripetal term of short moves),
//       - both moves' cruise speeds, and what the previous move can reach from its own
//         largest start speed (v^2 + 2 a L);
//       - held (JunctionRule::per_tick; not Klipper's rule, the bench's fair form): the speed
//         at which no axis's velocity steps by more than one tick of its acceleration;
//   * smoothed lookahead: a second, slower acceleration a (1 - r) (r = minimum cruise ratio,
//     default 0.5, Klipper's replacement of max_accel_to_decel = a / 2) is run through the
//     same junction caps; wherever the smoothed speed profile peaks, the real cruise speed of
//     the moves around that peak is capped at the smoothed peak, so a run of short moves does
//     not saw between accelerating and braking;
//   * a backward pass from the end (at rest) takes each move's start speed as the smaller of
//     its cap and what it can brake from, its cruise speed as the smallest of its cruise limit,
//     the peak of the triangle between its ends and the smoothed peak, and builds the
//     trapezoid (accelerate, cruise, decelerate at the move's acceleration), ending at the
//     next move's start (where Klipper's min(end, cruise) would step the speed there, the
//     cruise is raised to that start: never slower than Klipper).
// Like grbl, the machine follows the polyline exactly, so the velocity vector steps at every
// junction crossed above zero.
#pragma once

#include "line_moves.hpp"

namespace pathstream::bench {

/// Klipper's defaults: square_corner_velocity 5 mm/s, minimum_cruise_ratio 0.5.
constexpr double kKlipperSquareCornerVelocity = 5.0;
constexpr double kKlipperMinimumCruiseRatio = 0.5;

/// Plans `moves` (flatten_to_lines) with the rules above; with JunctionRule::per_tick every
/// move's start speed is also capped by per_tick_junction_speed2, for both lookaheads, before
/// the backward pass. O(moves).
PeerPlan plan_klipper_style(std::vector<LineMove> moves, const host::MachineProfile& profile,
                            JunctionRule rule = JunctionRule::peer,
                            double square_corner_velocity = kKlipperSquareCornerVelocity,
                            double minimum_cruise_ratio = kKlipperMinimumCruiseRatio);

}  // namespace pathstream::bench
