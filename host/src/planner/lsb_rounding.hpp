// The roundings onto the LSB grid that the forward pass and the emitter share: the forward
// pass checks the spans the device will run only if both round alike, bit for bit.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "pathstream/units.hpp"
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

/// Ticks of the regular span of a piece whose feed is `feed` (mm/s), `ticks` being the
/// profile's regular span (regular_span_ticks): more where the feed is fine against the LSB
/// grid. A span of n ticks carries its velocity as whole-LSB tangents, in steps of 1/n LSB per
/// tick, so, as regular_span_ticks does for the axes' velocity limits, spans are lengthened
/// until the feed covers 8 LSB per span (up to the core's longest span). Without this a feed
/// far below an LSB per span (1 mm/min on 1 um and 1 kHz: 0.017 LSB per tick) has tangents
/// that round to 0: the motion becomes hops of one LSB from rest to rest within one span, at
/// ten times the feed and more (a diagonal hop broke the planner's feed check, and no motion
/// was found at all). With the lengthened spans the tangents carry the feed within 1/16.
inline std::uint32_t feed_span_ticks(std::uint32_t ticks, double feed, double tick_hz, double lsb) {
    if (!(feed > 0) || !(lsb > 0) || !(tick_hz > 0)) return ticks;
    const double n = std::ceil(8 * lsb * tick_hz / feed - 1e-9);
    if (!(n > ticks)) return ticks;
    return static_cast<std::uint32_t>(std::min<double>(n, kMaxSpanTicks));
}

/// A point on the LSB grid (mm), rounded as the emitter rounds span end points.
inline Vec on_lsb_grid(const Vec& q, double lsb, std::size_t axes) {
    Vec r{};
    for (std::size_t i = 0; i < axes; ++i)
        r[i] = static_cast<double>(std::llround(q[i] / lsb)) * lsb;
    return r;
}

}  // namespace pathstream::host::planner_detail
