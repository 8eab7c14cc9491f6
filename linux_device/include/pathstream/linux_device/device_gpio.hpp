// The I/O glue between a MotionDevice and its discrete lines: e-stop and limit-switch inputs
// in, enable, pen-lift, spindle and coolant outputs out. The rules are firmware_core's
// (gpio_logic.hpp, switch_rules.hpp: the firmware applies the same ones); this class only moves
// levels, edges and requests between the hal interfaces and the device. The same code runs against
// the simulated lines (tests) and libgpiod (the VM test's driver).
#pragma once

#include <cstdint>

#include "pathstream/device/gpio_logic.hpp"
#include "pathstream/device/motion_device.hpp"
#include "pathstream/device/switch_rules.hpp"
#include "pathstream/hal/gpio.hpp"

namespace pathstream::linux_device {

/// Which line does what; a null pointer means "not fitted".
template <unsigned Axes>
struct DeviceWiring {
    hal::DigitalInput* estop = nullptr;
    hal::DigitalInput* limit[Axes][2] = {};  ///< [axis][LimitSide]
    hal::DigitalOutput* enable = nullptr;
    hal::DigitalOutput* pen = nullptr;
    /// Spindle, spindle direction, mist, flood: by device::kMachineOutputBits index.
    hal::DigitalOutput* machine[device::kMachineOutputCount] = {};
};

/// Task-side glue. Call poll_inputs() before each tick (or whenever an input's event_fd is
/// readable) and update_outputs() after each tick.
template <unsigned Axes, std::uint32_t Capacity>
class DeviceGpio {
public:
    using Device = device::MotionDevice<Axes, Capacity>;

    /// `device` and every line in `wiring` must outlive this object. Drives the outputs to
    /// the device's current state at once (enable off for an idle device).
    DeviceGpio(Device& device, const DeviceWiring<Axes>& wiring)
        : device_(device), wiring_(wiring) {
        update_outputs();
    }

    /// Drains every input's edges and applies them:
    /// * e-stop: an edge to active requests the e-stop at once (a pulse shorter than a poll
    ///   still counts); the input is reported released only when the line is inactive and
    ///   the device has entered kEstop (so the tick has seen it).
    /// * limit switch: an edge to active (or a switch already active at the first poll) raises
    ///   limit_fault(axis, side), unless masked (the switch homing is looking for). A switch
    ///   that stays active does not fault again after a reset, so the machine can move off it.
    void poll_inputs() {
        if (wiring_.estop != nullptr) {
            hal::InputEdge e;
            bool activated = false;
            while (wiring_.estop->next_edge(e)) {
                if (e.active) {
                    activated = true;
                    last_estop_edge_ns_ = e.timestamp_ns;
                    ++estop_edges_;
                }
            }
            rules_.estop(device_, activated, wiring_.estop->active());
        }
        for (unsigned a = 0; a < Axes; ++a) {
            for (unsigned side = 0; side < 2; ++side) {
                hal::DigitalInput* in = wiring_.limit[a][side];
                if (in == nullptr) continue;
                hal::InputEdge e;
                bool tripped = false;
                while (in->next_edge(e)) tripped = tripped || e.active;
                (void)rules_.limit(device_, a, static_cast<device::LimitSide>(side), tripped,
                                   in->active());
            }
        }
    }

    /// Drives enable, pen and the machine functions (spindle, its direction, mist, flood)
    /// from the state the last tick left. Cheap: each output switches only on a change (one
    /// ioctl with libgpiod).
    void update_outputs() {
        const device::DeviceState s = device_.state();
        const std::uint8_t outputs = device_.outputs();
        if (wiring_.enable != nullptr) wiring_.enable->set(device::enable_asserted(s));
        if (wiring_.pen != nullptr) wiring_.pen->set(device::pen_down(s, outputs));
        for (unsigned k = 0; k < device::kMachineOutputCount; ++k) {
            if (wiring_.machine[k] != nullptr)
                wiring_.machine[k]->set(
                    device::machine_output_on(s, outputs, device::kMachineOutputBits[k]));
        }
    }

    /// Masks (or unmasks) one switch's fault: homing drives onto its own switch on purpose.
    void mask_limit(unsigned axis, device::LimitSide side, bool masked) {
        rules_.mask_limit(axis, side, masked);
    }
    /// The switch's level seen by the last poll_inputs (true also for a pulse seen then).
    bool limit_active(unsigned axis, device::LimitSide side) const {
        return rules_.limit_active(axis, side);
    }
    std::uint32_t estop_edges() const { return estop_edges_; }
    std::uint32_t limit_trips() const { return rules_.limit_trips(); }
    /// Timestamp of the last activating e-stop edge (backend clock, ns; 0 if none).
    std::uint64_t last_estop_edge_ns() const { return last_estop_edge_ns_; }

private:
    Device& device_;
    DeviceWiring<Axes> wiring_;
    device::SwitchRules<Axes> rules_;
    std::uint32_t estop_edges_ = 0;
    std::uint64_t last_estop_edge_ns_ = 0;
};

}  // namespace pathstream::linux_device
