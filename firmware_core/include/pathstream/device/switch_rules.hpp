// What the e-stop and limit-switch inputs do to the device, whatever reads them: the Linux
// glue with its queued edges (DeviceGpio) and a firmware polling levels give this class what
// they saw since their last poll, and it applies the rules once for every port.
#pragma once

#include <cstdint>

#include "pathstream/device/device_state.hpp"
#include "pathstream/device/gpio_logic.hpp"

namespace pathstream::device {

/// The switch rules for `Axes` axes. Task context (the context that polls the inputs); each
/// call is a few compares and at most one device call per switch.
template <unsigned Axes>
class SwitchRules {
public:
    /// The e-stop: `seen` it was active at some moment since the last call (its level now, or
    /// an edge to active that a pulse shorter than the poll left), `level` it is active now.
    /// Held from the first time it is seen until it is inactive and the device has entered
    /// e-stop (so the tick has taken it, however short the pulse); the device's e-stop input
    /// follows the hold.
    template <typename Device>
    void estop(Device& device, bool seen, bool level) {
        if (seen || level) estop_held_ = true;
        if (estop_held_ && !seen && !level && device.state() == DeviceState::kEstop)
            estop_held_ = false;
        device.set_estop_input(estop_held_);
    }

    /// A limit switch: `tripped` it went active since the last call (an edge to active, or
    /// active at the first call for this switch), `level` it is active now. A trip raises
    /// limit_fault(axis, side) unless the switch is masked; a switch that stays active does
    /// not fault again after a reset, so the machine can be moved off it. Returns whether it
    /// faulted. `axis` < Axes.
    template <typename Device>
    bool limit(Device& device, unsigned axis, LimitSide side, bool tripped, bool level) {
        const auto s = static_cast<unsigned>(side);
        if (!polled_[axis][s]) {
            polled_[axis][s] = true;
            tripped = tripped || level;
        }
        level_[axis][s] = level || tripped;
        if (!tripped || masked_[axis][s]) return false;
        device.raise_fault(limit_fault(axis, side));
        ++limit_trips_;
        return true;
    }

    /// Masks (or unmasks) one switch's fault: homing drives onto its own switch on purpose.
    void mask_limit(unsigned axis, LimitSide side, bool masked) {
        masked_[axis][static_cast<unsigned>(side)] = masked;
    }
    /// The switch's level at the last call (true also for a trip seen then).
    bool limit_active(unsigned axis, LimitSide side) const {
        return level_[axis][static_cast<unsigned>(side)];
    }
    bool estop_held() const { return estop_held_; }
    std::uint32_t limit_trips() const { return limit_trips_; }

private:
    bool estop_held_ = false;
    bool polled_[Axes][2] = {};
    bool masked_[Axes][2] = {};
    bool level_[Axes][2] = {};
    std::uint32_t limit_trips_ = 0;
};

}  // namespace pathstream::device
