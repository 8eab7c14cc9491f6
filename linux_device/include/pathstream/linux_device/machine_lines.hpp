// A machine profile's GPIO lines opened through libgpiod (docs/gpio.md): what
// `pathstream device --machine` and the VM test's driver wire a device to.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "pathstream/hal/digital_output.hpp"
#include "pathstream/hal/gpio.hpp"
#include "pathstream/hal/gpio_gpiod.hpp"
#include "pathstream/linux_device/device_io.hpp"
#include "pathstream/machine/machine.hpp"

namespace pathstream::linux_device {

/// The libgpiod request for one profile line (chip from the gpio object).
hal::GpioLineSpec line_spec(const std::string& chip, const host::GpioLineConfig& line);

/// Owns the requested lines. Outputs start inactive (drives disabled, pen up, spindle and
/// coolant off).
class MachineLines {
public:
    /// Requests every line the profile's "gpio" object names, consumers "pathstream-<function>"
    /// (gpioinfo shows them). Throws hal::GpioError naming chip, line and function's failure
    /// (no such chip or line, busy with its holder named), std::invalid_argument when the
    /// profile has no gpio object.
    static MachineLines open(const host::MachineProfile& profile);

    MachineLines(MachineLines&&) = default;
    MachineLines& operator=(MachineLines&&) = delete;
    /// Drives every output inactive (drives disabled, pen up, spindle and coolant off) before
    /// releasing the lines: a released line may keep its last level, and a program that ends
    /// must not leave the drives enabled or the spindle running.
    ~MachineLines();

    /// Pointers into the owned lines; valid while this object lives.
    const linux_device::MachineWiring& wiring() const { return wiring_; }
    /// "enable=enable estop=estop pen=0 x-=limit-x ..." on chip: what was opened, for the log.
    const std::string& summary() const { return summary_; }

private:
    MachineLines() = default;
    std::vector<std::unique_ptr<hal::DigitalInput>> inputs_;
    std::vector<std::unique_ptr<hal::DigitalOutput>> outputs_;
    linux_device::MachineWiring wiring_;
    std::string summary_;
};

}  // namespace pathstream::linux_device
