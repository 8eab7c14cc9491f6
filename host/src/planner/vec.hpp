// The planner's vector of axis values: a fixed-size array (up to kAxesMax axes, the unused
// ones 0) so that the hot loops allocate nothing, and the few operations on it.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>

namespace pathstream::host::planner_detail {

inline constexpr std::size_t kAxesMax = 8;
using Vec = std::array<double, kAxesMax>;  // the first `axes` entries are used, the rest stay 0

/// Summed as a tree: a chain of eight dependent additions costs four times as long, and with
/// two or three axes in use (the rest 0) the result is the chain's, bit for bit.
inline double dot(const Vec& a, const Vec& b) {
    static_assert(kAxesMax == 8);
    const double s01 = a[0] * b[0] + a[1] * b[1], s23 = a[2] * b[2] + a[3] * b[3];
    const double s45 = a[4] * b[4] + a[5] * b[5], s67 = a[6] * b[6] + a[7] * b[7];
    return (s01 + s23) + (s45 + s67);
}
inline double norm(const Vec& a) {
    return std::sqrt(dot(a, a));
}
inline Vec sub(const Vec& a, const Vec& b) {
    Vec r{};
    for (std::size_t i = 0; i < kAxesMax; ++i) r[i] = a[i] - b[i];
    return r;
}
inline Vec scaled(const Vec& a, double s) {
    Vec r{};
    for (std::size_t i = 0; i < kAxesMax; ++i) r[i] = a[i] * s;
    return r;
}

}  // namespace pathstream::host::planner_detail
