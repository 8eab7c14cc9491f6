// The roundings onto the LSB grid that the forward pass and the emitter share: the forward
// pass checks the spans the device will run only if both round alike, bit for bit.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>

#include "vec.hpp"

namespace pathstream::host::planner_detail {

/// LSB of tangent per mm/s of velocity on a span of `ticks` ticks: the one formula the forward
/// pass and the emitter both round tangents with. (Two formulas an ulp apart broke a tie of
/// 1.5 LSB differently: the device got an exact cubic 1.6 % over a limit the forward pass had
/// checked within it.)
inline double tangent_scale(std::uint32_t ticks, double tick_hz, double lsb) {
    return ticks / tick_hz / lsb;
}

/// A velocity (mm/s, one axis) as the tangent of a span in whole LSB, `scale` being the span's
/// tangent_scale: the one rounding (half away from zero) the forward pass and the emitter share.
inline long long scaled_tangent_lsb(double velocity, double scale) {
    const double x = velocity * scale;
    // std::llround inline (it is a library call, and this runs for every axis of every span
    // tried): below 2^52 the fraction x - trunc(x) is exact, so half away from zero is exact.
    if (!(std::fabs(x) < 0x1p52)) return std::llround(x);
    long long i = static_cast<long long>(x);
    const double fraction = x - static_cast<double>(i);
    if (fraction >= 0.5)
        ++i;
    else if (fraction <= -0.5)
        --i;
    return i;
}

/// A point on the LSB grid (mm), rounded as the emitter rounds span end points.
inline Vec on_lsb_grid(const Vec& q, double lsb, std::size_t axes) {
    Vec r{};
    for (std::size_t i = 0; i < axes; ++i)
        r[i] = static_cast<double>(std::llround(q[i] / lsb)) * lsb;
    return r;
}

}  // namespace pathstream::host::planner_detail
