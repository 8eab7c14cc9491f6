// The e-stop and limit-switch rules (switch_rules.hpp) every port applies, against a real
// MotionDevice: an e-stop pulse shorter than a poll still stops the device and is held until
// released and taken; a limit switch faults on its trip (or when active at the first poll),
// not while masked, and not again while it stays active after a reset.
#include <catch2/catch.hpp>
#include <cstdint>

#include "pathstream/device/switch_rules.hpp"

using namespace pathstream;
using namespace pathstream::device;

namespace {

constexpr unsigned kAxes = 2;
using Device = MotionDevice<kAxes, 16>;

MotionLimits<kAxes> limits() {
    MotionLimits<kAxes> l;
    l.tick_hz = 1000;
    for (auto& a : l.axis) a = {250000, 3000000};
    return l;
}

void tick(Device& d, unsigned n = 1) {
    for (unsigned i = 0; i < n; ++i) {
        Lsb out[kAxes];
        d.tick(out);
    }
}

}  // namespace

TEST_CASE("switch rules: an e-stop pulse shorter than a poll stops the device and is held",
          "[device][gpio][switch]") {
    const Lsb start[kAxes] = {0, 0};
    Device d(start);
    REQUIRE(d.configure(limits()) == Status::kOk);
    SwitchRules<kAxes> rules;
    rules.estop(d, false, false);
    tick(d);
    CHECK(d.state() == DeviceState::kIdle);
    // Active and released again between two polls: seen, but inactive now.
    rules.estop(d, true, false);
    CHECK(rules.estop_held());
    // Released, but the tick has not taken the e-stop yet: still held.
    rules.estop(d, false, false);
    CHECK(rules.estop_held());
    tick(d);
    CHECK(d.state() == DeviceState::kEstop);
    // Now released and taken: the hold ends, and a reset leaves the e-stop.
    rules.estop(d, false, false);
    CHECK_FALSE(rules.estop_held());
    REQUIRE(d.command(Command::kReset) == Status::kOk);
    tick(d);
    CHECK(d.state() == DeviceState::kIdle);
    // While the input stays active, a reset cannot leave the e-stop.
    rules.estop(d, true, true);
    tick(d);
    CHECK(d.state() == DeviceState::kEstop);
    rules.estop(d, false, true);
    CHECK(rules.estop_held());
}

TEST_CASE("switch rules: a limit faults on its trip, not masked, not again while it stays",
          "[device][gpio][switch]") {
    const Lsb start[kAxes] = {0, 0};
    Device d(start);
    REQUIRE(d.configure(limits()) == Status::kOk);
    SwitchRules<kAxes> rules;
    // Active at the first poll: a trip.
    CHECK(rules.limit(d, 1, LimitSide::kPositive, false, true));
    tick(d);
    CHECK(d.state() == DeviceState::kFault);
    CHECK(d.fault_code() == limit_fault(1, LimitSide::kPositive));
    CHECK(rules.limit_active(1, LimitSide::kPositive));
    REQUIRE(d.command(Command::kReset) == Status::kOk);
    tick(d);
    CHECK(d.state() == DeviceState::kIdle);
    // Still active at the next polls, no new edge: no fault (the machine can move off it).
    CHECK_FALSE(rules.limit(d, 1, LimitSide::kPositive, false, true));
    tick(d);
    CHECK(d.state() == DeviceState::kIdle);
    // Inactive at its first poll: nothing; then a trip on the other axis, masked: nothing.
    CHECK_FALSE(rules.limit(d, 0, LimitSide::kNegative, false, false));
    rules.mask_limit(0, LimitSide::kNegative, true);
    CHECK_FALSE(rules.limit(d, 0, LimitSide::kNegative, true, true));
    tick(d);
    CHECK(d.state() == DeviceState::kIdle);
    CHECK(rules.limit_active(0, LimitSide::kNegative));
    // Unmasked, a new trip faults.
    rules.mask_limit(0, LimitSide::kNegative, false);
    CHECK(rules.limit(d, 0, LimitSide::kNegative, true, false));
    tick(d);
    CHECK(d.fault_code() == limit_fault(0, LimitSide::kNegative));
    CHECK(rules.limit_trips() == 2);
}
