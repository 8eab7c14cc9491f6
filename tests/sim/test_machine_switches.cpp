// Switches played by the simulated axes (sim/gpio: AxisSwitch, MachineSwitches): the trigger,
// the hysteresis, seeded bounce, a machine frame that the device's new zero does not move, and
// homing on the simulated plotter against a bouncing switch with hysteresis.
#include <catch2/catch.hpp>
#include <cstdint>
#include <vector>

#include "pathstream/device/homing.hpp"
#include "pathstream/sim/axis_switch.hpp"
#include "pathstream/sim/gpio_bench.hpp"
#include "pathstream/sim/machine_switches.hpp"

using namespace pathstream;
using device::LimitSide;

namespace {

sim::SwitchPlacement negative_at(Lsb trigger, Lsb hysteresis = 0, std::uint32_t bounces = 0,
                                 std::uint32_t bounce_ticks = 0, std::uint64_t seed = 1) {
    sim::SwitchPlacement p;
    p.axis = 0;
    p.side = LimitSide::kNegative;
    p.trigger = trigger;
    p.hysteresis = hysteresis;
    p.bounces = bounces;
    p.bounce_ticks = bounce_ticks;
    p.seed = seed;
    return p;
}

// The levels of a switch over a sweep of positions.
std::vector<bool> levels(sim::AxisSwitch s, const std::vector<Lsb>& positions) {
    std::vector<bool> out;
    for (Lsb p : positions) out.push_back(s.update(p));
    return out;
}

}  // namespace

TEST_CASE("axis switch: closes at the trigger, opens past the hysteresis", "[gpio][switch]") {
    SECTION("negative side") {
        sim::AxisSwitch s(negative_at(-100, 10));
        CHECK_FALSE(s.update(0));
        CHECK_FALSE(s.update(-99));
        CHECK(s.update(-100));
        CHECK(s.update(-150));
        CHECK(s.update(-95));  // back inside the hysteresis: still closed
        CHECK(s.update(-90));  // trigger + hysteresis: still closed
        CHECK_FALSE(s.update(-89));
        CHECK_FALSE(s.update(-99));  // open until the trigger again
        CHECK(s.update(-100));
        CHECK(s.changes() == 3);  // closed, opened, closed
        CHECK(s.edges() == 3);
    }
    SECTION("positive side") {
        sim::SwitchPlacement p = negative_at(500, 3);
        p.side = LimitSide::kPositive;
        sim::AxisSwitch s(p);
        CHECK_FALSE(s.update(499));
        CHECK(s.update(500));
        CHECK(s.update(497));
        CHECK_FALSE(s.update(496));
    }
    SECTION("a negative hysteresis is none") {
        sim::AxisSwitch s(negative_at(0, -5));
        CHECK(s.update(0));
        CHECK_FALSE(s.update(1));
    }
}

TEST_CASE("axis switch: seeded bounce after every change, settled at the new level",
          "[gpio][switch]") {
    // Closes at tick 1 and stays closed: 3 bounces within 8 ticks, then steady.
    std::vector<Lsb> closing(20, -200);
    closing[0] = 0;
    const std::vector<bool> a = levels(sim::AxisSwitch(negative_at(-100, 0, 3, 8, 7)), closing);
    const std::vector<bool> b = levels(sim::AxisSwitch(negative_at(-100, 0, 3, 8, 7)), closing);
    CHECK(a == b);  // the same seed, the same bounce
    CHECK_FALSE(a[0]);
    CHECK(a[1]);  // the first touch shows at once
    std::uint32_t edges = 0;
    for (std::size_t k = 1; k < a.size(); ++k) edges += a[k] != a[k - 1] ? 1 : 0;
    CHECK(edges == 1 + 2 * 3);
    for (std::size_t k = 1 + 8 + 1; k < a.size(); ++k) CHECK(a[k]);  // settled after the window
    sim::AxisSwitch s(negative_at(-100, 0, 3, 8, 7));
    for (Lsb p : closing) (void)s.update(p);
    CHECK(s.changes() == 1);
    CHECK(s.edges() == 7);

    // Another seed draws other ticks (over a few seeds at least one differs).
    bool differs = false;
    for (std::uint64_t seed = 8; seed < 16; ++seed) {
        differs =
            differs || levels(sim::AxisSwitch(negative_at(-100, 0, 3, 8, seed)), closing) != a;
    }
    CHECK(differs);

    // The window is at least two ticks per bounce.
    sim::AxisSwitch narrow(negative_at(-100, 0, 4, 1));
    CHECK(narrow.placement().bounce_ticks == 8);
}

TEST_CASE("machine switches: the device's new zero does not move a switch", "[gpio][switch]") {
    sim::MachineSwitches w;
    std::vector<bool> seen;
    w.place(negative_at(-1000), [&seen](bool closed) { seen.push_back(closed); });
    REQUIRE(seen == std::vector<bool>{false});  // driven open at once
    Lsb p[1] = {0};
    w.after_tick(p, 1, 0);
    p[0] = -1000;
    w.after_tick(p, 1, 0);
    CHECK(seen.back());
    // The device redefines -1000 as 0 (a position setting applied): the machine stays put.
    p[0] = 0;
    w.after_tick(p, 1, 1);
    CHECK(w.machine_position(0) == -1000);
    CHECK(seen.size() == 2);  // no change of the line
    p[0] = 1;
    w.after_tick(p, 1, 1);
    CHECK_FALSE(seen.back());
    CHECK(w.machine_position(0) == -999);
    p[0] = 0;
    w.after_tick(p, 1, 1);
    CHECK(seen.back());
}

TEST_CASE("homing against a bouncing switch with hysteresis on the simulated plotter",
          "[gpio][switch][homing]") {
    const Lsb start[2] = {8000, 0};
    device::MotionLimits<2> l;
    l.tick_hz = 1000;
    for (auto& a : l.axis) a = {200000, 2000000};
    for (std::uint64_t seed = 1; seed <= 20; ++seed) {
        INFO("seed " << seed);
        sim::GpioBench<2, 64> b(start, l);
        b.place_switch(negative_at(2500, 40, 3, 10, seed));
        b.glue.mask_limit(0, LimitSide::kNegative, true);
        device::HomingSequencer<2, 64> h(b.device);
        device::HomingConfig c;
        c.axis = 0;
        c.search_velocity = 40000;
        c.latch_velocity = 1000;
        c.backoff = 2000;
        c.max_travel = 300000;
        c.pull_off = 500;
        REQUIRE(h.start(c) == Status::kOk);
        REQUIRE(b.run_until(
            [&] {
                h.poll(b.glue.limit_active(0, LimitSide::kNegative));
                return !h.busy();
            },
            100000));
        CHECK(h.phase() == device::HomingPhase::kDone);
        CHECK(b.device.state() == device::DeviceState::kIdle);
        // The latch is the first closing on the slow approach: its bounces come after it.
        CHECK(h.latch_position() <= 2500);
        CHECK(h.latch_position() >= 2497);
        // Every approach and departure bounced: search, back-off, latch, pull-off.
        CHECK(b.switches.contact(0).changes() == 4);
        CHECK(b.switches.contact(0).edges() == 4 * 7);
        // Zero at the switch point: the machine's 2500 is the device's 0 within a tick's travel.
        CHECK(b.switches.machine_position(0) - b.device.position(0) == h.latch_position());
    }
}
