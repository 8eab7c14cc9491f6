#include "pathstream/sim/residual_vibration.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace pathstream::sim {

std::uint64_t residual_window_ticks(double tick_hz, double lowest_hz) {
    const double seconds = lowest_hz > 0 ? std::min(1.0, 5.0 / lowest_hz) : 1.0;
    return std::max<std::uint64_t>(1, static_cast<std::uint64_t>(std::ceil(seconds * tick_hz)));
}

std::uint64_t servo_settle_ticks(double tick_hz, double servo_hz, double servo_damping) {
    if (!(servo_hz > 0) || !(servo_damping > 0)) return 0;
    const double seconds = 6.64 / (std::min(1.0, servo_damping) * 2 * std::numbers::pi * servo_hz);
    return static_cast<std::uint64_t>(std::ceil(seconds * tick_hz));
}

ResidualVibrationMeter::ResidualVibrationMeter(std::size_t axes, std::uint64_t window_ticks,
                                               std::uint64_t min_stop_ticks,
                                               std::uint64_t settle_ticks)
    : axes_(axes), window_(window_ticks), min_stop_(min_stop_ticks), settle_(settle_ticks) {
    if (axes == 0 || window_ticks == 0)
        throw std::invalid_argument("residual vibration needs an axis and a window of a tick");
    previous_.assign(axes, 0.0);
    peak_tool_.assign(axes, 0.0);
    peak_carriage_.assign(axes, 0.0);
    r_.window_ticks = window_ticks;
    r_.settle_ticks = settle_ticks;
}

void ResidualVibrationMeter::add(const double* command_mm, const double* tool_mm,
                                 const double* carriage_mm) {
    const std::uint64_t k = tick_++;
    bool moving = false;
    for (std::size_t a = 0; a < axes_; ++a) moving = moving || command_mm[a] != previous_[a];
    if (k == 0 || moving) {
        if (k > 0) {
            close_stop(false);
            moved_ = true;
        }
        std::copy(command_mm, command_mm + axes_, previous_.begin());
        return;
    }
    if (!moved_) return;
    if (held_ == 0) peak_ = -1;
    if (++held_ <= settle_ || held_ > settle_ + window_) return;
    double squares = 0;
    for (std::size_t a = 0; a < axes_; ++a) {
        const double d = tool_mm[a] - carriage_mm[a];
        squares += d * d;
    }
    const double distance = std::sqrt(squares);
    if (distance > peak_) {
        peak_ = distance;
        peak_tick_ = k;
        std::copy(tool_mm, tool_mm + axes_, peak_tool_.begin());
        std::copy(carriage_mm, carriage_mm + axes_, peak_carriage_.begin());
    }
}

void ResidualVibrationMeter::close_stop(bool run_ended) {
    const std::uint64_t held = held_;
    held_ = 0;
    if (held <= settle_ || (held < min_stop_ && !run_ended)) return;
    ++r_.stops;
    sum_squares_ += peak_ * peak_;
    if (r_.max_tool_mm.empty() || peak_ > r_.max_mm) {
        r_.max_mm = peak_;
        r_.max_tick = peak_tick_;
        r_.max_tool_mm = peak_tool_;
        r_.max_carriage_mm = peak_carriage_;
        r_.max_rest_mm = previous_;
    }
}

ResidualVibration ResidualVibrationMeter::finish() {
    close_stop(true);
    if (r_.stops > 0) r_.rms_mm = std::sqrt(sum_squares_ / static_cast<double>(r_.stops));
    return std::move(r_);
}

}  // namespace pathstream::sim
