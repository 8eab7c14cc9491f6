// Homing a device's axes one after another through its DeviceIo (docs/gpio.md):
// what `pathstream device --machine M --home` runs before it serves. The caller owns the
// ticking (paced in real time by the CLI, as fast as possible with simulated switches in tests).
#pragma once

#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "pathstream/linux_device/any_motion_device.hpp"
#include "pathstream/linux_device/device_io.hpp"
#include "pathstream/machine/device_setup.hpp"

namespace pathstream::linux_device {

/// Homing ended in an error; what() names the axis, the switch and the reason:
/// "homing x: switch x- not found within 300 mm (max_travel)".
class HomingFailed : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// One homed axis.
struct HomedAxis {
    std::string axis_name;
    Lsb latch = 0;               ///< where the slow approach saw the switch (old coordinates)
    std::int64_t overshoot = 0;  ///< how far the search stop ran past the switch (LSB)
    Lsb rest = 0;                ///< the axis's position afterwards (new coordinates)
    std::uint64_t ticks = 0;     ///< ticks the axis's homing took
};

/// Ticks the device until `done()` is true; false if it gave up (interrupted by the user).
using RunTicksUntil = std::function<bool(const std::function<bool()>& done)>;
/// Receives one line of progress (phase changes) at a time.
using HomingLog = std::function<void(const std::string& line)>;

/// Follows homing runs a bus command starts (`pathstream ctl TARGET home`) and describes them
/// in home_axes's words, one line per phase and one per axis at its end. Task context: after
/// every tick.
class HomingRunLog {
public:
    /// `setups` are the plan's axes (set_homing_plan). `device` and `io` must outlive it.
    HomingRunLog(const linux_device::AnyMotionDevice& device, const linux_device::DeviceIo& io,
                 std::vector<host::HomingSetup> setups, double mm_per_lsb);
    void after_tick(const HomingLog& log);

private:
    const linux_device::AnyMotionDevice& device_;
    const linux_device::DeviceIo& io_;
    std::vector<host::HomingSetup> setups_;
    double mm_per_lsb_;
    bool busy_ = false;
    bool sequencer_busy_ = false;
    unsigned axis_ = 0;
    device::HomingPhase phase_ = device::HomingPhase::kIdle;
};

/// Gives `io` the axes a bus's home command may home (`setups`, in order). Throws
/// HomingFailed naming the switch when one is not wired.
void set_homing_plan(linux_device::DeviceIo& io, const std::vector<host::HomingSetup>& setups);

/// Homes `setups` in order, each as a homing run of one axis (so the bus status reports it).
/// Sets the plan (set_homing_plan) first. `device` must be configured and idle, `io` attached to
/// it. Throws HomingFailed (with the device stopped: idle, or in fault/e-stop if that ended it).
std::vector<HomedAxis> home_axes(linux_device::AnyMotionDevice& device, linux_device::DeviceIo& io,
                                 const std::vector<host::HomingSetup>& setups, double mm_per_lsb,
                                 const RunTicksUntil& run_until, const HomingLog& log);

}  // namespace pathstream::linux_device
