// The time base a device loop runs on, counted in ticks of the device's tick rate.
#pragma once

#include <cstdint>

namespace pathstream::hal {

/// A monotonic tick counter: tick 0 is when the clock started, tick k is k tick periods
/// later. Implementations: a hardware timer on an MCU, hal/linux_clock.hpp (steady clock) on
/// Linux, pathstream::sim::VirtualClock (instant) in the simulator.
/// Freestanding: no heap, no exceptions; usable by firmware and host alike.
class Clock {
public:
    virtual ~Clock() = default;

    /// Whole ticks elapsed since the start; never decreases. Cost: one timer read (a
    /// clock_gettime on Linux, a load in the simulator). Any context, the tick interrupt too.
    virtual std::uint64_t now() const = 0;

    /// Returns once now() >= tick; at once if that tick has already come (a late caller is
    /// not punished with a longer wait: deadlines are absolute, so lateness never
    /// accumulates). Blocks (sleeps) on Linux, advances the count in the simulator.
    /// Task context only: never from an interrupt, never while holding a lock the tick needs.
    virtual void wait_until(std::uint64_t tick) = 0;
};

}  // namespace pathstream::hal
