// Homing and the operator's pen as bus commands (`pathstream ctl TARGET home`, `pen`): the
// simulated device with limit switches placed on a physical axis, served over Modbus TCP and
// native CAN. Checked: every axis of a run homed in plan order with zero where its switch is,
// every tick within the velocity and acceleration limits, the refusals while homing, a failed
// axis reported by name, and a pen lowered by the operator carried by a jog.
#include <array>
#include <atomic>
#include <catch2/catch.hpp>
#include <chrono>
#include <cmath>
#include <memory>
#include <thread>
#include <vector>

#include "pathstream/device/operator_commands.hpp"
#include "pathstream/hal/modbus_server.hpp"
#include "pathstream/host/can_stream.hpp"
#include "pathstream/host/device_link.hpp"
#include "pathstream/linux_device/can_motion_device.hpp"
#include "pathstream/linux_device/modbus_motion_device.hpp"
#include "pathstream/sim/can_loopback.hpp"
#include "pathstream/sim/machine_switches.hpp"
#include "pathstream/sim/simulated_input.hpp"

using namespace pathstream;
using device::AxisHoming;
using device::DeviceState;
using device::HomingError;
using device::LimitSide;

namespace {

constexpr unsigned kAxes = 2;
constexpr std::uint32_t kTickHz = 1000;
constexpr std::uint32_t kMaxVelocity = 100000;       // LSB/s
constexpr std::uint32_t kMaxAcceleration = 1000000;  // LSB/s^2

host::DeviceLimitsLsb limits() {
    host::DeviceLimitsLsb l;
    l.tick_hz = kTickHz;
    l.max_velocity = {kMaxVelocity, kMaxVelocity};
    l.max_acceleration = {kMaxAcceleration, kMaxAcceleration};
    return l;
}

device::HomingAxis homing_axis(unsigned axis, std::uint32_t max_travel) {
    device::HomingAxis h;
    h.config.axis = axis;
    h.config.search_velocity = 40000;
    h.config.latch_velocity = 2000;
    h.config.backoff = 2000;
    h.config.max_travel = max_travel;
    h.config.pull_off = 1000;
    h.side = LimitSide::kNegative;
    return h;
}

// One tick as recorded by the rig.
struct TickRow {
    std::array<Lsb, kAxes> position{};
    DeviceState state = DeviceState::kIdle;
};

// The simulated device on a physical machine: each axis's negative switch closes at a fixed
// physical point. The device's coordinates move against the physical ones where it redefines
// its position at rest (homing's zero), which the rig follows, as the real machine would.
// Ticks, switches and the bus all run on the device thread.
class HomingRig {
public:
    // Physical and device coordinates agree at the start.
    explicit HomingRig(linux_device::AnyMotionDevice& device) : device_(device) {
        REQUIRE(device.configure(limits()) == Status::kOk);
        device.record(true);
        linux_device::MachineWiring w;
        for (unsigned a = 0; a < kAxes; ++a) w.limit[a][0] = &switches_[a];
        io_ = &device.attach_io(w);
        device.observe_ticks(&machine_switches_);
    }

    // The switch of `axis` closes at physical `point` and below; none: it never closes. The
    // device plays it after every tick (sim::MachineSwitches).
    void place_switch(unsigned axis, Lsb point) {
        sim::SwitchPlacement p;
        p.axis = axis;
        p.side = device::LimitSide::kNegative;
        p.trigger = point;
        sim::SimulatedInput& in = switches_[axis];
        machine_switches_.place(p, [&in](bool closed) { in.drive(closed); });
    }
    linux_device::DeviceIo& io() { return *io_; }

    // One tick with the switches following the physical position.
    void tick() {
        const auto before_state = static_cast<DeviceState>(device_.state());
        std::array<Lsb, kAxes> before{};
        for (unsigned a = 0; a < kAxes; ++a) before[a] = device_.position(a);
        device_.tick();
        TickRow row;
        row.state = static_cast<DeviceState>(device_.state());
        for (unsigned a = 0; a < kAxes; ++a) row.position[a] = device_.position(a);
        // A position that changes idle at rest is redefined, not moved.
        if (before_state == DeviceState::kIdle && row.state == DeviceState::kIdle) {
            for (unsigned a = 0; a < kAxes; ++a) {
                if (row.position[a] != before[a]) ++redefinitions_[a];
            }
        }
        rows_.push_back(row);
    }

    // Where the device's coordinates put physical point `point` of `axis` now.
    Lsb device_coordinate(unsigned axis, Lsb point) const {
        return point + device_.position(axis) - machine_switches_.machine_position(axis);
    }
    unsigned redefinitions(unsigned axis) const { return redefinitions_[axis]; }
    const std::vector<TickRow>& rows() const { return rows_; }

    // Every tick's step within the velocity limit and every change of step within the
    // acceleration limit (exact integer spans: at most one LSB of rounding each), except
    // across a redefinition.
    void check_limits() const {
        const double max_step = static_cast<double>(kMaxVelocity) / kTickHz + 1.0;
        const double max_change = static_cast<double>(kMaxAcceleration) / kTickHz / kTickHz + 2.0;
        for (unsigned a = 0; a < kAxes; ++a) {
            double last_step = 0;
            for (std::size_t k = 1; k < rows_.size(); ++k) {
                const double step =
                    static_cast<double>(rows_[k].position[a]) - rows_[k - 1].position[a];
                if (rows_[k].state == DeviceState::kIdle &&
                    rows_[k - 1].state == DeviceState::kIdle) {
                    last_step = 0;
                    continue;
                }
                INFO("axis " << a << " tick " << k);
                REQUIRE(std::abs(step) <= max_step);
                REQUIRE(std::abs(step - last_step) <= max_change);
                last_step = step;
            }
        }
    }

private:
    linux_device::AnyMotionDevice& device_;
    linux_device::DeviceIo* io_ = nullptr;
    sim::SimulatedInput switches_[kAxes];
    sim::MachineSwitches machine_switches_;
    unsigned redefinitions_[kAxes] = {};
    std::vector<TickRow> rows_;
};

// A Modbus TCP device with the rig, ticked fast on its own thread.
struct ModbusRig {
    std::unique_ptr<linux_device::ModbusMotionDevice> device;
    std::unique_ptr<HomingRig> rig;
    std::unique_ptr<hal::ModbusServer> server;
    std::atomic<bool> stop{false};
    std::thread thread;

    explicit ModbusRig(const std::vector<Lsb>& start) {
        device = linux_device::ModbusMotionDevice::create(start);
        rig = std::make_unique<HomingRig>(*device);
        server = std::make_unique<hal::ModbusServer>(
            hal::ModbusServer::tcp(device->handler(), {"127.0.0.1", 0, 4}));
    }
    void run() {
        thread = std::thread([this] {
            linux_device::DeviceLoopOptions o;
            o.time_scale = 20.0;
            linux_device::run_paced_loop([&] { rig->tick(); }, [&] { return device->tick_hz(); },
                                         [&](std::chrono::microseconds w) { server->poll_once(w); },
                                         o, stop);
        });
    }
    std::string target() const {
        return "modbus-tcp://127.0.0.1:" + std::to_string(server->port()) + "?unit=1";
    }
    void join() {
        stop = true;
        if (thread.joinable()) thread.join();
    }
    ~ModbusRig() { join(); }
};

// Reads the status until `done` or 30 s.
template <typename Done>
host::DeviceSnapshot poll_until(host::DeviceLink& link, Done done) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    host::DeviceSnapshot s = link.status();
    while (!done(s) && std::chrono::steady_clock::now() < deadline) {
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
        s = link.status();
    }
    REQUIRE(done(s));
    return s;
}

}  // namespace

TEST_CASE("home over Modbus: every axis in plan order, zero at its switch, within the limits",
          "[homing][modbus][threads]") {
    const std::vector<Lsb> start = {20000, 15000};
    ModbusRig m(start);
    m.rig->place_switch(0, -3000);
    m.rig->place_switch(1, -2000);
    const device::HomingAxis plan[] = {homing_axis(1, 300000),
                                       homing_axis(0, 300000)};  // y, then x
    REQUIRE(m.rig->io().set_homing_plan(plan, 2) == Status::kOk);
    m.run();
    const std::unique_ptr<host::DeviceLink> link = host::open_device_link(m.target(), {});
    host::DeviceSnapshot s = link->status();
    CHECK(
        (s.homing[0].state == AxisHoming::kNotHomed && s.homing[1].state == AxisHoming::kNotHomed));
    // Axis 2 does not exist; a value or feed is no argument of home.
    CHECK(link->command_with_arguments(device::kCommandHome, 4, 0, 0) ==
          Status::kControlValueOutOfRange);
    CHECK(link->command_with_arguments(device::kCommandHome, 0, 1, 0) ==
          Status::kControlValueOutOfRange);
    REQUIRE(link->command_with_arguments(device::kCommandHome, 0, 0, 0) == Status::kOk);
    s = link->status();
    REQUIRE(s.homing_runs());
    CHECK((s.homing[0].state == AxisHoming::kHoming && s.homing[1].state == AxisHoming::kHoming));
    // While homing nothing else may move the machine or redefine its position.
    CHECK(link->command_with_arguments(device::kCommandHome, 0, 0, 0) == Status::kWrongState);
    CHECK(link->command_with_arguments(device::kCommandJog, 0, 100, 0) == Status::kWrongState);
    CHECK(link->command_with_arguments(device::kCommandPen, 0, 1, 0) == Status::kWrongState);
    CHECK(link->command_with_arguments(device::kCommandSetPosition, 0, 0, 0) ==
          Status::kWrongState);
    // y first: x waits its turn while y moves.
    s = poll_until(*link, [](const host::DeviceSnapshot& x) {
        return x.homing[1].state != AxisHoming::kHoming;
    });
    CHECK(s.homing[1].state == AxisHoming::kHomed);
    s = poll_until(*link, [](const host::DeviceSnapshot& x) { return !x.homing_runs(); });
    CHECK((s.homing[0].state == AxisHoming::kHomed && s.homing[0].error == HomingError::kNone));
    CHECK(s.homing[1].state == AxisHoming::kHomed);
    CHECK(s.state == device::DeviceState::kIdle);
    // Both pulled 1000 LSB off where the latch stop came to rest (a few LSB past the switch
    // point, which is now 0: the stop from latch velocity overshoots by some 20 LSB).
    const Lsb homed_x = s.position[0];
    INFO("at " << s.position[0] << ", " << s.position[1]);
    CHECK((s.position[0] >= 950 && s.position[0] <= 1000 && s.position[1] >= 950 &&
           s.position[1] <= 1000));

    // The pen by the operator: down at rest, carried by a jog, up again.
    REQUIRE(link->command_with_arguments(device::kCommandPen, 0, 1, 0) == Status::kOk);
    s = poll_until(*link, [](const host::DeviceSnapshot& x) { return x.pen_down(); });
    CHECK(link->command_with_arguments(device::kCommandPen, 0, 2, 0) ==
          Status::kControlValueOutOfRange);
    REQUIRE(link->command_with_arguments(device::kCommandJog, 0, 5000, 0) == Status::kOk);
    const std::uint32_t jog = s.last_accepted + 1;
    s = poll_until(*link, [&](const host::DeviceSnapshot& x) {
        return x.state == device::DeviceState::kIdle && x.finished_job == jog;
    });
    CHECK((s.position[0] == homed_x + 5000 && s.pen_down()));
    const std::size_t jog_ticks = s.finished_job_ticks;
    REQUIRE(link->command_with_arguments(device::kCommandPen, 0, 0, 0) == Status::kOk);
    s = poll_until(*link, [](const host::DeviceSnapshot& x) { return !x.pen_down(); });
    m.join();

    // Each axis's zero was set once, where its switch is (the slow approach sees it within
    // one tick of latch velocity, 2 LSB), and every tick kept the limits.
    for (unsigned a = 0; a < kAxes; ++a) {
        INFO("axis " << a);
        CHECK(m.rig->redefinitions(a) == 1);
        CHECK(std::abs(m.rig->device_coordinate(a, a == 0 ? -3000 : -2000)) <= 2);
    }
    m.rig->check_limits();
    // The path ticks: the homing moves' with the pen up, then the jog's, every one pen down.
    const auto& ticks = m.device->recorded_ticks();
    REQUIRE(ticks.size() > jog_ticks);
    for (std::size_t k = 0; k < ticks.size(); ++k) {
        INFO("path tick " << k << " of " << ticks.size());
        REQUIRE(((ticks[k].outputs & kOutputPenDown) != 0) == (k >= ticks.size() - jog_ticks));
    }
}

TEST_CASE("home over Modbus: an axis whose switch never closes fails by name, the run ends",
          "[homing][modbus][threads]") {
    const std::vector<Lsb> start = {20000, 15000};
    ModbusRig m(start);
    m.rig->place_switch(0, -3000);  // y has no switch that ever closes
    const device::HomingAxis plan[] = {homing_axis(1, 20000), homing_axis(0, 300000)};
    REQUIRE(m.rig->io().set_homing_plan(plan, 2) == Status::kOk);
    m.run();
    const std::unique_ptr<host::DeviceLink> link = host::open_device_link(m.target(), {});
    REQUIRE(link->command_with_arguments(device::kCommandHome, 0, 0, 0) == Status::kOk);
    const host::DeviceSnapshot s =
        poll_until(*link, [](const host::DeviceSnapshot& x) { return !x.homing_runs(); });
    CHECK((s.homing[1].state == AxisHoming::kFailed &&
           s.homing[1].error == HomingError::kSwitchNotFound));
    CHECK(s.homing[0].state == AxisHoming::kNotHomed);  // after y failed, x never started
    CHECK(s.state == device::DeviceState::kIdle);
    CHECK(s.position[1] == 15000 - 20000);  // the whole max_travel searched, then stopped
    // x alone (mask bit 0) homes.
    REQUIRE(link->command_with_arguments(device::kCommandHome, 1, 0, 0) == Status::kOk);
    const host::DeviceSnapshot x =
        poll_until(*link, [](const host::DeviceSnapshot& y) { return !y.homing_runs(); });
    CHECK((x.homing[0].state == AxisHoming::kHomed && x.homing[1].state == AxisHoming::kFailed));
    m.join();
    m.rig->check_limits();
}

TEST_CASE("home and pen over native CAN: status E reports each axis, status A the pen",
          "[homing][can][threads]") {
    const std::vector<Lsb> start = {20000, 15000};
    sim::CanLoopback loop;
    hal::CanBus& device_bus = loop.add_endpoint();
    hal::CanBus& host_bus = loop.add_endpoint();
    std::unique_ptr<linux_device::CanMotionDevice> device =
        linux_device::CanMotionDevice::create(start, 7);
    HomingRig rig(*device);
    rig.place_switch(0, -3000);
    const device::HomingAxis plan[] = {homing_axis(0, 300000)};
    REQUIRE(rig.io().set_homing_plan(plan, 1) == Status::kOk);
    std::atomic<bool> stop{false};
    std::thread t([&] {
        linux_device::DeviceLoopOptions o;
        o.time_scale = 20.0;
        linux_device::run_paced_loop(
            [&] { rig.tick(); }, [&] { return device->tick_hz(); },
            [&](std::chrono::microseconds w) { device->serve(device_bus, w); }, o, stop);
    });
    host::CanStreamOptions c;
    c.node = 7;
    c.ack_timeout_ms = 30;
    c.name = "can://loop?node=7";
    const std::unique_ptr<host::DeviceLink> link = host::open_can_link(host_bus, c);
    CHECK(link->command_with_arguments(device::kCommandHome, 2, 0, 0) ==
          Status::kNoHoming);  // y: no switch
    REQUIRE(link->command_with_arguments(device::kCommandHome, 0, 0, 0) == Status::kOk);
    // Until x's homing has ended: a status read before the device took the command shows no
    // homing running either (a loaded machine saw that).
    host::DeviceSnapshot s = poll_until(*link, [](const host::DeviceSnapshot& x) {
        return !x.homing_runs() && (x.homing[0].state == AxisHoming::kHomed ||
                                    x.homing[0].state == AxisHoming::kFailed);
    });
    CHECK((s.homing[0].state == AxisHoming::kHomed && s.homing[1].state == AxisHoming::kNotHomed));
    CHECK((s.position[0] >= 950 && s.position[0] <= 1000 && s.position[1] == 15000));
    REQUIRE(link->command_with_arguments(device::kCommandPen, 0, 1, 0) == Status::kOk);
    s = poll_until(*link, [](const host::DeviceSnapshot& x) { return x.pen_down(); });
    // A stop raises the operator's pen.
    REQUIRE(link->command(device::Command::kStop) == Status::kOk);
    s = poll_until(*link, [](const host::DeviceSnapshot& x) { return !x.pen_down(); });
    stop = true;
    t.join();
    CHECK(std::abs(rig.device_coordinate(0, -3000)) <= 2);
    rig.check_limits();
}
