// The machine functions on a Modbus I/O module's coils (linux_device/output_coils.hpp) against
// a real server: sim::CoilModule is libmodbus's own, on loopback, recording every change. A
// MotionDevice plays jobs with the spindle and flood on; the coils follow (on, kept through a
// hold, off at the job's end), first written from the ticking thread itself (deterministic),
// then by the writer thread: a module that holds its answers delays no tick, and a module that
// is gone faults the device (kOutputFailed) with a message naming the target and the coil.
#include <catch2/catch.hpp>
#include <cstdint>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "pathstream/device/axis_move.hpp"
#include "pathstream/device/gpio_logic.hpp"
#include "pathstream/device/motion_device.hpp"
#include "pathstream/device/wire_span.hpp"
#include "pathstream/hal/modbus_error.hpp"
#include "pathstream/linux_device/output_coils.hpp"
#include "pathstream/sim/coil_module.hpp"

using namespace pathstream;
using device::Command;
using device::DeviceState;
using device::FaultCode;
using linux_device::CoilWriter;
using linux_device::OutputCoilThread;
using sim::CoilModule;
using std::chrono::milliseconds;

namespace {

constexpr unsigned kAxes = 2;
using Device = device::MotionDevice<kAxes, 64>;
constexpr std::uint8_t kCutting = kOutputSpindle | kOutputFlood;
// Generous bounds for another thread to catch up: a loaded machine, never a measurement.
constexpr milliseconds kPatience{20000};

device::MotionLimits<kAxes> limits() {
    device::MotionLimits<kAxes> l;
    l.tick_hz = 1000;
    for (auto& a : l.axis) a = {200000, 2000000};
    return l;
}

// Spindle 0, spindle_reverse 1, mist 2, flood 3 (consecutive: one FC15 per change), or
// `coils` in kMachineFunctionKeys order.
host::OutputCoilsConfig config_for(const CoilModule& module,
                                   std::vector<std::int32_t> coils = {0, 1, 2, 3}) {
    host::OutputCoilsConfig c;
    c.present = true;
    c.target = module.url();
    for (unsigned k = 0; k < host::kMachineFunctionCount; ++k) c.coil[k] = coils[k];
    return c;
}

// Queues a job: a move of `distance` LSB on x with `outputs`, ending (kWireJobEnd) at rest.
void queue_job(Device& d, std::int64_t distance, std::uint8_t outputs) {
    Lsb from[kAxes];
    for (unsigned a = 0; a < kAxes; ++a) from[a] = d.position(a);
    device::AxisMove<kAxes> m;
    REQUIRE(m.plan(from, 0, distance, 100000, d.limits()) == Status::kOk);
    while (m.pending()) {
        device::WireSpan w;
        REQUIRE(m.next(w));
        w.outputs = outputs;
        if (!m.pending()) w.flags = static_cast<std::uint8_t>(w.flags | device::kWireJobEnd);
        std::uint8_t bytes[4 + 12 * kAxes];
        const std::size_t n = device::encode_wire_span(w, kAxes, bytes, sizeof bytes);
        REQUIRE(d.accept_batch(d.last_accepted_sequence() + 1, 1, bytes, n) == Status::kOk);
    }
}

// The module's changes as (coil, on) in order.
using Levels = std::vector<std::pair<std::uint16_t, bool>>;
Levels levels(const std::vector<CoilModule::Change>& changes) {
    Levels out;
    for (const CoilModule::Change& x : changes) out.emplace_back(x.coil, x.on);
    return out;
}

}  // namespace

TEST_CASE("output coils: a job's spindle and flood, written from the ticking thread",
          "[coils][outputs][threads]") {
    // The module runs in its thread; the writer and the device share the test's, so every
    // write is done when apply() returns.
    const Lsb start[kAxes] = {0, 0};
    Device d(start);
    REQUIRE(d.configure(limits()) == Status::kOk);
    CoilModule module(16);
    CoilWriter writer(config_for(module));
    CHECK_FALSE(writer.known());
    writer.apply(0);  // every coil off: one FC15 of coils 0..3
    CHECK(writer.known());
    CHECK(module.write_requests() == 1);
    CHECK(module.changes().empty());
    const auto tick = [&] {
        Lsb out[kAxes];
        d.tick(out);
        writer.apply(device::machine_outputs_on(d.state(), d.outputs()));
    };
    queue_job(d, 30000, kCutting);
    tick();
    CHECK(module.write_requests() == 1);  // idle with a job queued: nothing to write
    REQUIRE(d.command(Command::kStart) == Status::kOk);
    tick();
    CHECK(module.coil(0));
    CHECK(module.coil(3));
    CHECK_FALSE(module.coil(1));
    CHECK_FALSE(module.coil(2));
    CHECK(module.write_requests() == 2);  // both in one FC15
    for (int i = 0; i < 100; ++i) tick();
    REQUIRE(d.command(Command::kHold) == Status::kOk);
    for (int i = 0; i < 500; ++i) tick();
    REQUIRE(d.state() == DeviceState::kHolding);
    CHECK(module.coil(0));  // held: the spindle and the coolant run on
    CHECK(module.coil(3));
    CHECK(module.write_requests() == 2);
    REQUIRE(d.command(Command::kResume) == Status::kOk);
    for (int i = 0; i < 20000 && d.state() != DeviceState::kIdle; ++i) tick();
    REQUIRE(d.state() == DeviceState::kIdle);  // the job ran to its end mark
    CHECK_FALSE(module.coil(0));
    CHECK_FALSE(module.coil(3));
    CHECK(module.write_requests() == 3);  // one write per change, none per tick
    CHECK(levels(module.changes()) == Levels{{0, true}, {3, true}, {0, false}, {3, false}});
    CHECK(writer.transactions() == 3);
}

TEST_CASE("output coils: scattered coils are written one by one, the spindle last on and first off",
          "[coils][outputs][threads]") {
    CoilModule module(16);
    // spindle 5, spindle_reverse 6, mist: none, flood 9: 5 and 6 are consecutive, 9 is not.
    CoilWriter writer(config_for(module, {5, 6, -1, 9}));
    CHECK(writer.mapping() == "spindle=5 spindle_reverse=6 flood=9");
    writer.apply(0);  // state unknown: every coil, one FC5 each
    CHECK(module.write_requests() == 3);
    // M4 with flood: direction and flood before the spindle runs.
    writer.apply(kOutputSpindle | kOutputSpindleReverse | kOutputFlood | kOutputPenDown);
    CHECK(levels(module.changes()) == Levels{{6, true}, {9, true}, {5, true}});
    CHECK(module.write_requests() == 6);
    writer.apply(kOutputMist);  // no coil for mist: everything else off, the spindle first
    CHECK(levels(module.changes()) ==
          Levels{{6, true}, {9, true}, {5, true}, {5, false}, {6, false}, {9, false}});
    // Spindle and its direction change together: one FC15 of 5..6.
    writer.apply(kOutputSpindle | kOutputSpindleReverse);
    CHECK(module.write_requests() == 10);
    CHECK(module.coil(5));
    CHECK(module.coil(6));
}

TEST_CASE("output coils: the writer thread follows a job through a hold to its end",
          "[coils][outputs][threads]") {
    const Lsb start[kAxes] = {0, 0};
    Device d(start);
    REQUIRE(d.configure(limits()) == Status::kOk);
    CoilModule module(16);
    OutputCoilThread coils(CoilWriter(config_for(module)));
    CHECK(module.write_requests() == 1);  // every coil off before the thread started
    const auto tick = [&] {
        Lsb out[kAxes];
        d.tick(out);
        CHECK(coils.after_tick(d).empty());
    };
    queue_job(d, 30000, kCutting);
    REQUIRE(d.command(Command::kStart) == Status::kOk);
    tick();
    REQUIRE(d.outputs() == kCutting);
    REQUIRE(
        module.wait_until([](const CoilModule& m) { return m.coil(0) && m.coil(3); }, kPatience));
    for (int i = 0; i < 100; ++i) tick();
    REQUIRE(d.command(Command::kHold) == Status::kOk);
    for (int i = 0; i < 500; ++i) tick();
    REQUIRE(d.state() == DeviceState::kHolding);
    CHECK(module.coil(0));
    CHECK(module.coil(3));
    REQUIRE(d.command(Command::kResume) == Status::kOk);
    for (int i = 0; i < 20000 && d.state() != DeviceState::kIdle; ++i) tick();
    REQUIRE(d.state() == DeviceState::kIdle);
    REQUIRE(
        module.wait_until([](const CoilModule& m) { return !m.coil(0) && !m.coil(3); }, kPatience));
    CHECK(levels(module.changes()) == Levels{{0, true}, {3, true}, {0, false}, {3, false}});
    // The writer counts a write once its answer is in: it may lag the module a moment.
    REQUIRE(module.wait_until([&](const CoilModule&) { return coils.writes() == 2; }, kPatience));
    CHECK(coils.failures() == 0);
    CHECK(coils.stop().empty());  // every coil off once more
    CHECK(module.write_requests() == 4);
    CHECK(coils.stop().empty());  // idempotent
    CHECK(module.write_requests() == 4);
}

TEST_CASE("output coils: a module that holds its answers delays no tick",
          "[coils][outputs][threads]") {
    const Lsb start[kAxes] = {0, 0};
    Device d(start);
    REQUIRE(d.configure(limits()) == Status::kOk);
    CoilModule module(16);
    // A response timeout far beyond the hold: the test does not race the client's timeout.
    hal::ModbusClientOptions patient = linux_device::output_coil_client_options();
    patient.response_timeout = kPatience;
    OutputCoilThread coils(CoilWriter(config_for(module), patient));
    module.hold_answers(true);
    queue_job(d, 30000, kCutting);
    REQUIRE(d.command(Command::kStart) == Status::kOk);
    Lsb out[kAxes];
    d.tick(out);
    CHECK(coils.after_tick(d).empty());
    REQUIRE(d.outputs() == kCutting);
    // The writer has taken the spindle and flood and waits for the module's answer.
    REQUIRE(module.wait_until([](const CoilModule& m) { return m.waiting_requests() == 1; },
                              kPatience));
    // The rest of the job runs, every tick publishing, while the module answers nothing.
    std::uint64_t ticks = 0;
    do {
        d.tick(out);
        CHECK(coils.after_tick(d).empty());
    } while (++ticks < 20000 && d.state() != DeviceState::kIdle);
    REQUIRE(d.state() == DeviceState::kIdle);
    CHECK(ticks > 300);
    CHECK(module.waiting_requests() == 1);
    CHECK(module.write_requests() == 1);  // the coils written off at start, nothing since
    CHECK(coils.writes() == 0);
    // Answered at last: the held write lands, then the newest value (off) follows.
    module.hold_answers(false);
    REQUIRE(module.wait_until(
        [](const CoilModule& m) { return m.write_requests() == 3 && !m.coil(0) && !m.coil(3); },
        kPatience));
    CHECK(levels(module.changes()) == Levels{{0, true}, {3, true}, {0, false}, {3, false}});
    CHECK(coils.failures() == 0);
}

TEST_CASE("output coils: a module that is gone faults the device, naming target and coil",
          "[coils][outputs][threads]") {
    const Lsb start[kAxes] = {0, 0};
    Device d(start);
    REQUIRE(d.configure(limits()) == Status::kOk);
    CoilModule module(16);
    const std::string url = module.url();
    OutputCoilThread coils(CoilWriter(config_for(module, {0, -1, -1, 7})));
    module.stop();  // switched off after the start
    queue_job(d, 30000, kCutting);
    REQUIRE(d.command(Command::kStart) == Status::kOk);
    Lsb out[kAxes];
    std::string failure;
    // Tick until the writer's failure comes back (its client's two tries), a tick a millisecond.
    for (int i = 0; i < 60000 && failure.empty(); ++i) {
        d.tick(out);
        failure = coils.after_tick(d);
        if (failure.empty()) std::this_thread::sleep_for(milliseconds(1));
    }
    INFO(failure);
    REQUIRE_FALSE(failure.empty());
    CHECK(failure.rfind(url + ": cannot switch ", 0) == 0);
    // On: the flood before the spindle (coils 0 and 7 are not consecutive: one FC5 each).
    CHECK(failure.find("flood (coil 7) on: FC5 write coil 7 on") != std::string::npos);
    CHECK(failure.find("(after 2 tries)") != std::string::npos);
    d.tick(out);  // the fault raised after the last tick stops the machine at this one
    CHECK(d.state() == DeviceState::kFault);
    CHECK(d.fault_code() == FaultCode::kOutputFailed);
    CHECK(coils.failures() >= 1);
    // At exit the coils cannot be written off either: said, not thrown.
    const std::string last = coils.stop();
    CHECK(last.rfind(url + ": cannot switch spindle (coil 0) off", 0) == 0);
}

TEST_CASE("output coils: a module that cannot be reached or refuses a coil stops the start",
          "[coils][outputs][threads]") {
    host::OutputCoilsConfig gone;
    {
        CoilModule module(16);
        gone = config_for(module);
    }
    try {
        CoilWriter writer(gone);
        FAIL("connected to a module that is gone");
    } catch (const hal::ModbusError& e) {
        CHECK(e.kind() == hal::ModbusError::Kind::kConnectFailed);
        CHECK(std::string(e.what()).find(gone.target) != std::string::npos);
    }
    // A module with 3 coils and flood mapped to coil 7: the first write (all off) is refused.
    CoilModule small(3);
    try {
        OutputCoilThread coils(CoilWriter(config_for(small, {0, -1, 1, 7})));
        FAIL("started with a coil the module does not have");
    } catch (const hal::ModbusError& e) {
        CHECK(e.kind() == hal::ModbusError::Kind::kExceptionResponse);
        CHECK(std::string(e.what()) == small.url() +
                                           ": cannot switch flood (coil 7) off: FC5 write coil 7 "
                                           "off: exception response 2 (illegal data address)");
    }
}
