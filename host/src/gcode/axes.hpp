// The nine axes of RS274/NGC (X Y Z A B C U V W) as the G-code reader tracks them, and the
// cubic pieces moves are made of in that space; the planes arcs lie in.
#pragma once

#include <array>
#include <cstddef>
#include <sstream>
#include <string>
#include <string_view>

#include "vec2.hpp"

namespace pathstream::host::gcode {

/// The axis words in LinuxCNC's order; an axis's index is its place here.
inline constexpr std::string_view kAxisLetters = "XYZABCUVW";
inline constexpr std::size_t kAxisCount = 9;
inline constexpr std::size_t kX = 0, kY = 1, kZ = 2;

/// The largest |coordinate| a program may reach, mm or degrees: as the JSON reader, it
/// catches unit mix-ups.
inline constexpr double kMaxCoordinateMm = 1e6;

/// The shortest usual form of a number, for messages ("1.5", "1e+06").
inline std::string number_text(double v) {
    std::ostringstream s;
    s << v;
    return s.str();
}

/// A position: mm on X Y Z U V W, degrees on A B C (machine coordinates).
using Axes = std::array<double, kAxisCount>;

/// The index of axis word `letter` (upper case), or kAxisCount when it is no axis word.
inline std::size_t axis_index(char letter) {
    const std::size_t i = kAxisLetters.find(letter);
    return i == std::string_view::npos ? kAxisCount : i;
}
/// A B C are rotary (degrees: no inch scaling); the rest are linear.
inline bool is_rotary(std::size_t axis) {
    return axis >= 3 && axis <= 5;
}

/// One cubic Bezier piece in all nine axes.
struct Piece {
    std::array<Axes, 4> p;
};

/// The straight piece from `a` to `b`: control points at the thirds.
inline Piece line_piece(const Axes& a, const Axes& b) {
    Piece piece{{a, a, a, b}};
    for (std::size_t i = 0; i < kAxisCount; ++i) {
        piece.p[1][i] = a[i] + (1.0 / 3.0) * (b[i] - a[i]);
        piece.p[2][i] = a[i] + (2.0 / 3.0) * (b[i] - a[i]);
    }
    return piece;
}

/// Whether `piece` is exactly line_piece of its ends (a run of these is kept as a polyline).
inline bool is_line_piece(const Piece& piece) {
    const Piece line = line_piece(piece.p[0], piece.p[3]);
    return piece.p[1] == line.p[1] && piece.p[2] == line.p[2];
}

/// An arc plane (G17, G18, G19): its two in-plane axes in the order that makes G3
/// counterclockwise seen from the positive normal axis, and the letters of their center
/// offsets (G17: X Y, I J; G18: Z X, K I; G19: Y Z, J K).
struct Plane {
    std::size_t first = kX, second = kY, normal = kZ;
    char first_offset = 'I', second_offset = 'J';
    const char* name = "G17";
};

inline constexpr Plane kPlaneXY{kX, kY, kZ, 'I', 'J', "G17"};
inline constexpr Plane kPlaneZX{kZ, kX, kY, 'K', 'I', "G18"};
inline constexpr Plane kPlaneYZ{kY, kZ, kX, 'J', 'K', "G19"};

/// A position's coordinates in `plane`.
inline Vec2 in_plane(const Axes& a, const Plane& plane) {
    return {a[plane.first], a[plane.second]};
}

}  // namespace pathstream::host::gcode
