// A simulated plotter with its discrete lines: MotionDevice + DeviceGpio + simulated e-stop,
// limit switches that trip at a position, and enable, pen, spindle and coolant outputs that
// record the tick of every switch. Tests drive it tick by tick.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "pathstream/device/motion_device.hpp"
#include "pathstream/linux_device/device_gpio.hpp"
#include "pathstream/sim/machine_switches.hpp"
#include "pathstream/sim/simulated_input.hpp"
#include "pathstream/sim/simulated_output.hpp"
#include "pathstream/sim/virtual_clock.hpp"

namespace pathstream::sim {

/// Tick k of a run is clock tick k (1-based after the first step): an output stamped k
/// switched right after the k-th tick.
template <unsigned Axes, std::uint32_t Capacity>
class GpioBench {
public:
    using Device = device::MotionDevice<Axes, Capacity>;

    /// A configured idle device at `start` with every line fitted; no switch placed yet.
    GpioBench(const Lsb (&start)[Axes], const device::MotionLimits<Axes>& limits)
        : device(start), glue(device, wiring()) {
        (void)device.configure(limits);
    }
    GpioBench(const GpioBench&) = delete;
    GpioBench& operator=(const GpioBench&) = delete;

    /// A switch that is active while the axis is at or beyond `trigger` (at or below for the
    /// negative side): the way a cam or an optical flag works. `trigger` is a machine position:
    /// the device's coordinates at the first step(); homing's new zero does not move it.
    void place_switch(unsigned axis, device::LimitSide side, Lsb trigger) {
        SwitchPlacement p;
        p.axis = axis;
        p.side = side;
        p.trigger = trigger;
        place_switch(p);
    }
    /// The same with hysteresis and bounce.
    void place_switch(const SwitchPlacement& p) {
        SimulatedInput& in = limit[p.axis][static_cast<unsigned>(p.side)];
        switches.place(p, [&in, this](bool closed) { in.drive(closed, clock.now()); });
    }

    /// One tick: switches follow the last setpoint, inputs are polled, the device ticks, the
    /// outputs follow the new state.
    void step() {
        if (switches.size() != 0) {
            Lsb p[Axes];
            for (unsigned a = 0; a < Axes; ++a) p[a] = device.position(a);
            switches.after_tick(p, Axes, device.status().position_applied);
        }
        glue.poll_inputs();
        Lsb out[Axes];
        device.tick(out);
        clock.wait_until(clock.now() + 1);
        glue.update_outputs();
        std::array<Lsb, Axes> row{};
        for (unsigned a = 0; a < Axes; ++a) row[a] = out[a];
        ticks.push_back(row);
        states.push_back(device.state());
    }

    /// Steps until `done()` or `max_ticks` more ticks; true when done() became true.
    template <typename Done>
    bool run_until(Done done, std::uint32_t max_ticks) {
        for (std::uint32_t i = 0; i < max_ticks; ++i) {
            if (done()) return true;
            step();
        }
        return done();
    }

    VirtualClock clock;
    Device device;
    SimulatedInput estop;
    SimulatedInput limit[Axes][2];
    SimulatedOutput enable{clock};
    SimulatedOutput pen{clock};
    SimulatedOutput spindle{clock};
    SimulatedOutput spindle_reverse{clock};
    SimulatedOutput mist{clock};
    SimulatedOutput flood{clock};
    linux_device::DeviceGpio<Axes, Capacity> glue;
    MachineSwitches switches;  ///< the switches placed, on the machine's coordinates
    std::vector<std::array<Lsb, Axes>> ticks;  ///< every tick's setpoints
    std::vector<device::DeviceState> states;   ///< the state after every tick

private:
    linux_device::DeviceWiring<Axes> wiring() {
        linux_device::DeviceWiring<Axes> w;
        w.estop = &estop;
        for (unsigned a = 0; a < Axes; ++a) {
            w.limit[a][0] = &limit[a][0];
            w.limit[a][1] = &limit[a][1];
        }
        w.enable = &enable;
        w.pen = &pen;
        SimulatedOutput* machine[device::kMachineOutputCount] = {&spindle, &spindle_reverse, &mist,
                                                                 &flood};
        for (unsigned k = 0; k < device::kMachineOutputCount; ++k) w.machine[k] = machine[k];
        return w;
    }
};

}  // namespace pathstream::sim
