// E-stop and limit switches read as levels by the task, through the board's input lines
// (hal::InputLevel), applied by the core's SwitchRules: the rules the Linux device applies to
// its edges. A level poll sees a pulse only if it lasts a main-loop pass (microseconds).
#pragma once

#include "board.hpp"
#include "pathstream/device/switch_rules.hpp"
#include "pathstream/hal/machine_lines.hpp"
#include "pins.hpp"

namespace firmware {

template <unsigned Axes>
class SwitchInputs {
    static_assert(pathstream::hal::InputLevel<pins::Input>);

public:
    /// Reads every switch and applies it to `device`. Task context, every main-loop pass.
    template <typename Device>
    void poll(Device& device) {
        const bool estop = pins::Input{board::kEstop, true}.active();
        rules_.estop(device, estop, estop);
        for (unsigned a = 0; a < Axes; ++a) {
            for (unsigned side = 0; side < 2; ++side) {
                const pins::Input in{{board::kLimitPort, board::kLimitPinFirst + 2 * a + side},
                                     true};
                const bool active = in.active();
                // An edge is a level that was not there at the last pass.
                const bool tripped = active && !was_[a][side];
                was_[a][side] = active;
                (void)rules_.limit(device, a, static_cast<pathstream::device::LimitSide>(side),
                                   tripped, active);
            }
        }
    }

private:
    pathstream::device::SwitchRules<Axes> rules_;
    bool was_[Axes][2] = {};
};

}  // namespace firmware
