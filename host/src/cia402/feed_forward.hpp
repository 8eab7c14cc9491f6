// The feed-forward of one cycle from the exact integer targets around it: the velocity offset
// (0x60B1) and the torque offset (0x60B2) the master sends with target p_k (docs/cia402.md
// "Feed-forward").
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace pathstream::host::cia402 {

/// One axis's offsets for the cycle whose SYNC applies target `p`.
struct CycleFeedForward {
    std::int32_t velocity = 0;  ///< LSB/s
    std::int16_t torque = 0;    ///< per mille of rated torque
};

/// A drive interpolating between cycle targets moves from `p1` = p_(k-1) to `p` = p_k over the
/// cycle that starts at the SYNC applying p_k: the backward difference (p - p1) / T is that
/// cycle's velocity, exactly. The demand's velocity changes by (p - 2 p1 + p2) / T at the
/// cycle's start and by (next - 2 p + p1) / T at its end; spreading each half over the cycles on
/// either side gives the central acceleration (next - p - p1 + p2) / (2 T^2), which needs
/// `next` = p_(k+1), one cycle ahead. Rounded, and clamped to the objects' ranges.
inline CycleFeedForward cycle_feed_forward(std::int64_t p2, std::int64_t p1, std::int64_t p,
                                           std::int64_t next, double cycle_s,
                                           double torque_per_acceleration) {
    const auto clamp = [](double v, std::int64_t limit) {
        return std::clamp<std::int64_t>(std::llround(v), -limit, limit);
    };
    CycleFeedForward f;
    f.velocity = static_cast<std::int32_t>(
        clamp(static_cast<double>(p - p1) / cycle_s, std::numeric_limits<std::int32_t>::max()));
    const double acceleration = static_cast<double>(next - p - p1 + p2) / (2 * cycle_s * cycle_s);
    f.torque = static_cast<std::int16_t>(clamp(acceleration * torque_per_acceleration, 32767));
    return f;
}

}  // namespace pathstream::host::cia402
