// The switches of a simulated machine, played by its axes: each switch is fixed on the
// machine, so homing or `ctl position` moving the device's coordinates does not move it.
// What drives a switch's line is the caller's: an in-process input (tests, GpioBench) or a
// gpio-sim line's pull (the kernel's simulated chip, GpioSimPull).
#pragma once

#include <cstdint>
#include <functional>
#include <utility>
#include <vector>

#include "pathstream/linux_device/any_motion_device.hpp"
#include "pathstream/sim/axis_switch.hpp"
#include "pathstream/units.hpp"

namespace pathstream::sim {

/// Task context, the thread that ticks the device; host simulation only (allocates at place()).
/// A device plays them once given to AnyMotionDevice::observe_ticks.
class MachineSwitches final : public linux_device::TickObserver {
public:
    /// Called with the contact's level (true: closed, the input active) whenever it changes.
    using Line = std::function<void(bool closed)>;

    /// Adds a switch whose trigger is a machine position (the device's coordinates at the first
    /// after_tick()). Its line is driven open at once, so a stale level from an earlier run
    /// never reaches the device. Init context.
    void place(const SwitchPlacement& p, Line line) {
        switches_.push_back({AxisSwitch(p), std::move(line)});
        switches_.back().line(false);
    }

    /// After every tick: `position` holds the setpoints it output (device coordinates, one per
    /// axis), `positions_set` the device's count of applied position settings. A change of that
    /// count means the coordinates jumped while the axes stood still: the machine did not move.
    void after_tick(const Lsb* position, unsigned axes, std::uint32_t positions_set) override {
        if (offset_.size() != axes) {
            offset_.assign(axes, 0);
            last_.assign(position, position + axes);
            positions_set_ = positions_set;
        }
        if (positions_set != positions_set_) {
            for (unsigned a = 0; a < axes; ++a) offset_[a] += position[a] - last_[a];
            positions_set_ = positions_set;
        }
        last_.assign(position, position + axes);
        for (Placed& s : switches_) {
            const unsigned a = s.contact.placement().axis;
            if (a >= axes) continue;
            const bool before = s.contact.level();
            const bool now = s.contact.update(position[a] - offset_[a]);
            if (now != before) s.line(now);
        }
    }

    /// The axis's machine position after the last tick (LSB).
    Lsb machine_position(unsigned axis) const { return last_.at(axis) - offset_.at(axis); }
    std::size_t size() const { return switches_.size(); }
    const AxisSwitch& contact(std::size_t i) const { return switches_.at(i).contact; }

private:
    struct Placed {
        AxisSwitch contact;
        Line line;
    };
    std::vector<Placed> switches_;
    std::vector<Lsb> offset_;  // device coordinates minus machine coordinates, per axis
    std::vector<Lsb> last_;
    std::uint32_t positions_set_ = 0;
};

}  // namespace pathstream::sim
