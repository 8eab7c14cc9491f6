// The operator's pen (set_pen, the bus's pen command) and the homing run's bookkeeping
// (HomingRun, the bus's home command): when the pen may come down, what raises it again, that
// a jog carries it and a job does not, and in which order a run homes its axes and how a
// failure ends it.
#include <catch2/catch.hpp>
#include <cstdint>

#include "pathstream/device/homing_run.hpp"
#include "pathstream/device/modbus_register_map.hpp"
#include "pathstream/device/operator_commands.hpp"

using namespace pathstream;
using namespace pathstream::device;

namespace {

constexpr unsigned kAxes = 2;
constexpr std::uint32_t kCapacity = 16;
using Device = MotionDevice<kAxes, kCapacity>;

MotionLimits<kAxes> limits() {
    MotionLimits<kAxes> l;
    l.tick_hz = 1000;
    for (auto& a : l.axis) a = {250000, 3000000};
    l.pen_down_ticks = 80;
    return l;
}

void tick(Device& d, unsigned n = 1) {
    for (unsigned i = 0; i < n; ++i) {
        Lsb out[kAxes];
        d.tick(out);
    }
}

// Runs `c`'s service and the tick until idle; returns the ticks whose pen was down and all
// ticks run.
struct Run {
    unsigned pen_ticks = 0;
    unsigned ticks = 0;
};
Run run_to_idle(Device& d, OperatorCommands<kAxes, kCapacity>& c) {
    Run r;
    do {
        c.service();
        tick(d);
        ++r.ticks;
        if ((d.outputs() & kOutputPenDown) != 0) ++r.pen_ticks;
    } while (d.state() != DeviceState::kIdle && r.ticks < 100000);
    return r;
}

OperatorCommand pen(std::int32_t down) {
    OperatorCommand c;
    c.command = kCommandPen;
    c.value = down;
    return c;
}

OperatorCommand jog(unsigned axis, std::int32_t distance) {
    OperatorCommand c;
    c.command = kCommandJog;
    c.axis = static_cast<std::uint16_t>(axis);
    c.value = distance;
    return c;
}

}  // namespace

TEST_CASE("operator's pen: down at rest while idle, carried by a jog, raised by a stop",
          "[device][pen]") {
    const Lsb start[kAxes] = {1000, 2000};
    Device d(start);
    REQUIRE(d.configure(limits()) == Status::kOk);
    OperatorCommands<kAxes, kCapacity> c(d);
    CHECK(c.execute(pen(2)) == Status::kControlValueOutOfRange);
    OperatorCommand with_axis = pen(1);
    with_axis.axis = 1;
    CHECK(c.execute(with_axis) == Status::kControlValueOutOfRange);
    REQUIRE(c.execute(pen(1)) == Status::kOk);
    CHECK(d.outputs() == 0);  // the next tick lowers it
    tick(d);
    CHECK(d.outputs() == kOutputPenDown);
    tick(d, 10);
    CHECK(d.outputs() == kOutputPenDown);  // and keeps it down at rest
    // A jog with the pen down draws: every tick of it, and it stays down at the end.
    REQUIRE(c.execute(jog(0, 20000)) == Status::kOk);
    CHECK(c.execute(pen(0)) == Status::kWrongState);  // running
    const Run r = run_to_idle(d, c);
    CHECK(r.pen_ticks == r.ticks);
    CHECK(d.position(0) == 21000);
    CHECK(d.outputs() == kOutputPenDown);
    // A stop raises it (the device always ends a stop with the pen up).
    REQUIRE(d.command(Command::kStop) == Status::kOk);
    tick(d);
    CHECK(d.outputs() == 0);
    // Down again, then up by command.
    REQUIRE(c.execute(pen(1)) == Status::kOk);
    tick(d);
    REQUIRE(d.outputs() == kOutputPenDown);
    REQUIRE(c.execute(pen(0)) == Status::kOk);
    tick(d);
    CHECK(d.outputs() == 0);
}

TEST_CASE("operator's pen: a job's start, a fault and the e-stop raise it", "[device][pen]") {
    const Lsb start[kAxes] = {0, 0};
    Device d(start);
    REQUIRE(d.configure(limits()) == Status::kOk);
    OperatorCommands<kAxes, kCapacity> c(d);
    // A host's job: one pen-up span queued and started; its pen is its own, not the operator's.
    REQUIRE(c.execute(pen(1)) == Status::kOk);
    tick(d);
    REQUIRE(d.outputs() == kOutputPenDown);
    WireSpan w;
    w.ticks = 100;
    w.flags = kWireJobEnd;
    w.end[0] = 100;
    std::uint8_t bytes[4 + 12 * kAxes];
    const std::size_t n = encode_wire_span(w, kAxes, bytes, sizeof bytes);
    REQUIRE(d.accept_batch(1, 1, bytes, n) == Status::kOk);
    CHECK(c.execute(pen(0)) == Status::kWrongState);  // something is queued
    REQUIRE(d.command(Command::kStart) == Status::kOk);
    unsigned pen_ticks = 0, ticks = 0;
    do {
        tick(d);
        ++ticks;
        if (d.outputs() != 0) ++pen_ticks;
    } while (d.state() != DeviceState::kIdle && ticks < 1000);
    CHECK(d.ticks_executed() == 100);
    CHECK(pen_ticks == 0);
    CHECK(d.outputs() == 0);  // idle after the job: up
    // A fault raises it.
    REQUIRE(c.execute(pen(1)) == Status::kOk);
    tick(d);
    REQUIRE(d.outputs() == kOutputPenDown);
    d.raise_fault(FaultCode::kExternal);
    tick(d);
    CHECK(d.outputs() == 0);
    CHECK(c.execute(pen(1)) == Status::kWrongState);  // in fault
    REQUIRE(d.command(Command::kReset) == Status::kOk);
    tick(d);
    CHECK(d.outputs() == 0);  // the reset does not lower it again
    // The e-stop raises it.
    REQUIRE(c.execute(pen(1)) == Status::kOk);
    tick(d);
    REQUIRE(d.outputs() == kOutputPenDown);
    d.set_estop_input(true);
    tick(d);
    CHECK(d.outputs() == 0);
}

TEST_CASE("home without a homing port is refused by name, bad arguments by value",
          "[device][homing]") {
    const Lsb start[kAxes] = {0, 0};
    Device d(start);
    REQUIRE(d.configure(limits()) == Status::kOk);
    OperatorCommands<kAxes, kCapacity> c(d);
    OperatorCommand h;
    h.command = kCommandHome;
    CHECK(c.execute(h) == Status::kNoHoming);
    h.axis = 4;  // axis 2 of a two-axis device
    CHECK(c.execute(h) == Status::kControlValueOutOfRange);
    h.axis = 1;
    h.feed = 5;
    CHECK(c.execute(h) == Status::kControlValueOutOfRange);
    CHECK_FALSE(c.homing());
    CHECK(c.homing_report(0).state == AxisHoming::kNotHomed);
    OperatorCommand unknown;
    unknown.command = 10;
    CHECK(c.execute(unknown) == Status::kUnknownCommand);
}

TEST_CASE("homing run: plan order, a mask, a failure keeps the waiting axes as they were",
          "[device][homing]") {
    HomingRun<3> run;
    HomingAxis plan[3];
    plan[0].config.axis = 2;
    plan[1].config.axis = 0;
    plan[2].config.axis = 0;
    CHECK(run.set_plan(plan, 3) == Status::kBadLimits);  // axis 0 twice
    CHECK(run.begin(0) == Status::kNoHoming);            // nothing planned after the refusal
    plan[2].config.axis = 1;
    REQUIRE(run.set_plan(plan, 3) == Status::kOk);
    CHECK(run.plannable() == 7u);
    // The whole plan, in its order: z, x, y.
    REQUIRE(run.begin(0) == Status::kOk);
    CHECK(run.busy());
    CHECK(run.begin(0) == Status::kWrongState);
    for (unsigned a = 0; a < 3; ++a) CHECK(run.report(a).state == AxisHoming::kHoming);
    const HomingAxis* next = run.next();
    REQUIRE(next != nullptr);
    CHECK(next->config.axis == 2);
    run.finished(HomingError::kNone);
    CHECK(run.report(2).state == AxisHoming::kHomed);
    next = run.next();
    REQUIRE(next != nullptr);
    CHECK(next->config.axis == 0);
    run.finished(HomingError::kSwitchNotFound);  // x fails: y never starts
    CHECK_FALSE(run.busy());
    CHECK((run.report(0).state == AxisHoming::kFailed &&
           run.report(0).error == HomingError::kSwitchNotFound));
    CHECK(run.report(1).state == AxisHoming::kNotHomed);  // as before the run
    CHECK(run.report(2).state == AxisHoming::kHomed);
    // y alone (mask bit 1); an axis outside the plan is kNoHoming.
    HomingRun<4> wide;
    REQUIRE(wide.set_plan(plan, 3) == Status::kOk);
    CHECK(wide.begin(8) == Status::kNoHoming);
    REQUIRE(run.begin(2) == Status::kOk);
    CHECK(run.report(2).state == AxisHoming::kHomed);  // not part of this run
    next = run.next();
    REQUIRE(next != nullptr);
    CHECK(next->config.axis == 1);
    run.finished(HomingError::kNone);
    CHECK(run.next() == nullptr);
    CHECK_FALSE(run.busy());
    CHECK(run.report(1).state == AxisHoming::kHomed);
}
