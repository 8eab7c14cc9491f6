// A resonance from its ring-down: the natural frequency and damping ratio of the mode that
// dominates a decaying oscillation, from samples taken after the motion that excited it
// stopped (docs/input-shaping.md, "Calibration").
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace pathstream::host {

/// One signal over time: position (mm) or acceleration (mm/s^2) of the tool, or any quantity
/// proportional to the ringing. Times in seconds, increasing.
struct RingDownSamples {
    std::vector<double> time;
    std::vector<double> value;
};

/// What the ring-down shows.
struct RingDown {
    double frequency_hz = 0;      ///< natural (undamped) frequency of the mode
    double damped_hz = 0;         ///< the oscillation's own frequency, f sqrt(1 - zeta^2)
    double damping = 0;           ///< damping ratio zeta
    std::size_t half_cycles = 0;  ///< half-cycles used (between zero crossings)
    double first_amplitude = 0;   ///< the first half-cycle's peak, in the samples' unit
};

/// Fits a damped oscillation to `samples`: the rest value is the mean of the last fifth; the
/// zero crossings about it (linear interpolation between samples) give the damped period by
/// least squares over their index, and the half-cycles' peak amplitudes the decay rate by
/// least squares over ln(amplitude) (the logarithmic decrement), from the first half-cycle
/// until one falls below `floor` times the first (noise). zeta = s / sqrt(s^2 + w_d^2) and
/// f = sqrt(s^2 + w_d^2) / 2 pi with s the decay rate. O(samples). Throws std::invalid_argument
/// ("...: what is wrong") for fewer than 16 samples, times not increasing, non-finite values,
/// or fewer than 4 half-cycles above the floor (no ringing to measure).
RingDown fit_ring_down(const RingDownSamples& samples, double floor = 0.02);

/// Reads a ring-down CSV: a header line naming the columns `time` (s) and one of `position`
/// (mm) or `acceleration` (mm/s^2), comma-separated, then one sample per line; `#` lines are
/// comments. Throws InputError ("file:line:col: what is wrong") for a missing or unknown
/// column, a bad number, too few columns on a line or times that do not increase.
RingDownSamples load_ring_down_csv(const std::string& file);

/// The same reading of `text`, errors naming `file`. O(text); at most 2,000,000 samples.
RingDownSamples parse_ring_down_csv(const std::string& text, const std::string& file);

}  // namespace pathstream::host
