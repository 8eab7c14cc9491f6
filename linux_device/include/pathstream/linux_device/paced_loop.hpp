// The device loop's pacing: ticks due on the steady clock at the device's rate (times a scale),
// the bus served in between. One loop for every transport and for homing before serving.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>

namespace pathstream::linux_device {

/// How the device loop paces ticks.
struct DeviceLoopOptions {
    /// Device ticks run `time_scale` times faster than real time (1 = real time). The tick
    /// rate is the configured one (unconfigured: 1 kHz).
    double time_scale = 1.0;
    /// Stop after this much wall time (0: until `stop` is set).
    std::chrono::milliseconds run_for{0};
    /// True while the device is at rest with nothing to do (optional): ticks then run at most
    /// `rest_tick_hz` times per second of wall time whatever the time scale, and the idle time
    /// between them is not made up, so an idle device costs the same CPU at 1x and at 1000x.
    std::function<bool()> at_rest;
    double rest_tick_hz = 1000;
};

/// The pacing shared by every simulated device: calls `tick` whenever a tick falls due on the
/// steady clock (period 1 / (tick_hz() x time_scale), tick_hz() read after every tick, 1 kHz
/// while it is 0), and `serve` with the time left until the next one, until `stop` becomes
/// true or options.run_for passes. Ticks that fall due while `serve` runs are run right after
/// it, so the count never drifts (except at rest, see DeviceLoopOptions::at_rest). Returns the
/// ticks run. Throws std::invalid_argument for a time scale <= 0.
std::uint64_t run_paced_loop(const std::function<void()>& tick,
                             const std::function<std::uint32_t()>& tick_hz,
                             const std::function<void(std::chrono::microseconds)>& serve,
                             const DeviceLoopOptions& options, const std::atomic<bool>& stop);

}  // namespace pathstream::linux_device
