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

}  // namespace pathstream::host::gcode
