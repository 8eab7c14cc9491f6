// The outside world of a gpio-sim line (the kernel's simulated GPIO chip, docs/vm.md): writing
// "pull-up" or "pull-down" to the line's sysfs `pull` attribute sets the level every consumer
// of the line reads, with edge events, as a switch wired to a real pin would.
#pragma once

#include <string>

namespace pathstream::sim {

/// One gpio-sim line driven from outside. Task context; each change is one open, write and
/// close of a sysfs file (tens of microseconds).
class GpioSimPull {
public:
    /// The line `offset` of chip `chip_name` ("gpiochip3"), found under `sysfs_devices`
    /// (CHIP/sim_gpioOFFSET/pull). `active_low`: the consumer reads active on a low line.
    /// Throws hal::GpioError naming the path when the chip is no gpio-sim chip or the
    /// attribute cannot be written.
    GpioSimPull(const std::string& chip_name, unsigned offset, bool active_low,
                const std::string& sysfs_devices = "/sys/bus/gpio/devices");

    /// Drives the line so that its consumer reads `active`. Throws hal::GpioError when the
    /// write fails (the chip went away).
    void set(bool active);

    const std::string& path() const { return path_; }

private:
    std::string path_;
    bool active_low_ = false;
};

}  // namespace pathstream::sim
