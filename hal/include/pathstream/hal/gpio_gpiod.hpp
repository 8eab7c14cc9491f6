// The libgpiod 1.6 backend of DigitalInput and DigitalOutput (Linux character device).
#pragma once

#include <memory>
#include <stdexcept>
#include <string>

#include "pathstream/hal/gpio.hpp"

namespace pathstream::hal {

/// Where a line is and how it is wired.
struct GpioLineSpec {
    /// "gpiochip0", "/dev/gpiochip0", a chip number ("0"), or a chip label ("pathstream-sim").
    std::string chip;
    /// An offset on the chip ("3") or a line name ("estop", as gpioinfo shows it).
    std::string line;
    bool active_low = false;  ///< active = electrically low (inverted by the backend)
    Bias bias = Bias::kAsIs;
};

/// Opening or driving a line failed. The message names the chip and the line, what was being
/// done, and the system error: "gpio pathstream-sim line \"estop\": request edge events: ...".
class GpioError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// Requests `spec` as an input with edge events on both edges. Throws GpioError: no such chip
/// or line, line busy, bias not supported. `consumer` is the label the kernel shows (gpioinfo).
std::unique_ptr<DigitalInput> open_gpiod_input(const GpioLineSpec& spec,
                                               const std::string& consumer);

/// Requests `spec` as an output driven to `initially_active` at once (no glitch through the
/// other level). Throws GpioError. set() on the returned output throws GpioError when the
/// kernel refuses the write (the line vanished): an output that silently stops working is
/// worse than a stopped program.
std::unique_ptr<DigitalOutput> open_gpiod_output(const GpioLineSpec& spec,
                                                 const std::string& consumer,
                                                 bool initially_active = false);

/// A line's place in the kernel: the chip's name ("gpiochip3") and the line's offset on it.
struct GpioLineLocation {
    std::string chip_name;
    unsigned offset = 0;
};

/// Resolves `spec` (chip by path, name, number or label; line by offset or name) without
/// requesting the line. Throws GpioError as open_gpiod_input does. Init context.
GpioLineLocation locate_gpiod_line(const GpioLineSpec& spec);

}  // namespace pathstream::hal
