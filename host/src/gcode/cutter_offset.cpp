// Offsets, intersections and trims of cutter compensation's tool moves (cutter_offset.hpp).
#include "cutter_offset.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace pathstream::host::gcode::cutter {

namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;

double angle_of(Vec2 a) {
    return std::atan2(a.y, a.x);
}

// How far an arc about `center` turning `ccw` must go from `from` to reach `to`, in [0, 2π).
double turn_between(Vec2 center, bool ccw, Vec2 from, Vec2 to) {
    double a = angle_of(to - center) - angle_of(from - center);
    if (!ccw) a = -a;
    a = std::fmod(a, kTwoPi);
    return a < 0 ? a + kTwoPi : a;
}

// The arc's direction of motion at `p` on it.
Vec2 arc_tangent(const PlaneMove& arc, Vec2 p) {
    const Vec2 t = left(unit(p - arc.center));
    return arc.ccw ? t : -1.0 * t;
}

std::vector<Vec2> line_circle(Vec2 p, Vec2 d, Vec2 c, double r) {
    const Vec2 foot = p + dot(c - p, d) * d;  // d is a unit vector
    const double h = norm(c - foot);
    if (h > r) return {};
    const double s = std::sqrt(r * r - h * h);
    return {foot - s * d, foot + s * d};
}

std::vector<Vec2> circle_circle(Vec2 c1, double r1, Vec2 c2, double r2) {
    const double d = norm(c2 - c1);
    if (d < kNoise || d > r1 + r2 || d < std::fabs(r1 - r2)) return {};
    const double a = (r1 * r1 - r2 * r2 + d * d) / (2 * d);
    const double h = std::sqrt(std::max(0.0, r1 * r1 - a * a));
    const Vec2 u = unit(c2 - c1);
    const Vec2 mid = c1 + a * u;
    return {mid + h * left(u), mid - h * left(u)};
}

[[noreturn]] void gouge(const ToolMove& t) {
    throw CompError(t.move.source, t.move.kind == PlaneMove::kLine
                                       ? "Straight feed in concave corner cannot be reached by "
                                         "the tool without gouging"
                                       : "Arc move in concave corner cannot be reached by the "
                                         "tool without gouging");
}

}  // namespace

std::vector<Vec2> line_line(Vec2 p, Vec2 d, Vec2 q, Vec2 e) {
    const double det = cross(d, e);
    if (std::fabs(det) < 1e-12 * norm(d) * norm(e)) return {};
    return {p + (cross(q - p, e) / det) * d};
}

double arc_sweep(const PlaneMove& arc) {
    if (arc.start == arc.end) return arc.ccw ? kTwoPi : -kTwoPi;
    const double a = turn_between(arc.center, arc.ccw, arc.start, arc.end);
    const double turn = a == 0 ? kTwoPi : a;
    return arc.ccw ? turn : -turn;
}

Vec2 start_tangent(const PlaneMove& move) {
    return move.kind == PlaneMove::kLine ? unit(move.end - move.start)
                                         : arc_tangent(move, move.start);
}

Vec2 end_tangent(const PlaneMove& move) {
    return move.kind == PlaneMove::kLine ? unit(move.end - move.start)
                                         : arc_tangent(move, move.end);
}

double curvature(const PlaneMove& move) {
    if (move.kind == PlaneMove::kLine) return 0;
    const double k = 1 / norm(move.end - move.center);
    return move.ccw ? k : -k;
}

ToolMove tool_move(const PlaneMove& m) {
    ToolMove t{m, 0, {}, {}, false};
    if (m.kind == PlaneMove::kArc) {
        t.sweep = arc_sweep(m);
    } else {
        t.forward = t.along = unit(m.end - m.start);
        t.stationary = norm(m.end - m.start) <= kNoise;
    }
    return t;
}

ToolMove offset_move(const PlaneMove& m, double distance) {
    ToolMove t = tool_move(m);
    if (t.stationary) return t;
    // Each end moves along its own normal: for an arc that is the radius through it, so the
    // center stays and the radius changes by `distance` (inward when the normal points in).
    t.move.start = m.start + distance * left(start_tangent(m));
    t.move.end = m.end + distance * left(end_tangent(m));
    if (m.kind == PlaneMove::kArc) {
        // Left of a counterclockwise arc (right of a clockwise one) is toward its center.
        const bool inward = (distance > 0) == m.ccw;
        if (inward && (std::fabs(distance) >= norm(m.start - m.center) ||
                       std::fabs(distance) >= norm(m.end - m.center))) {
            throw CompError(m.source, "Tool radius not less than arc radius with comp");
        }
        t.sweep = arc_sweep(m);  // the turn of the programmed arc: a full circle stays full
    }
    return t;
}

std::vector<Vec2> intersections(const ToolMove& a, const ToolMove& b) {
    const bool a_line = a.move.kind == PlaneMove::kLine, b_line = b.move.kind == PlaneMove::kLine;
    const double ra = norm(a.move.end - a.move.center);
    // The later move is cut at its start: its circle through the start.
    const double rb = norm(b.move.start - b.move.center);
    if (a_line && b_line) return line_line(a.move.end, a.along, b.move.end, b.along);
    if (a_line) return line_circle(a.move.end, a.along, b.move.center, rb);
    if (b_line) return line_circle(b.move.end, b.along, a.move.center, ra);
    return circle_circle(a.move.center, ra, b.move.center, rb);
}

void trim_end(ToolMove& t, Vec2 point) {
    if (norm(point - t.move.end) <= kNoise) return;
    if (t.move.kind == PlaneMove::kLine) {
        if (dot(point - t.move.start, t.forward) < 0) gouge(t);
    } else {
        // The cut end must lie on what the arc already covers from its start: further round,
        // the tool would have to run the arc backwards (or the long way round).
        const double turn = norm(point - t.move.start) <= kNoise
                                ? 0
                                : turn_between(t.move.center, t.move.ccw, t.move.start, point);
        if (turn > std::fabs(t.sweep)) gouge(t);
        t.sweep = t.move.ccw ? turn : -turn;
    }
    t.move.end = point;
}

void trim_start(ToolMove& t, Vec2 point) {
    if (norm(point - t.move.start) <= kNoise) return;
    if (t.move.kind == PlaneMove::kLine) {
        if (dot(t.move.end - point, t.forward) < 0) gouge(t);
    } else {
        const double turn = norm(point - t.move.end) <= kNoise
                                ? std::fabs(t.sweep)
                                : turn_between(t.move.center, t.move.ccw, t.move.start, point);
        if (turn > std::fabs(t.sweep)) gouge(t);
        t.sweep = t.move.ccw ? t.sweep - turn : t.sweep + turn;
    }
    t.move.start = point;
}

PlaneMove finished(const ToolMove& t) {
    PlaneMove m = t.move;
    if (m.kind == PlaneMove::kArc && std::fabs(t.sweep) * norm(m.end - m.center) <= kNoise) {
        m.kind = PlaneMove::kLine;
    }
    return m;
}

}  // namespace pathstream::host::gcode::cutter
