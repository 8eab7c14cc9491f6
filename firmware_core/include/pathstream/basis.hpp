// The four cubic bases a span can use, each as an integer matrix and a scale.
//
// p(u) = [u^3 u^2 u 1] * M * [P0 P1 P2 P3]^T / scale, u in [0, 1] across the span.
// Integer matrices keep the tick-domain polynomial integral (docs/exact-math.md).
#pragma once

#include <cstdint>

namespace pathstream {

/// Which cubic a span's four control values describe.
enum class Basis : std::uint8_t {
    kUniformBSpline = 0,  ///< P0..P3: uniform cubic B-spline points; C2 across spans
    kCatmullRom = 1,      ///< P0..P3: passes through P1 (u=0) and P2 (u=1); C1 across spans
    kBezier = 2,          ///< P0..P3: cubic Bezier; passes through P0 and P3
    kHermite = 3,         ///< P0, P1 end points, then tangents T0, T1 (dp/du, LSB per span)
};

inline constexpr std::uint8_t kBasisCount = 4;

/// Integer basis matrix (row 0 multiplies u^3) and its common denominator.
struct BasisMatrix {
    std::int8_t m[4][4];
    std::uint8_t scale;
};

/// Basis matrix of `b`; caller guarantees b is a valid enumerator.
constexpr BasisMatrix basis_matrix(Basis b) {
    switch (b) {
        case Basis::kUniformBSpline:
            return {{{-1, 3, -3, 1}, {3, -6, 3, 0}, {-3, 0, 3, 0}, {1, 4, 1, 0}}, 6};
        case Basis::kCatmullRom:
            return {{{-1, 3, -3, 1}, {2, -5, 4, -1}, {-1, 0, 1, 0}, {0, 2, 0, 0}}, 2};
        case Basis::kBezier:
            return {{{-1, 3, -3, 1}, {3, -6, 3, 0}, {-3, 3, 0, 0}, {1, 0, 0, 0}}, 1};
        case Basis::kHermite:
            return {{{2, -2, 1, 1}, {-3, 3, -2, -1}, {0, 0, 1, 0}, {1, 0, 0, 0}}, 1};
    }
    return {{{0}}, 1};
}

/// True for the four defined enumerators; used to validate ids read from a wire.
constexpr bool is_valid_basis(std::uint8_t id) {
    return id < kBasisCount;
}

}  // namespace pathstream
