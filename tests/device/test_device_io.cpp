// A simulated bus device wired to lines (what `pathstream device --machine` runs): the device
// configured from a profile exactly as a host would configure it, e-stop and limit switches
// through the attached DeviceIo on every tick, enable and pen driven after it, and homing of
// the profile's axes in order against simulated switches, with its errors.
#include <catch2/catch.hpp>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "pathstream/device/gpio_logic.hpp"
#include "pathstream/device/motion_device.hpp"
#include "pathstream/linux_device/can_motion_device.hpp"
#include "pathstream/linux_device/machine_homing.hpp"
#include "pathstream/linux_device/modbus_motion_device.hpp"
#include "pathstream/machine/device_setup.hpp"
#include "pathstream/machine/machine.hpp"
#include "pathstream/sim/simulated_input.hpp"
#include "pathstream/sim/simulated_output.hpp"
#include "pathstream/sim/virtual_clock.hpp"

using namespace pathstream;
using device::DeviceState;
using device::LimitSide;

namespace {

// x homes to x- at 0 mm (switch at physical 10 mm), y to y+ (switch at physical 50 mm) at
// 200 mm; 1 um per LSB.
const char* kProfile = R"({
  "axes": [{"name": "x", "max_velocity": 200, "max_acceleration": 2000},
           {"name": "y", "max_velocity": 200, "max_acceleration": 2000}],
  "gpio": {
    "chip": "unused-in-this-test",
    "enable": {"line": 1}, "pen": {"line": 0}, "estop": {"line": 2},
    "limits": {"x-": {"line": 3}, "y+": {"line": 4}},
    "home": {
      "x": {"switch": "x-", "search_velocity": 20, "latch_velocity": 1, "backoff": 1, "max_travel": 40},
      "y": {"switch": "y+", "search_velocity": 20, "latch_velocity": 1, "backoff": 1, "max_travel": 40,
            "position": 200, "pull_off": 0.5}
    }
  }
})";

// The simulated machine around a device: switches at physical positions (the device's
// coordinates change when homing sets zero; `offset` maps them back).
struct Machine {
    explicit Machine(std::unique_ptr<linux_device::AnyMotionDevice> d) : dev(std::move(d)) {
        wiring.estop = &estop;
        wiring.limit[0][0] = &x_min;
        wiring.limit[1][1] = &y_max;
        wiring.enable = &enable;
        wiring.pen = &pen;
    }

    // Switch levels from the last setpoint, then one tick.
    void tick() {
        const Lsb x = dev->position(0) - offset[0], y = dev->position(1) - offset[1];
        x_min.drive(x <= x_switch, clock.now());
        y_max.drive(y >= y_switch, clock.now());
        const Lsb before[2] = {dev->position(0), dev->position(1)};
        const bool idle_before = dev->state() == (DeviceState::kIdle);
        dev->tick();
        clock.wait_until(clock.now() + 1);
        // An idle device moves only by set_position (homing's set zero): the coordinates
        // moved, the machine did not.
        if (idle_before && dev->state() == (DeviceState::kIdle)) {
            offset[0] += dev->position(0) - before[0];
            offset[1] += dev->position(1) - before[1];
        }
    }

    linux_device::RunTicksUntil run_until(std::uint64_t max_ticks) {
        return [this, max_ticks](const std::function<bool()>& done) {
            for (std::uint64_t k = 0; k < max_ticks; ++k) {
                if (done()) return true;
                tick();
            }
            return done();
        };
    }

    std::unique_ptr<linux_device::AnyMotionDevice> dev;
    sim::VirtualClock clock;
    sim::SimulatedInput estop, x_min, y_max;
    sim::SimulatedOutput enable{clock}, pen{clock};
    linux_device::MachineWiring wiring;
    linux_device::DeviceIo* io = nullptr;
    Lsb x_switch = 10000, y_switch = 50000;
    Lsb offset[2] = {0, 0};
};

host::MachineProfile profile() {
    return host::parse_machine_profile(kProfile, "m.json");
}

std::unique_ptr<linux_device::AnyMotionDevice> modbus_device(Lsb x, Lsb y) {
    return linux_device::ModbusMotionDevice::create({x, y});
}

}  // namespace

TEST_CASE("device setup: limits and homing in LSB from the profile", "[host][gpio][homing]") {
    const host::MachineProfile p = profile();
    const host::DeviceLimitsLsb l = host::device_limits(p);
    CHECK(l.tick_hz == 1000);
    CHECK(l.max_velocity == std::vector<std::uint32_t>{200000, 200000});
    CHECK(l.max_acceleration == std::vector<std::uint32_t>{2000000, 2000000});
    const auto h = host::homing_setups(p);
    REQUIRE(h.size() == 2);
    CHECK(h[0].axis_name == "x");
    CHECK(h[0].side == LimitSide::kNegative);
    CHECK_FALSE(h[0].config.toward_positive);
    CHECK(h[0].config.search_velocity == 20000);
    CHECK(h[0].config.latch_velocity == 1000);
    CHECK(h[0].config.backoff == 1000);
    CHECK(h[0].config.max_travel == 40000);
    CHECK(h[0].config.pull_off == 1000);  // default: the backoff
    CHECK(h[1].config.axis == 1);
    CHECK(h[1].config.toward_positive);
    CHECK(h[1].config.home_position == 200000);
    CHECK(h[1].config.pull_off == 500);
    host::MachineProfile huge = p;
    huge.axes[0].max_velocity = 5e6;  // 5e9 LSB/s
    CHECK_THROWS_WITH(host::device_limits(huge), Catch::Contains("axis x max_velocity"));
}

TEST_CASE(
    "device io: the configured device is the one a host would configure, e-stop and limits act per "
    "tick",
    "[host][gpio]") {
    for (bool can : {false, true}) {
        Machine m(can ? std::unique_ptr<linux_device::AnyMotionDevice>(
                            linux_device::CanMotionDevice::create({20000, 0}, 1))
                      : modbus_device(20000, 0));
        REQUIRE(m.dev->configure(host::device_limits(profile())) == Status::kOk);
        CHECK(m.dev->tick_hz() == 1000);
        m.io = &m.dev->attach_io(m.wiring);
        m.tick();
        CHECK_FALSE(m.enable.state());
        // A limit switch: the next tick faults, naming the axis and side.
        m.x_switch = 30000;  // now the machine stands on x-
        m.tick();
        m.tick();
        CHECK(m.io->limit_trips() == 1);
        CHECK(m.dev->state() == (DeviceState::kFault));
        CHECK(m.dev->fault_code() ==
              static_cast<std::uint16_t>(device::limit_fault(0, LimitSide::kNegative)));
        // The e-stop overrides the fault: the next tick enters e-stop.
        m.estop.drive(true);
        m.tick();
        CHECK(m.dev->state() == (DeviceState::kEstop));
        CHECK(m.io->estop_edges() == 1);
        CHECK_FALSE(m.enable.state());
    }
}

TEST_CASE("device io: homing x then y from the profile, pulled off the switches",
          "[host][gpio][homing]") {
    for (bool can : {false, true}) {
        Machine m(can ? std::unique_ptr<linux_device::AnyMotionDevice>(
                            linux_device::CanMotionDevice::create({25000, 30000}, 1))
                      : modbus_device(25000, 30000));
        const host::MachineProfile p = profile();
        REQUIRE(m.dev->configure(host::device_limits(p)) == Status::kOk);
        m.io = &m.dev->attach_io(m.wiring);
        std::vector<std::string> log;
        bool enable_seen = false;
        auto run = m.run_until(400000);
        const auto homed = linux_device::home_axes(
            *m.dev, *m.io, host::homing_setups(p), p.mm_per_lsb,
            [&](const std::function<bool()>& done) {
                return run([&] {
                    enable_seen = enable_seen || m.enable.state();
                    return done();
                });
            },
            [&](const std::string& line) { log.push_back(line); });
        REQUIRE(homed.size() == 2);
        CHECK(enable_seen);
        CHECK_FALSE(m.enable.state());
        CHECK(m.dev->state() == (DeviceState::kIdle));
        CHECK(m.io->limit_trips() == 0);  // the homing switch was masked, the other never hit
        // The latch saw each switch within one tick at latch velocity (1 LSB/tick + the poll).
        CHECK(homed[0].latch <= 10000);
        CHECK(homed[0].latch >= 10000 - 2);
        CHECK(homed[1].latch >= 50000);
        CHECK(homed[1].latch <= 50000 + 2);
        // x: the switch point is 0 now and the axis rests pull_off (1 mm) off it, beyond the
        // latch stop's overrun; y: the switch point is 200 mm, the axis 0.5 mm below it.
        const Lsb x_overrun = homed[0].latch - (m.dev->position(0) - m.offset[0] - 1000);
        CHECK(m.dev->position(0) == 1000 - x_overrun);
        CHECK(m.dev->position(0) - m.offset[0] > m.x_switch);  // physically off the switch
        CHECK(m.dev->position(1) - m.offset[1] < m.y_switch);
        CHECK(m.dev->position(1) < 200000);
        CHECK(m.dev->position(1) > 200000 - 600);
        CHECK(log.front().find(
                  "homing x toward switch x-: search at 20.000 mm/s for at most 40.000 mm") == 0);
        bool latch_logged = false;
        for (const auto& l : log)
            latch_logged = latch_logged || l.find("y: approaching slowly") != std::string::npos;
        CHECK(latch_logged);
        // The homing switch is armed again: the machine on it (here: the switch moved under it)
        // faults, naming it.
        m.x_switch = m.dev->position(0) - m.offset[0] + 5;
        m.tick();
        m.tick();
        CHECK(m.dev->fault_code() ==
              static_cast<std::uint16_t>(device::limit_fault(0, LimitSide::kNegative)));
    }
}

TEST_CASE("device io: homing errors name the axis, the switch and the reason",
          "[host][gpio][homing]") {
    const host::MachineProfile p = profile();
    auto start = [&](Machine& m) {
        REQUIRE(m.dev->configure(host::device_limits(p)) == Status::kOk);
        m.io = &m.dev->attach_io(m.wiring);
    };
    const auto quiet = [](const std::string&) {};
    SECTION("no switch within max_travel") {
        Machine m(modbus_device(25000, 0));
        start(m);
        m.x_switch = -100000;
        CHECK_THROWS_WITH(linux_device::home_axes(*m.dev, *m.io, host::homing_setups(p),
                                                  p.mm_per_lsb, m.run_until(400000), quiet),
                          "homing x: switch x- not found within 40.000 mm (max_travel)");
        CHECK(m.dev->state() == (DeviceState::kIdle));
        CHECK(m.dev->position(0) == 25000 - 40000);
    }
    SECTION("a switch that never releases") {
        Machine m(modbus_device(25000, 0));
        start(m);
        m.x_switch = 1000000;
        CHECK_THROWS_WITH(
            linux_device::home_axes(*m.dev, *m.io, host::homing_setups(p), p.mm_per_lsb,
                                    m.run_until(400000), quiet),
            Catch::StartsWith("homing x: switch x- still active after moving off it"));
    }
    SECTION("the e-stop during homing") {
        Machine m(modbus_device(25000, 0));
        start(m);
        std::uint64_t ticks = 0;
        auto run = m.run_until(400000);
        CHECK_THROWS_WITH(linux_device::home_axes(
                              *m.dev, *m.io, host::homing_setups(p), p.mm_per_lsb,
                              [&](const std::function<bool()>& done) {
                                  return run([&] {
                                      if (++ticks == 200) m.estop.drive(true);
                                      return done();
                                  });
                              },
                              quiet),
                          "homing x: interrupted by the e-stop");
        CHECK(m.dev->state() == (DeviceState::kEstop));
    }
    SECTION("a homing switch that is not wired") {
        Machine m(modbus_device(25000, 0));
        m.wiring.limit[0][0] = nullptr;
        start(m);
        CHECK_THROWS_WITH(linux_device::home_axes(*m.dev, *m.io, host::homing_setups(p),
                                                  p.mm_per_lsb, m.run_until(1000), quiet),
                          "homing x: switch x- is not wired");
    }
    SECTION("an unconfigured device") {
        Machine m(modbus_device(25000, 0));
        m.io = &m.dev->attach_io(m.wiring);
        CHECK_THROWS_WITH(
            linux_device::home_axes(*m.dev, *m.io, host::homing_setups(p), p.mm_per_lsb,
                                    m.run_until(1000), quiet),
            "homing x: the device refused a homing step: device limits not configured");
    }
}
