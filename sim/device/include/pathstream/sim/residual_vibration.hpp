// Residual vibration: how far the tool still rings about the carriage once the command into
// the plant has come to rest (docs/simulator.md, "Residual vibration").
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace pathstream::sim {

/// A hold of the command shorter than this (s) is slow motion (setpoints that advance by less
/// than one LSB per tick), not a stop; the run's final hold counts whatever its length.
inline constexpr double kMinStopSeconds = 0.01;

/// The residual vibration over a run's stops.
struct ResidualVibration {
    std::uint64_t stops = 0;              ///< stops measured
    std::uint64_t window_ticks = 0;       ///< ticks of each stop looked at, at most
    std::uint64_t settle_ticks = 0;       ///< ticks of each stop skipped first (servo settling)
    double max_mm = 0;                    ///< largest peak over the stops
    double rms_mm = 0;                    ///< RMS of the stops' peaks (0 without stops)
    std::uint64_t max_tick = 0;           ///< tick of the largest peak
    std::vector<double> max_tool_mm;      ///< tool position per axis at that tick (empty: none)
    std::vector<double> max_rest_mm;      ///< that stop's rest position per axis
    std::vector<double> max_carriage_mm;  ///< the carriage per axis at that tick
};

/// Ticks the servo takes to settle after its command stops, before a stop's ringing is looked
/// at: its error within 1 % (a critically damped servo's e^(-w t)(1 + w t) < 0.01 at
/// w t = 6.64; 6.64 / (zeta w) below critical damping), rounded up; 0 for `servo_hz` <= 0 (the
/// ideal plant).
std::uint64_t servo_settle_ticks(double tick_hz, double servo_hz, double servo_damping);

/// Ticks a stop is looked at: 5 periods of the plant's lowest natural frequency (a servo's
/// bandwidth or a mode's frequency, Hz), at most 1 s, at least 1 tick; `lowest_hz` <= 0
/// (nothing that rings: the ideal plant): 1 s.
std::uint64_t residual_window_ticks(double tick_hz, double lowest_hz);

/// Measures residual vibration tick by tick in O(axes) memory. A stop begins at the first tick
/// whose command equals the previous tick's after a tick where it changed (motion, then rest;
/// the rest before the first motion is no stop) and lasts while the command stays equal. Its
/// peak is the largest Euclidean distance over the axes between the tool and the carriage
/// (the servo's own position, which the modes ring about) over `window_ticks` ticks once the
/// motion has settled, `settle_ticks` after the stop began: the ringing, not the carriage
/// still decelerating nor the servo closing its lag. A stop counts when it holds past its
/// settling and for min_stop_ticks or more, or when the run ends in it.
class ResidualVibrationMeter {
public:
    /// `axes` >= 1, `window_ticks` >= 1. Throws std::invalid_argument otherwise.
    ResidualVibrationMeter(std::size_t axes, std::uint64_t window_ticks,
                           std::uint64_t min_stop_ticks, std::uint64_t settle_ticks = 0);

    /// The next tick (ticks come in order, from 0): the command into the plant, the tool's
    /// position and the carriage's (the servo's; the tool's without modes) at the tick, mm
    /// per axis.
    void add(const double* command_mm, const double* tool_mm, const double* carriage_mm);
    /// After the last tick: the figures. Call once.
    ResidualVibration finish();

private:
    void close_stop(bool run_ended);

    std::size_t axes_;
    std::uint64_t window_;
    std::uint64_t min_stop_;
    std::uint64_t settle_;
    std::uint64_t tick_ = 0;
    bool moved_ = false;      // a tick changed the command since the start
    std::uint64_t held_ = 0;  // ticks of the stop so far (0: moving)
    double peak_ = 0;         // this stop's peak
    std::uint64_t peak_tick_ = 0;
    std::vector<double> previous_;
    std::vector<double> peak_tool_;
    std::vector<double> peak_carriage_;
    double sum_squares_ = 0;
    ResidualVibration r_;
};

}  // namespace pathstream::sim
