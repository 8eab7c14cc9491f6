// The pieces cutter_comp.cpp builds the tool path from: plane vector helpers, one programmed
// move offset by the tool radius, where two tool moves meet, and cutting a tool move back to
// a point without letting it run backwards.
#pragma once

#include <cmath>
#include <cstddef>
#include <vector>

#include "cutter_comp.hpp"

namespace pathstream::host::gcode::cutter {

inline double dot(Vec2 a, Vec2 b) {
    return a.x * b.x + a.y * b.y;
}
/// The z component of a × b: > 0 when b turns counterclockwise from a.
inline double cross(Vec2 a, Vec2 b) {
    return a.x * b.y - a.y * b.x;
}
inline double norm(Vec2 a) {
    return std::hypot(a.x, a.y);
}
/// `a` turned 90 degrees counterclockwise.
inline Vec2 left(Vec2 a) {
    return {-a.y, a.x};
}
/// `a` scaled to length 1; (0, 0) stays (0, 0).
inline Vec2 unit(Vec2 a) {
    const double n = norm(a);
    return n > 0 ? Vec2{a.x / n, a.y / n} : Vec2{};
}

/// Distances below this (mm) are rounding, not geometry.
inline constexpr double kNoise = 1e-9;

/// The signed turn of an arc: in (0, 2π] counterclockwise, [-2π, 0) clockwise; ±2π when
/// start == end.
double arc_sweep(const PlaneMove& arc);
/// The unit direction of motion where `move` starts / ends ((0, 0) for a line with no length).
Vec2 start_tangent(const PlaneMove& move);
Vec2 end_tangent(const PlaneMove& move);
/// Signed curvature (1/mm, > 0 turning counterclockwise; 0 for a line).
double curvature(const PlaneMove& move);

/// A move of the tool path under construction.
struct ToolMove {
    PlaneMove move;
    /// Arcs: the signed turn (kept here because a trimmed full circle's end points alone no
    /// longer say how far it turns).
    double sweep = 0;
    /// Lines: the direction the move must keep; a cut that reverses it is a gouge.
    Vec2 forward;
    /// Lines: the direction of the line other moves are intersected with, through `move.end`.
    /// The entry move's is the programmed direction, not its own (LinuxCNC backs an inside
    /// corner off along the programmed entry line's offset).
    Vec2 along;
    /// A move without length in the plane: it stays wherever the move before it ends.
    bool stationary = false;
};

/// `m` offset by `distance` to its left (negative: right), source kept. Throws CompError when
/// an arc's offset radius is not positive (the tool does not fit inside the arc).
ToolMove offset_move(const PlaneMove& m, double distance);

/// A tool move along `m` as it is (lines: `along` is its own direction).
ToolMove tool_move(const PlaneMove& m);

/// Where the line through `p` along `d` meets the one through `q` along `e` (none when they
/// are parallel).
std::vector<Vec2> line_line(Vec2 p, Vec2 d, Vec2 q, Vec2 e);

/// Where the line or circle carrying `a` meets the one carrying `b` (0, 1 or 2 points).
std::vector<Vec2> intersections(const ToolMove& a, const ToolMove& b);

/// Moves the end / start of `t` to `point` on it. Throws CompError naming `t`'s source when
/// the move would then run backwards (the tool cannot reach the corner without gouging).
void trim_end(ToolMove& t, Vec2 point);
void trim_start(ToolMove& t, Vec2 point);

/// The finished move: an arc cut down to nothing becomes a line.
PlaneMove finished(const ToolMove& t);

}  // namespace pathstream::host::gcode::cutter
