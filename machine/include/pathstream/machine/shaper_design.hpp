// Input shaper design: from a shaper family, a mode's frequency and damping, to the device's
// taps on its tick grid (whole-tick delays, weights over 2^16 summing exactly to one), and the
// residual vibration any set of taps leaves on a mode (docs/input-shaping.md).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "pathstream/shaper_taps.hpp"

namespace pathstream::host {

struct MachineProfile;  // machine.hpp, which includes this header

/// Setpoints each axis of the Linux device and the simulator remembers for its shaper: the
/// longest tap delay is one less (0.41 s at 10 kHz, a 3-hump EI down to 5 Hz).
inline constexpr std::uint32_t kDeviceShaperHistoryTicks = 4096;

/// The shaper families with positive impulses.
enum class ShaperType {
    kZv,           ///< zero vibration: 2 impulses over half a damped period
    kZvd,          ///< zero vibration and derivative: 3 impulses over one period
    kMzv,          ///< modified ZV: 3 impulses over 3/4 of a period
    kEi,           ///< extra-insensitive (5 % tolerance): 3 impulses over one period
    kTwoHumpEi,    ///< 2-hump EI: 4 impulses over 1.5 periods
    kThreeHumpEi,  ///< 3-hump EI: 5 impulses over 2 periods
};

/// Names as the profile and the command line spell them: "zv", "zvd", "mzv", "ei", "2hump_ei",
/// "3hump_ei".
const char* shaper_type_name(ShaperType type);
/// The type named `name`, or nothing.
std::optional<ShaperType> shaper_type_from_name(const std::string& name);
/// Every name, comma-separated, for messages.
std::string shaper_type_names();

/// What to shape one axis for: a family tuned to a mode.
struct ShaperSpec {
    ShaperType type = ShaperType::kMzv;
    double frequency_hz = 0;  ///< the mode's natural frequency
    double damping = 0.1;     ///< the mode's damping ratio, 0 <= zeta < 1
};

/// One continuous-time impulse: seconds after the input, weight (the weights sum to 1).
struct ShaperImpulse {
    double time = 0;
    double weight = 0;
};

/// The family's impulses for `spec`, exact to double precision. Throws std::invalid_argument
/// for a frequency that is not finite and positive or a damping outside [0, 1).
std::vector<ShaperImpulse> shaper_impulses(const ShaperSpec& spec);

/// The device's taps for `spec` at `tick_hz`: each impulse falling between ticks k and k + 1
/// at k + f is split into weights (1 - f) and f on the two (a linear fractional delay, which
/// keeps every weight positive), taps on the same tick merge, and the weights are rounded to
/// numerators over kShaperWeightOne by largest remainder so they sum to it exactly.
/// Throws std::invalid_argument (a message naming the figures) when the shaper is shorter
/// than two ticks (the frequency is too high for the tick rate) or its longest delay reaches
/// `history_ticks` (too low for the device's memory).
std::vector<ShaperTap> design_shaper_taps(const ShaperSpec& spec, double tick_hz,
                                          std::uint32_t history_ticks);

/// Residual vibration ratio of `taps` at `tick_hz` on a mode of `frequency_hz` and `damping`:
/// the amplitude a shaped step leaves ringing over the amplitude an unshaped step leaves, for
/// the ideal sampled shaper (|sum w_i exp((zeta w + i w_d) t_i)| exp(-zeta w t_last)).
/// 0: no vibration; 1: none removed.
double residual_vibration_ratio(const std::vector<ShaperTap>& taps, double tick_hz,
                                double frequency_hz, double damping);

/// Seconds from the first tap to the last: the time the shaped motion needs to settle after the
/// command stops.
double shaper_duration(const std::vector<ShaperTap>& taps, double tick_hz);

/// The spread of a shaper's delays, which sets how much it smooths the path: on a bend of
/// curvature k crossed at speed s the shaped command runs about s^2 k variance / 2 inside it;
/// through a corner whose unit tangent jumps by J at speed s, about s |J| spread / 2 off it.
struct ShaperSpread {
    double variance = 0;              ///< s^2: sum w_i (t_i - mean)^2 of the taps' delays
    double spread = 0;                ///< s: sum w_i |t_i - mean|, the mean absolute deviation
    std::uint32_t longest_delay = 0;  ///< ticks
};

/// The spread of `taps` at `tick_hz` (zeros for none). O(taps).
ShaperSpread shaper_spread(const std::vector<ShaperTap>& taps, double tick_hz);

/// The largest spread over a profile's axes' shapers at its tick rate (each designed for
/// kDeviceShaperHistoryTicks), what the planner allows for: variance, spread and longest
/// delay each the largest of any axis. Zeros without a shaper. O(axes taps).
ShaperSpread profile_shaper_spread(const MachineProfile& profile);

}  // namespace pathstream::host
