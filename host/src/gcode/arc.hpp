// Circular arcs (and the slight spirals G-code allows when the end is not quite on the
// circle) as chains of cubic Bezier pieces.
#pragma once

#include <vector>

#include "vec2.hpp"

namespace pathstream::host::gcode {

/// An arc about `center` from `start` to `end`, turning `sweep` radians (> 0 counterclockwise,
/// < 0 clockwise; a full circle is ±2π, several turns more). When |end - center| differs from
/// |start - center| the curve is the spiral whose radius changes linearly with the angle
/// (what LinuxCNC moves along). Both radii must be positive.
struct Arc {
    Vec2 start;
    Vec2 end;
    Vec2 center;
    double sweep = 0;
    /// A helix: how far the axis normal to the plane moves over the sweep, linearly in the
    /// angle. The pieces carry only the plane; the tolerance covers the normal axis too when
    /// it is made linear in each piece's parameter (Interpreter::lift).
    double rise = 0;
};

/// Pieces approximating `arc`: each turns at most 90 degrees, the first starts exactly at
/// arc.start, the last ends exactly at arc.end, consecutive pieces share end points, and every
/// piece stays within `tolerance_mm` (> 0) of the arc, checked by sampling each piece.
std::vector<Cubic> arc_to_cubics(const Arc& arc, double tolerance_mm);

}  // namespace pathstream::host::gcode
