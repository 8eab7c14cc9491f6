// What the reference planners of bench_plan work on and produce: straight line moves (the
// path flattened as a G-code sender would, within the profile's chord tolerance) and one
// trapezoidal speed profile per move. The planners themselves are grbl_style.hpp and
// klipper_style.hpp; these are bench code, written to compare pathstream with, not used by it.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "pathstream/host/geometry.hpp"
#include "pathstream/machine/machine.hpp"

namespace pathstream::bench {

/// One straight move, as a G1 line: from `start` to `end` (mm per axis) at up to `feed`.
struct LineMove {
    host::PathPoint start, end;
    host::PathPoint unit;  ///< (end - start) / length
    double length = 0;     ///< mm, > 0 (zero-length pieces are dropped when flattening)
    double feed = 0;       ///< requested speed, mm/s (the segment's, else the profile's)
    /// The machine is at rest before this move: the start of the job, a pen change, a pause or
    /// a dwell. Both peers stop there as pathstream does (grbl waits for its buffer to drain
    /// before a spindle/pen command; a pen lift is a separate move).
    bool stop_before = false;
};

/// Flattens `segments` into line moves whose chords stay within `chord_tolerance` (mm) of each
/// cubic: a segment is cut into n equal parameter steps, n from the bound on its second
/// derivative (chord error <= max|B''| h^2 / 8), so straight segments (polylines, G1, travel)
/// stay one move. Vertices lie on the curve. Cost: O(moves out).
std::vector<LineMove> flatten_to_lines(const std::vector<host::BezierSegment>& segments,
                                       const host::MachineProfile& profile);

/// The largest speed and acceleration along direction `unit` that keep every axis within its
/// own limit: min over axes of limit_i / |unit_i| (how grbl scales its per-axis settings).
double along_direction_velocity(const host::PathPoint& unit, const host::MachineProfile& profile);
double along_direction_acceleration(const host::PathPoint& unit,
                                    const host::MachineProfile& profile);

/// Which junction speeds a reference planner allows.
enum class JunctionRule {
    /// The peer's own rule only: an axis's velocity may step by any amount at a junction.
    peer,
    /// Also capped by per_tick_junction_speed2, so that no axis's velocity steps by more than
    /// one tick of its acceleration (pathstream's per-tick limit; "held" in the peer table).
    per_tick,
};

/// The largest junction speed squared (mm^2/s^2) between moves with unit directions `from` and
/// `to` at which no axis's velocity steps by more than one tick of its acceleration: a peer
/// follows the polyline exactly, so axis i's velocity jumps by v (to_i - from_i) within a tick,
/// and |v (to_i - from_i)| <= a_i / tick_hz gives v^2 <= min over axes of
/// (a_i / (tick_hz |to_i - from_i|))^2. Infinite when no axis changes. Cost: O(axes).
double per_tick_junction_speed2(const host::PathPoint& from, const host::PathPoint& to,
                                const host::MachineProfile& profile);

/// One move's planned speed profile: accelerate at `accel` from v_entry to v_cruise, cruise,
/// decelerate at `accel` to v_exit (mm/s, mm/s^2; phases may be empty).
struct TimedMove {
    double v_entry = 0, v_cruise = 0, v_exit = 0, accel = 0;
    double t_accel = 0, t_cruise = 0, t_decel = 0;  ///< s
    double d_accel = 0, d_cruise = 0, d_decel = 0;  ///< mm, summing to the move's length
    /// Seconds the move takes.
    double duration() const { return t_accel + t_cruise + t_decel; }
};

/// Builds the trapezoid of a move of `length` mm from squared speeds (v_cruise2 at least both
/// ends'; the caller ensures the ends are reachable within the length at `accel`).
TimedMove make_trapezoid(double length, double accel, double v_entry2, double v_cruise2,
                         double v_exit2);

/// A reference planner's whole result: the moves and their profiles, one each.
struct PeerPlan {
    std::vector<LineMove> moves;
    std::vector<TimedMove> timed;
    /// Sum of the moves' durations (s): motion only (pen dwells, like pathstream's motion
    /// ticks, excluded), continuous (not rounded to whole ticks).
    double motion_time() const;
};

/// The largest velocity jump of one axis at a junction of `plan` (v_exit |to_i - from_i|, the
/// step a peer takes within one tick) over one tick of that axis's acceleration, a_i / tick_hz:
/// at most 1 (plus rounding) for plans made with JunctionRule::per_tick. O(moves * axes).
double max_junction_step_fraction(const PeerPlan& plan, const host::MachineProfile& profile);

/// Empty when `plan` is self-consistent: one profile per move, finite non-negative phase times
/// and distances adding up to each move's length, speeds within each move's cruise speed and
/// continuous from move to move, at rest at the start, at every stop and at the end, positive
/// total time. Else what is wrong and where. O(moves).
std::string consistency_problem(const PeerPlan& plan);

}  // namespace pathstream::bench
