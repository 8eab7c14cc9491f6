// Real-time pacing on Linux: the monotonic clock counted in device ticks.
#pragma once

#include <cstdint>
#include <ctime>

#include "pathstream/hal/clock.hpp"

namespace pathstream::hal {

/// Clock over CLOCK_MONOTONIC (what std::chrono::steady_clock uses on Linux). Tick 0 is the
/// moment of construction; tick k is start + k / tick_hz, computed from the start each time
/// (no accumulated rounding). wait_until() sleeps with an absolute deadline
/// (clock_nanosleep TIMER_ABSTIME), so a late wake-up never delays the ticks after it.
/// Linux host only (library pathstream_hal_linux). Wake-up jitter is the scheduler's (tens
/// of microseconds typically): good for pacing a simulation, not for hard real time.
class LinuxClock final : public Clock {
public:
    /// `tick_hz` > 0. Throws std::invalid_argument otherwise.
    explicit LinuxClock(double tick_hz);

    std::uint64_t now() const override;
    void wait_until(std::uint64_t tick) override;

    double tick_hz() const { return tick_hz_; }

private:
    double tick_hz_;
    timespec start_{};
};

}  // namespace pathstream::hal
