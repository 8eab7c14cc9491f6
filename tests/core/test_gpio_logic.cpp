// GPIO device logic (gpio_logic.hpp): limit-switch fault codes and names, when enables, the
// pen and the machine functions (spindle, coolant) are asserted, and MotionDevice::set_position
// (homing's "set zero").
#include <catch2/catch.hpp>
#include <string>

#include "core/device_fixture.hpp"
#include "pathstream/device/gpio_logic.hpp"

using namespace pathstream;
using namespace pathstream::device;

namespace {
std::string name_of(FaultCode c) {
    char buf[64];
    const std::size_t n = fault_name(c, buf, sizeof buf);
    REQUIRE(n == std::string(buf).size());
    return buf;
}
}  // namespace

TEST_CASE("limit switch faults encode axis and side as documented", "[device][gpio]") {
    CHECK(static_cast<unsigned>(limit_fault(0, LimitSide::kNegative)) == 0x100);
    CHECK(static_cast<unsigned>(limit_fault(0, LimitSide::kPositive)) == 0x101);
    CHECK(static_cast<unsigned>(limit_fault(1, LimitSide::kNegative)) == 0x102);
    CHECK(static_cast<unsigned>(limit_fault(7, LimitSide::kPositive)) == 0x10F);
    for (unsigned axis = 0; axis < kMaxAxes; ++axis) {
        for (LimitSide side : {LimitSide::kNegative, LimitSide::kPositive}) {
            unsigned a = 99;
            LimitSide s = LimitSide::kPositive;
            REQUIRE(limit_fault_switch(limit_fault(axis, side), a, s));
            CHECK(a == axis);
            CHECK(s == side);
        }
    }
    unsigned a = 0;
    LimitSide s = LimitSide::kNegative;
    CHECK_FALSE(limit_fault_switch(FaultCode::kExternal, a, s));
    CHECK_FALSE(limit_fault_switch(static_cast<FaultCode>(0x110), a, s));
}

TEST_CASE("fault names say which switch, on which axis and side", "[device][gpio]") {
    CHECK(name_of(FaultCode::kNone) == "none");
    CHECK(name_of(FaultCode::kExternal) == "external fault");
    CHECK(name_of(FaultCode::kStopFailed) == "no controlled stop fits in one span");
    CHECK(name_of(FaultCode::kOutputFailed) == "a machine output could not be switched");
    CHECK(static_cast<unsigned>(FaultCode::kOutputFailed) == 4);
    CHECK(name_of(limit_fault(0, LimitSide::kNegative)) ==
          "limit switch x- (axis 0, negative side)");
    CHECK(name_of(limit_fault(1, LimitSide::kPositive)) ==
          "limit switch y+ (axis 1, positive side)");
    CHECK(name_of(limit_fault(7, LimitSide::kPositive)) ==
          "limit switch v+ (axis 7, positive side)");
    CHECK(name_of(static_cast<FaultCode>(0x1234)) == "fault 0x1234");
    // Bounded: truncated, always terminated; nothing written for capacity 0.
    char small[8];
    CHECK(fault_name(limit_fault(0, LimitSide::kNegative), small, sizeof small) == 7);
    CHECK(std::string(small) == "limit s");
    char untouched = 'z';
    CHECK(fault_name(FaultCode::kExternal, &untouched, 0) == 0);
    CHECK(untouched == 'z');
}

TEST_CASE("enables are asserted only while the device may move, the pen then or by the operator",
          "[device][gpio]") {
    CHECK_FALSE(enable_asserted(DeviceState::kIdle));
    CHECK(enable_asserted(DeviceState::kRunning));
    CHECK(enable_asserted(DeviceState::kHolding));
    CHECK(enable_asserted(DeviceState::kStopping));
    CHECK_FALSE(enable_asserted(DeviceState::kFault));
    CHECK_FALSE(enable_asserted(DeviceState::kEstop));
    CHECK(pen_down(DeviceState::kRunning, kOutputPenDown));
    CHECK_FALSE(pen_down(DeviceState::kRunning, 0));
    CHECK(pen_down(DeviceState::kHolding, kOutputPenDown));
    // Idle outputs are only the operator's pen (set_pen); fault and e-stop always lift it.
    CHECK(pen_down(DeviceState::kIdle, kOutputPenDown));
    CHECK_FALSE(pen_down(DeviceState::kIdle, 0));
    for (DeviceState s : {DeviceState::kFault, DeviceState::kEstop}) {
        CHECK_FALSE(pen_down(s, kOutputPenDown));
    }
}

TEST_CASE("machine function outputs are on only with the drives enabled and their bit set",
          "[device][gpio][outputs]") {
    constexpr std::uint8_t kAll = kOutputMachineMask | kOutputPenDown;
    static_assert(machine_output_on(DeviceState::kRunning, kOutputSpindle, kOutputSpindle));
    for (DeviceState s : {DeviceState::kRunning, DeviceState::kHolding, DeviceState::kStopping}) {
        for (const std::uint8_t bit : kMachineOutputBits) {
            CHECK(machine_output_on(s, bit, bit));
            CHECK(machine_output_on(s, kAll, bit));
            CHECK_FALSE(machine_output_on(s, static_cast<std::uint8_t>(kAll & ~bit), bit));
        }
        CHECK(machine_outputs_on(s, kAll) == kOutputMachineMask);
        CHECK(machine_outputs_on(s, kOutputSpindle | kOutputFlood | kOutputPenDown) ==
              (kOutputSpindle | kOutputFlood));
    }
    // Idle, fault, e-stop: off whatever the byte says (the drives are off too).
    for (DeviceState s : {DeviceState::kIdle, DeviceState::kFault, DeviceState::kEstop}) {
        for (const std::uint8_t bit : kMachineOutputBits)
            CHECK_FALSE(machine_output_on(s, kAll, bit));
        CHECK(machine_outputs_on(s, kAll) == 0);
    }
    // The pen is not a machine function.
    CHECK_FALSE(machine_output_on(DeviceState::kRunning, kOutputPenDown, kOutputPenDown));
    std::uint8_t all = 0;
    for (const std::uint8_t bit : kMachineOutputBits) all = static_cast<std::uint8_t>(all | bit);
    CHECK(all == kOutputMachineMask);
}

TEST_CASE("set_position redefines the rest point while idle and hands it to the producer",
          "[device][gpio]") {
    const Lsb start[2] = {5000, -3000};
    MotionDevice<2, 32> d(start);
    REQUIRE(d.configure(test::test_limits<2>()) == Status::kOk);
    Lsb out[2];
    d.tick(out);
    const Lsb zero[2] = {0, 100};
    REQUIRE(d.set_position(zero) == Status::kOk);
    CHECK(d.position_pending());
    const Lsb other[2] = {1, 1};
    CHECK(d.set_position(other) == Status::kWrongState);  // the first is still pending
    d.tick(out);
    CHECK_FALSE(d.position_pending());
    CHECK(out[0] == 0);  // the tick that applies it already outputs the new position
    CHECK(out[1] == 100);
    CHECK(d.position(0) == 0);
    d.tick(out);
    CHECK(out[0] == 0);
    CHECK(out[1] == 100);
    // The next batch must start at the new position: a move from there is accepted and runs.
    const auto spans = test::trapezoid_move<2>(zero, 1000, 8);
    const auto bytes = test::batch_bytes<2>(spans, 0, spans.size());
    REQUIRE(d.accept_batch(1, static_cast<std::uint16_t>(spans.size()), bytes.data(),
                           bytes.size()) == Status::kOk);
    // Refused with spans queued and while running.
    CHECK(d.set_position(zero) == Status::kWrongState);
    REQUIRE(d.command(Command::kStart) == Status::kOk);
    for (int i = 0;
         i < 2000 && d.queued_spans() + (d.last_completed_sequence() != spans.size()) > 0; ++i)
        d.tick(out);
    CHECK(out[0] == spans.back().end[0]);
    CHECK(d.set_position(zero) == Status::kWrongState);  // running (at rest): not idle
}

TEST_CASE("set_position is refused in fault and e-stop", "[device][gpio]") {
    const Lsb start[1] = {0};
    MotionDevice<1, 8> d(start);
    REQUIRE(d.configure(test::test_limits<1>()) == Status::kOk);
    Lsb out[1];
    d.set_estop_input(true);
    d.tick(out);
    REQUIRE(d.state() == DeviceState::kEstop);
    const Lsb p[1] = {7};
    CHECK(d.set_position(p) == Status::kWrongState);
    d.set_estop_input(false);
    REQUIRE(d.command(Command::kReset) == Status::kOk);
    d.tick(out);
    d.raise_fault(limit_fault(0, LimitSide::kPositive));
    d.tick(out);
    REQUIRE(d.state() == DeviceState::kFault);
    CHECK(d.set_position(p) == Status::kWrongState);
}
