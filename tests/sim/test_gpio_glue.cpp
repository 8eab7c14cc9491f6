// The GPIO glue on the simulated plotter (sim/gpio): enable follows the state, the spindle and
// coolant follow a job (kept through a hold, off at its end, a stop, a fault and the e-stop),
// the e-stop input stops motion within one tick and drops enable, limit switches fault naming
// axis and side, homing against a simulated switch, and the simulated lines themselves.
#include <catch2/catch.hpp>
#include <cmath>
#include <string>
#include <vector>

#include "pathstream/device/gpio_logic.hpp"
#include "pathstream/device/homing.hpp"
#include "pathstream/device/wire_span.hpp"
#include "pathstream/sim/gpio_bench.hpp"

using namespace pathstream;
using namespace pathstream::device;

namespace {

constexpr unsigned kAxes = 2;
using Bench = sim::GpioBench<kAxes, 64>;

MotionLimits<kAxes> limits() {
    MotionLimits<kAxes> l;
    l.tick_hz = 1000;
    for (auto& a : l.axis) a = {200000, 2000000};
    return l;
}

// Queues a move of `distance` LSB on `axis` (AxisMove spans) with `outputs` (pen down unless
// told) and returns its ticks; `flags` go on its last span (kWireJobEnd: the job ends there).
std::uint64_t queue_move(Bench& b, unsigned axis, std::int64_t distance,
                         std::uint8_t outputs = kOutputPenDown, std::uint8_t flags = 0) {
    Lsb from[kAxes];
    for (unsigned a = 0; a < kAxes; ++a) from[a] = b.device.position(a);
    AxisMove<kAxes> m;
    REQUIRE(m.plan(from, axis, distance, 100000, b.device.limits()) == Status::kOk);
    std::uint64_t ticks = 0;
    while (m.pending()) {
        WireSpan w;
        REQUIRE(m.next(w));
        w.outputs = outputs;
        if (!m.pending()) w.flags = static_cast<std::uint8_t>(w.flags | flags);
        std::uint8_t bytes[4 + 12 * kAxes];
        const std::size_t n = encode_wire_span(w, kAxes, bytes, sizeof bytes);
        REQUIRE(b.device.accept_batch(b.device.last_accepted_sequence() + 1, 1, bytes, n) ==
                Status::kOk);
        ticks += w.ticks;
    }
    return ticks;
}

std::string fault_text(FaultCode c) {
    char buf[64];
    fault_name(c, buf, sizeof buf);
    return buf;
}

}  // namespace

TEST_CASE("gpio glue: enable follows the state: up while running, down when idle again",
          "[gpio][glue]") {
    const Lsb start[kAxes] = {0, 0};
    Bench b(start, limits());
    CHECK_FALSE(b.enable.state());
    b.step();
    CHECK_FALSE(b.enable.state());  // idle
    const std::uint64_t ticks = queue_move(b, 0, 5000);
    REQUIRE(b.device.command(Command::kStart) == Status::kOk);
    b.step();
    CHECK(b.device.state() == DeviceState::kRunning);
    CHECK(b.enable.state());
    REQUIRE(b.enable.switch_ticks().size() == 1);
    CHECK(b.enable.switch_ticks()[0] == 2);  // asserted right after the tick that started
    CHECK(b.pen.state());                    // the span's pen-down output
    for (std::uint64_t i = 0; i < ticks; ++i) b.step();
    REQUIRE(b.device.command(Command::kStop) == Status::kOk);
    b.step();
    CHECK(b.device.state() == DeviceState::kIdle);
    CHECK_FALSE(b.enable.state());
    CHECK_FALSE(b.pen.state());
    // Hold keeps enable (a held axis is servoed), a stop from holding drops it.
    queue_move(b, 1, 20000);
    REQUIRE(b.device.command(Command::kStart) == Status::kOk);
    for (int i = 0; i < 100; ++i) b.step();
    REQUIRE(b.device.command(Command::kHold) == Status::kOk);
    REQUIRE(b.run_until(
        [&] { return b.device.state() == DeviceState::kHolding && b.ticks.size() > 400; }, 2000));
    CHECK(b.enable.state());
    REQUIRE(b.device.command(Command::kStop) == Status::kOk);
    REQUIRE(b.run_until([&] { return b.device.state() == DeviceState::kIdle; }, 2000));
    CHECK_FALSE(b.enable.state());
}

TEST_CASE("gpio glue: spindle and flood follow a job, kept through a hold, off when it ends",
          "[gpio][glue][outputs]") {
    const Lsb start[kAxes] = {0, 0};
    Bench b(start, limits());
    constexpr std::uint8_t kCutting = kOutputSpindle | kOutputFlood;
    const std::uint64_t ticks = queue_move(b, 0, 30000, kCutting, kWireJobEnd);
    b.step();
    CHECK_FALSE(b.spindle.state());  // idle with a job queued
    REQUIRE(b.device.command(Command::kStart) == Status::kOk);
    b.step();
    // On right after the tick that started, with the enable; the pen, mist and the spindle's
    // direction stay off (not in the spans).
    CHECK(b.spindle.state());
    CHECK(b.flood.state());
    CHECK(b.spindle.switch_ticks() == std::vector<std::uint64_t>{2});
    CHECK(b.flood.switch_ticks() == b.spindle.switch_ticks());
    CHECK_FALSE(b.spindle_reverse.state());
    CHECK_FALSE(b.mist.state());
    CHECK_FALSE(b.pen.state());
    for (int i = 0; i < 100; ++i) b.step();
    // A hold decelerates and rests: the spindle and the coolant keep running.
    REQUIRE(b.device.command(Command::kHold) == Status::kOk);
    REQUIRE(b.run_until(
        [&] { return b.device.state() == DeviceState::kHolding && b.ticks.size() > 600; }, 2000));
    CHECK(b.spindle.state());
    CHECK(b.flood.state());
    CHECK(b.spindle.switch_ticks().size() == 1);
    REQUIRE(b.device.command(Command::kResume) == Status::kOk);
    // The job runs to its end mark: the tick that ends it (idle) switches both off, with the
    // enable.
    REQUIRE(b.run_until([&] { return b.device.state() == DeviceState::kIdle; }, ticks + 2000));
    CHECK_FALSE(b.spindle.state());
    CHECK_FALSE(b.flood.state());
    REQUIRE(b.spindle.switch_ticks().size() == 2);
    CHECK(b.spindle.switch_ticks()[1] == b.enable.switch_ticks().back());
    CHECK(b.flood.switch_ticks() == b.spindle.switch_ticks());
}

TEST_CASE("gpio glue: a stop, a fault and the e-stop switch the spindle and coolant off",
          "[gpio][glue][outputs]") {
    const Lsb start[kAxes] = {0, 0};
    Bench b(start, limits());
    constexpr std::uint8_t kReverseMist = kOutputSpindle | kOutputSpindleReverse | kOutputMist;
    const auto cutting = [&] {
        return b.spindle.state() && b.spindle_reverse.state() && b.mist.state();
    };
    const auto all_off = [&] {
        return !b.spindle.state() && !b.spindle_reverse.state() && !b.mist.state() &&
               !b.flood.state() && !b.enable.state();
    };
    // A stop: the spindle keeps running while the axes decelerate (stopping), then off at rest.
    queue_move(b, 0, 30000, kReverseMist);
    REQUIRE(b.device.command(Command::kStart) == Status::kOk);
    for (int i = 0; i < 150; ++i) b.step();
    REQUIRE(cutting());
    REQUIRE(b.device.command(Command::kStop) == Status::kOk);
    b.step();
    REQUIRE(b.device.state() == DeviceState::kStopping);
    CHECK(cutting());
    REQUIRE(b.run_until([&] { return b.device.state() == DeviceState::kIdle; }, 2000));
    CHECK(all_off());
    // A fault (a limit switch): off right after the tick that faults.
    queue_move(b, 1, 30000, kReverseMist);
    REQUIRE(b.device.command(Command::kStart) == Status::kOk);
    for (int i = 0; i < 150; ++i) b.step();
    REQUIRE(cutting());
    b.limit[1][1].drive(true, 1);
    b.step();
    CHECK(b.device.state() == DeviceState::kFault);
    CHECK(all_off());
    b.limit[1][1].drive(false, 2);
    b.step();
    REQUIRE(b.device.command(Command::kReset) == Status::kOk);
    b.step();
    REQUIRE(b.device.state() == DeviceState::kIdle);
    // The e-stop: off right after the tick that sees it.
    queue_move(b, 1, -30000, kReverseMist);
    REQUIRE(b.device.command(Command::kStart) == Status::kOk);
    for (int i = 0; i < 150; ++i) b.step();
    REQUIRE(cutting());
    const std::size_t edge_at = b.ticks.size();
    b.estop.drive(true, 3);
    b.step();
    CHECK(b.device.state() == DeviceState::kEstop);
    CHECK(all_off());
    CHECK(b.spindle.switch_ticks().back() == edge_at + 1);
    for (int i = 0; i < 20; ++i) b.step();
    CHECK(all_off());
}

TEST_CASE("gpio glue: the e-stop stops motion within one tick, drops enable, resets only released",
          "[gpio][glue]") {
    const Lsb start[kAxes] = {0, 0};
    Bench b(start, limits());
    queue_move(b, 0, 30000);
    REQUIRE(b.device.command(Command::kStart) == Status::kOk);
    for (int i = 0; i < 150; ++i) b.step();
    REQUIRE(b.device.state() == DeviceState::kRunning);
    REQUIRE(b.ticks[149][0] != b.ticks[148][0]);  // moving
    const std::size_t edge_at = b.ticks.size();   // the edge comes between tick 150 and 151
    b.estop.drive(true, 123);
    b.step();
    // Reaction: the very next tick repeats the last setpoint, the state is e-stop and enable
    // is low right after that tick: one tick.
    CHECK(b.device.state() == DeviceState::kEstop);
    CHECK(b.ticks[edge_at] == b.ticks[edge_at - 1]);
    CHECK_FALSE(b.enable.state());
    CHECK(b.enable.switch_ticks().back() == edge_at + 1);
    CHECK_FALSE(b.pen.state());
    CHECK(b.glue.estop_edges() == 1);
    CHECK(b.glue.last_estop_edge_ns() == 123);
    for (int i = 0; i < 50; ++i) b.step();
    CHECK(b.ticks.back() == b.ticks[edge_at]);  // frozen
    // Reset is refused while the input is active; accepted once released.
    CHECK(b.device.command(Command::kReset) == Status::kWrongState);
    b.estop.drive(false);
    b.step();
    REQUIRE(b.device.command(Command::kReset) == Status::kOk);
    b.step();
    CHECK(b.device.state() == DeviceState::kIdle);
    CHECK_FALSE(b.enable.state());
}

TEST_CASE("gpio glue: an e-stop pulse shorter than a poll still stops", "[gpio][glue]") {
    const Lsb start[kAxes] = {0, 0};
    Bench b(start, limits());
    queue_move(b, 1, 30000);
    REQUIRE(b.device.command(Command::kStart) == Status::kOk);
    for (int i = 0; i < 100; ++i) b.step();
    b.estop.pulse();
    REQUIRE_FALSE(b.estop.active());
    b.step();
    CHECK(b.device.state() == DeviceState::kEstop);
    CHECK_FALSE(b.enable.state());
    b.step();  // the input is released and the device has seen the e-stop: reset allowed
    CHECK(b.device.command(Command::kReset) == Status::kOk);
}

TEST_CASE("gpio glue: a limit switch faults at once, naming axis and side", "[gpio][glue]") {
    for (bool positive : {false, true}) {
        const Lsb start[kAxes] = {0, 0};
        Bench b(start, limits());
        const LimitSide side = positive ? LimitSide::kPositive : LimitSide::kNegative;
        b.place_switch(1, side, positive ? 10000 : -10000);
        queue_move(b, 1, positive ? 30000 : -30000);
        REQUIRE(b.device.command(Command::kStart) == Status::kOk);
        REQUIRE(b.run_until([&] { return b.device.state() == DeviceState::kFault; }, 5000));
        const std::size_t k = b.ticks.size() - 1;  // the fault tick
        CHECK(b.ticks[k] == b.ticks[k - 1]);       // stopped at once
        const Lsb seen = b.ticks[k - 1][1];
        CHECK((positive ? seen >= 10000 : seen <= -10000));
        CHECK((positive ? b.ticks[k - 2][1] < 10000
                        : b.ticks[k - 2][1] > -10000));  // the tick before: not yet
        CHECK(b.device.fault_code() == limit_fault(1, side));
        CHECK(fault_text(b.device.fault_code()) ==
              (positive ? "limit switch y+ (axis 1, positive side)"
                        : "limit switch y- (axis 1, negative side)"));
        CHECK_FALSE(b.enable.state());
        CHECK(b.glue.limit_trips() == 1);
        // Reset while still on the switch is allowed (the machine must move off it) and does
        // not fault again until the switch is released and hit anew.
        REQUIRE(b.device.command(Command::kReset) == Status::kOk);
        for (int i = 0; i < 5; ++i) b.step();
        CHECK(b.device.state() == DeviceState::kIdle);
        CHECK(b.glue.limit_active(1, side));
        CHECK(b.glue.limit_trips() == 1);
    }
}

TEST_CASE("gpio glue: homing on the simulated plotter, its switch masked, the other armed",
          "[gpio][glue][homing]") {
    const Lsb start[kAxes] = {8000, 0};
    Bench b(start, limits());
    b.place_switch(0, LimitSide::kNegative, 2500);
    b.place_switch(0, LimitSide::kPositive, 400000);
    b.glue.mask_limit(0, LimitSide::kNegative, true);
    HomingSequencer<kAxes, 64> h(b.device);
    HomingConfig c;
    c.axis = 0;
    c.search_velocity = 40000;
    c.latch_velocity = 1000;
    c.backoff = 2000;
    c.max_travel = 300000;
    REQUIRE(h.start(c) == Status::kOk);
    bool enable_seen = false;
    REQUIRE(b.run_until(
        [&] {
            h.poll(b.glue.limit_active(0, LimitSide::kNegative));
            enable_seen = enable_seen || b.enable.state();
            return !h.busy();
        },
        100000));
    CHECK(h.phase() == HomingPhase::kDone);
    CHECK(enable_seen);
    CHECK_FALSE(b.enable.state());  // idle again
    CHECK(b.device.state() == DeviceState::kIdle);
    CHECK(b.glue.limit_trips() == 0);
    CHECK(h.latch_position() <= 2500);
    CHECK(h.latch_position() >= 2497);  // the poll sees the switch one tick late here
    b.glue.mask_limit(0, LimitSide::kNegative, false);
    // The switch stays where it is on the machine; homing moved the device's zero onto it.
    CHECK(b.switches.machine_position(0) - b.device.position(0) == h.latch_position());
    // Homing ends on the switch (the latch stop runs past its point). Off it, then back: in
    // the new coordinates the switch point is 0, so moving to -100 trips the armed switch.
    CHECK(b.glue.limit_active(0, LimitSide::kNegative));
    queue_move(b, 0, 1000 - b.device.position(0));
    REQUIRE(b.device.command(Command::kStart) == Status::kOk);
    REQUIRE(b.run_until(
        [&] { return b.device.last_completed_sequence() == b.device.last_accepted_sequence(); },
        5000));
    CHECK_FALSE(b.glue.limit_active(0, LimitSide::kNegative));
    CHECK(b.device.state() == DeviceState::kRunning);
    queue_move(b, 0, -1100);
    REQUIRE(b.run_until([&] { return b.device.state() == DeviceState::kFault; }, 5000));
    CHECK(b.device.fault_code() == limit_fault(0, LimitSide::kNegative));
}

TEST_CASE("simulated input queues edges in order and ignores repeats", "[gpio][glue]") {
    sim::SimulatedInput in;
    hal::InputEdge e;
    CHECK_FALSE(in.next_edge(e));
    in.drive(false);
    CHECK_FALSE(in.next_edge(e));
    in.drive(true, 5);
    in.drive(true, 6);
    in.drive(false, 7);
    REQUIRE(in.next_edge(e));
    CHECK(e.active);
    CHECK(e.timestamp_ns == 5);
    REQUIRE(in.next_edge(e));
    CHECK_FALSE(e.active);
    CHECK(e.timestamp_ns == 7);
    CHECK_FALSE(in.next_edge(e));
    CHECK(in.event_fd() == -1);
}
