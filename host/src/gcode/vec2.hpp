// Plane geometry shared by the G-code reader's pieces: points in the XY plane (mm) and one
// cubic Bezier piece.
#pragma once

#include <array>

namespace pathstream::host::gcode {

/// A point or offset in the XY plane, in millimetres.
struct Vec2 {
    double x = 0;
    double y = 0;
};

inline Vec2 operator+(Vec2 a, Vec2 b) {
    return {a.x + b.x, a.y + b.y};
}
inline Vec2 operator-(Vec2 a, Vec2 b) {
    return {a.x - b.x, a.y - b.y};
}
inline Vec2 operator*(double k, Vec2 a) {
    return {k * a.x, k * a.y};
}
inline bool operator==(Vec2 a, Vec2 b) {
    return a.x == b.x && a.y == b.y;
}

/// One cubic Bezier piece: start, two control points, end.
struct Cubic {
    std::array<Vec2, 4> p;
};

/// The straight piece of a line move: control points at the thirds.
inline Cubic line_piece(Vec2 from, Vec2 to) {
    return Cubic{{from, from + (1.0 / 3.0) * (to - from), from + (2.0 / 3.0) * (to - from), to}};
}

/// Whether `c` is exactly line_piece of its ends (a run of these is kept as a polyline).
inline bool is_line_piece(const Cubic& c) {
    const Cubic line = line_piece(c.p[0], c.p[3]);
    return c.p[1] == line.p[1] && c.p[2] == line.p[2];
}

}  // namespace pathstream::host::gcode
