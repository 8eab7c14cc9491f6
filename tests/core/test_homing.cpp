// Homing (homing.hpp): the constant-acceleration moves it generates, and the sequence search,
// back-off, latch, set zero against a simulated switch, with its errors. Every run checks
// every tick's velocity and acceleration against the limits.
#include <catch2/catch.hpp>
#include <cstdlib>
#include <vector>

#include "core/device_fixture.hpp"
#include "pathstream/device/homing.hpp"

using namespace pathstream;
using namespace pathstream::device;

namespace {

constexpr unsigned kAxes = 2;
using Device = MotionDevice<kAxes, 32>;

struct Result {
    std::vector<Lsb> x;  // axis 0 setpoint per tick
    bool finished = false;
    std::size_t set_at = 0;  // index of the tick that applied set zero (coordinates change there)
};

// Runs homing with a switch on axis 0 that is active at or below `trigger` (negative side) or
// at or above it (positive side). `during` is called before every tick (to inject events).
// `checked` ticks are checked against the limits (an e-stop stops at once, beyond them).
template <typename During>
Result run_homing(Device& d, HomingSequencer<kAxes, 32>& h, Lsb trigger, bool positive,
                  std::uint32_t max_ticks, During during, std::size_t checked = 1u << 30) {
    Result r;
    Lsb out[kAxes];
    for (std::uint32_t k = 0; k < max_ticks; ++k) {
        // The switch sits at a physical place: after set zero (the machine rests on that tick)
        // the coordinates moved by the difference between the two ticks.
        const Lsb shift =
            r.set_at != 0 && r.x.size() > r.set_at ? r.x[r.set_at] - r.x[r.set_at - 1] : 0;
        const Lsb p = d.position(0) - shift;
        const bool active = positive ? p >= trigger : p <= trigger;
        h.poll(active);
        if (!h.busy()) {
            r.finished = true;
            break;
        }
        during(k);
        if (h.phase() == HomingPhase::kSetZero && r.set_at == 0) r.set_at = r.x.size();
        d.tick(out);
        r.x.push_back(out[0]);
        REQUIRE(out[1] == d.position(1));
    }
    // Velocity and acceleration of every tick within the limits (200 LSB/tick, 2 LSB/tick^2,
    // plus one LSB of rounding on the second difference).
    if (r.set_at != 0 && r.set_at < checked) checked = r.set_at;
    for (std::size_t k = 2; k < r.x.size() && k < checked; ++k) {
        REQUIRE(std::abs(r.x[k] - r.x[k - 1]) <= 200);
        REQUIRE(std::abs(r.x[k] - 2 * r.x[k - 1] + r.x[k - 2]) <= 3);
    }
    return r;
}

HomingConfig config(bool positive = false) {
    HomingConfig c;
    c.axis = 0;
    c.toward_positive = positive;
    c.search_velocity = 50000;  // 50 LSB/tick
    c.latch_velocity = 2000;    // 2 LSB/tick
    c.backoff = 3000;
    c.max_travel = 40000;
    c.home_position = 0;
    return c;
}

}  // namespace

TEST_CASE("AxisMove: every span passes the exact limit check and the move ends exactly",
          "[device][homing]") {
    const MotionLimits<2> limits = test::test_limits<2>();
    for (std::int64_t distance : {1, 2, 7, 100, 999, 5000, 12345, -12345, 60001, -3}) {
        for (std::uint32_t velocity : {1000u, 50000u, 200000u, 400000u}) {
            const Lsb start[2] = {100, -7};
            AxisMove<2> m;
            REQUIRE(m.plan(start, 0, distance, velocity, limits) == Status::kOk);
            Lsb at[2] = {start[0], start[1]};
            std::int32_t last_t1 = 0;
            int spans = 0;
            while (m.pending()) {
                WireSpan w;
                REQUIRE(m.next(w));
                Span<2> s;
                s.basis = Basis::kHermite;
                s.ticks = w.ticks;
                for (unsigned a = 0; a < 2; ++a) {
                    s.control[a][0] = at[a];
                    s.control[a][1] = w.end[a];
                    s.control[a][2] = w.start_tangent[a];
                    s.control[a][3] = w.end_tangent[a];
                    at[a] = w.end[a];
                }
                REQUIRE(w.start_tangent[0] == last_t1);  // velocity continuous
                last_t1 = w.end_tangent[0];
                REQUIRE(stop_detail::check_span(s, limits) == Status::kOk);
                ++spans;
                REQUIRE(spans < 100000);
            }
            CHECK(last_t1 == 0);
            CHECK(at[0] == start[0] + distance);
            CHECK(at[1] == start[1]);
        }
    }
}

TEST_CASE("homing finds the switch, backs off, latches slowly and sets zero there",
          "[device][homing]") {
    for (bool positive : {false, true}) {
        const Lsb start[kAxes] = {5000, 777};
        const Lsb trigger = positive ? 20000 : 1000;
        Device d(start);
        REQUIRE(d.configure(test::test_limits<kAxes>()) == Status::kOk);
        HomingSequencer<kAxes, 32> h(d);
        HomingConfig c = config(positive);
        c.home_position = positive ? 300000 : 0;
        REQUIRE(h.start(c) == Status::kOk);
        const Result r = run_homing(d, h, trigger, positive, 200000, [](std::uint32_t) {});
        REQUIRE(r.finished);
        REQUIRE(h.phase() == HomingPhase::kDone);
        CHECK(h.error() == HomingError::kNone);
        CHECK(d.state() == DeviceState::kIdle);
        // The search ran past the switch (a controlled stop) by less than a stop from 50 LSB/tick.
        CHECK(h.search_overshoot() > 0);
        CHECK(h.search_overshoot() < 50 * 16 + 50 * 50 / 2 + 100);
        // The latch saw the switch within one tick of latch velocity of its true point.
        const Lsb latch = h.latch_position();
        if (positive) {
            CHECK(latch >= trigger);
            CHECK(latch <= trigger + 2);
        } else {
            CHECK(latch <= trigger);
            CHECK(latch >= trigger - 2);
        }
        // Set zero: the latch point is now home_position; the other axis did not move.
        REQUIRE(r.set_at > 0);
        const Lsb physical = r.x[r.set_at - 1];  // where the axis rests, in the old coordinates
        CHECK(d.position(0) == c.home_position + (physical - latch));
        CHECK(d.position(1) == 777);
        // A move from the new coordinates is accepted: the producer chain restarted there.
        const Lsb here[kAxes] = {d.position(0), d.position(1)};
        const auto spans = test::trapezoid_move<kAxes>(here, 500, 8);
        const auto bytes = test::batch_bytes<kAxes>(spans, 0, spans.size());
        CHECK(d.accept_batch(d.last_accepted_sequence() + 1,
                             static_cast<std::uint16_t>(spans.size()), bytes.data(),
                             bytes.size()) == Status::kOk);
    }
}

TEST_CASE("homing pulls off the switch after setting zero", "[device][homing]") {
    for (bool positive : {false, true}) {
        const Lsb start[kAxes] = {5000, 777};
        const Lsb trigger = positive ? 20000 : 1000;
        Device d(start);
        REQUIRE(d.configure(test::test_limits<kAxes>()) == Status::kOk);
        HomingSequencer<kAxes, 32> h(d);
        HomingConfig c = config(positive);
        c.home_position = positive ? 300000 : 0;
        c.pull_off = 2000;
        REQUIRE(h.start(c) == Status::kOk);
        const Result r = run_homing(d, h, trigger, positive, 200000, [](std::uint32_t) {});
        REQUIRE(r.finished);
        REQUIRE(h.phase() == HomingPhase::kDone);
        CHECK(d.state() == DeviceState::kIdle);
        REQUIRE(r.set_at > 0);
        // Set zero, then a rest-to-rest move of exactly pull_off away from the switch.
        const Lsb physical = r.x[r.set_at - 1];
        const Lsb zeroed = c.home_position + (physical - h.latch_position());
        CHECK(d.position(0) == (positive ? zeroed - 2000 : zeroed + 2000));
        CHECK(d.position(1) == 777);
        // Off the switch: the physical position is 2000 LSB back from where the latch stop ended.
        const Lsb physical_end = physical + (positive ? -2000 : 2000);
        CHECK((positive ? physical_end < trigger : physical_end > trigger));
        // The pull-off ticks (new coordinates) stay within the limits too.
        for (std::size_t k = r.set_at + 2; k < r.x.size(); ++k) {
            REQUIRE(std::abs(r.x[k] - r.x[k - 1]) <= 200);
            REQUIRE(std::abs(r.x[k] - 2 * r.x[k - 1] + r.x[k - 2]) <= 3);
        }
    }
}

TEST_CASE("homing: a pull-off that does not clear the switch is an error", "[device][homing]") {
    const Lsb start[kAxes] = {5000, 0};
    Device d(start);
    REQUIRE(d.configure(test::test_limits<kAxes>()) == Status::kOk);
    HomingSequencer<kAxes, 32> h(d);
    HomingConfig c = config();
    c.pull_off = 10;  // the latch stop runs further past the switch point than this
    c.latch_velocity = 50000;
    REQUIRE(h.start(c) == Status::kOk);
    const Result r = run_homing(d, h, 1000, false, 200000, [](std::uint32_t) {});
    REQUIRE(r.finished);
    CHECK(h.phase() == HomingPhase::kError);
    CHECK(h.error() == HomingError::kSwitchStuck);
    CHECK(d.state() == DeviceState::kIdle);
}

TEST_CASE("homing errors: switch never found, switch stuck, e-stop, bad config, wrong state",
          "[device][homing]") {
    const Lsb start[kAxes] = {0, 0};
    SECTION("no switch within max_travel: stops after at most max_travel") {
        Device d(start);
        REQUIRE(d.configure(test::test_limits<kAxes>()) == Status::kOk);
        HomingSequencer<kAxes, 32> h(d);
        REQUIRE(h.start(config()) == Status::kOk);
        const Result r = run_homing(d, h, -1000000, false, 100000, [](std::uint32_t) {});
        REQUIRE(r.finished);
        CHECK(h.phase() == HomingPhase::kError);
        CHECK(h.error() == HomingError::kSwitchNotFound);
        CHECK(d.state() == DeviceState::kIdle);
        CHECK(r.x.back() == -40000);
        for (Lsb x : r.x) CHECK(x >= -40000);
    }
    SECTION("a switch still active after the back-off") {
        Device d(start);
        REQUIRE(d.configure(test::test_limits<kAxes>()) == Status::kOk);
        HomingSequencer<kAxes, 32> h(d);
        REQUIRE(h.start(config()) == Status::kOk);
        const Result r = run_homing(d, h, 1000000, false, 100000, [](std::uint32_t) {});
        REQUIRE(r.finished);
        CHECK(h.error() == HomingError::kSwitchStuck);
        CHECK(d.state() == DeviceState::kIdle);
    }
    SECTION("an e-stop interrupts homing") {
        Device d(start);
        REQUIRE(d.configure(test::test_limits<kAxes>()) == Status::kOk);
        HomingSequencer<kAxes, 32> h(d);
        REQUIRE(h.start(config()) == Status::kOk);
        const Result r = run_homing(
            d, h, -20000, false, 100000,
            [&](std::uint32_t k) {
                if (k == 300) d.set_estop_input(true);
            },
            300);
        REQUIRE(r.finished);
        CHECK(h.error() == HomingError::kInterrupted);
        CHECK(d.state() == DeviceState::kEstop);
        CHECK(r.x.size() ==
              301);  // the tick with the e-stop repeated the last setpoint; then homing ended
        CHECK(r.x[300] == r.x[299]);
    }
    SECTION("bad configuration and wrong state") {
        Device d(start);
        HomingSequencer<kAxes, 32> h(d);
        CHECK(h.start(config()) == Status::kNotConfigured);
        CHECK(h.error() == HomingError::kDeviceRefused);
        REQUIRE(d.configure(test::test_limits<kAxes>()) == Status::kOk);
        HomingConfig c = config();
        c.latch_velocity = 0;
        CHECK(h.start(c) == Status::kBadLimits);
        CHECK(h.error() == HomingError::kBadConfig);
        c = config();
        c.axis = 2;
        CHECK(h.start(c) == Status::kBadLimits);
        c = config();
        c.backoff = static_cast<std::uint32_t>(kMaxPositionLsb) + 1;  // the latch runs 2 x backoff
        CHECK(h.start(c) == Status::kBadLimits);
        CHECK(h.error() == HomingError::kBadConfig);
        c.backoff = static_cast<std::uint32_t>(kMaxPositionLsb);
        CHECK(h.start(c) == Status::kOk);
        d.raise_fault(FaultCode::kExternal);
        Lsb out[kAxes];
        d.tick(out);
        CHECK(h.start(config()) == Status::kWrongState);
    }
}
