// E-stop and limit switches read as levels by the task (the board profile's pins, active low
// with pull-ups). The rules are the Linux device's (gpio_logic.hpp and DeviceGpio): the e-stop
// is held from its first active level until it is released and the device has entered e-stop;
// a limit switch faults on its edge to active (or when active at the first poll), so that a
// machine standing on a switch can be moved off it after a reset.
#pragma once

#include "board.hpp"
#include "pathstream/device/gpio_logic.hpp"
#include "pathstream/device/motion_device.hpp"
#include "pins.hpp"

namespace firmware {

template <unsigned Axes>
class SwitchInputs {
public:
    /// Reads every switch and applies it to `device`. Task context, every main-loop pass.
    template <typename Device>
    void poll(Device& device) {
        const bool estop = !pins::level(board::kEstop);
        if (estop) estop_held_ = true;
        if (estop_held_ && !estop && device.state() == pathstream::device::DeviceState::kEstop)
            estop_held_ = false;
        device.set_estop_input(estop_held_);
        for (unsigned a = 0; a < Axes; ++a) {
            for (unsigned side = 0; side < 2; ++side) {
                const board::Pin pin = {stm32::kGpioE, board::kLimitPinFirst + 2 * a + side};
                const bool active = !pins::level(pin);
                if (active && (first_ || !was_[a][side])) {
                    device.raise_fault(pathstream::device::limit_fault(
                        a, static_cast<pathstream::device::LimitSide>(side)));
                }
                was_[a][side] = active;
            }
        }
        first_ = false;
    }

private:
    bool estop_held_ = false;
    bool first_ = true;
    bool was_[Axes][2] = {};
};

}  // namespace firmware
