// The simulated device: the core's stream tick for tick, pen switching, plant models, errors,
// producer starvation, and pacing through an injected clock.
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "pathstream/hal/linux_clock.hpp"
#include "pathstream/host/core_spans.hpp"
#include "pathstream/host/plan.hpp"
#include "pathstream/sim/device.hpp"
#include "pathstream/sim/plant.hpp"
#include "pathstream/sim/simulated_output.hpp"
#include "pathstream/sim/virtual_clock.hpp"
#include "pathstream/status.hpp"
#include "pathstream/tick_cubic.hpp"
#include "sim_plots.hpp"

using namespace pathstream;
using host::CoreSpan;
using host::MachineProfile;
using host::Plan;
using sim::PlantModel;
using sim::SimOptions;
using sim::SimulationResult;

namespace {

using Control = std::vector<std::array<std::int32_t, 4>>;
using LsbPoint = std::vector<std::int32_t>;

CoreSpan make_span(Basis basis, std::uint32_t ticks, const Control& control, bool pen_down) {
    CoreSpan s;
    s.basis = basis;
    s.ticks = ticks;
    s.control = control;
    s.pen_down = pen_down;
    REQUIRE(make_span_timing(basis, ticks, s.timing) == Status::kOk);
    for (const auto& c : control) {
        const std::int32_t p[4] = {c[0], c[1], c[2], c[3]};
        TickCubic cubic;
        REQUIRE(make_tick_cubic(basis, p, s.timing, cubic) == Status::kOk);
        s.cubic.push_back(cubic);
    }
    return s;
}

/// A straight Hermite span (tangents = chord): exactly linear in the tick.
CoreSpan line(const LsbPoint& from, const LsbPoint& to, std::uint32_t ticks, bool pen_down) {
    Control c;
    for (std::size_t a = 0; a < from.size(); ++a) {
        const std::int32_t d = to[a] - from[a];
        c.push_back({from[a], to[a], d, d});
    }
    return make_span(Basis::kHermite, ticks, c, pen_down);
}

/// Standing still at `at` (Hermite, zero tangents).
CoreSpan dwell(const LsbPoint& at, std::uint32_t ticks, bool pen_down) {
    Control c;
    for (std::int32_t v : at) c.push_back({v, v, 0, 0});
    return make_span(Basis::kHermite, ticks, c, pen_down);
}

/// A jump in one tick (Hermite with zero tangents): a step input for the plant.
CoreSpan step(const LsbPoint& from, const LsbPoint& to) {
    Control c;
    for (std::size_t a = 0; a < from.size(); ++a) c.push_back({from[a], to[a], 0, 0});
    return make_span(Basis::kHermite, 1, c, true);
}

Plan make_plan(std::vector<CoreSpan> spans) {
    Plan p;
    bool pen = false;
    for (const CoreSpan& s : spans) {
        if (s.pen_down != pen) p.pen.push_back({p.total_ticks, s.pen_down});
        pen = s.pen_down;
        p.total_ticks += s.ticks;
    }
    p.spans = std::move(spans);
    p.duration = static_cast<double>(p.total_ticks) / 1000.0;
    return p;
}

MachineProfile profile_for(std::size_t axes) {
    MachineProfile m;
    for (std::size_t a = 0; a < axes; ++a) {
        m.axes.push_back({std::string(1, "xyzabcuv"[a]), 200.0, 5000.0});
    }
    m.mm_per_lsb = 0.001;
    m.tick_hz = 1000;
    return m;
}

/// The plan of the first tests: travel, dwell with pen down, a Bezier curve, a line, dwell up.
Plan drawing_plan() {
    const LsbPoint o{0, 0}, a{3000, 1000}, b{9000, -2000}, c{1000, 4000};
    std::vector<CoreSpan> spans;
    spans.push_back(line(o, a, 10, false));
    spans.push_back(dwell(a, 5, true));
    spans.push_back(
        make_span(Basis::kBezier, 16, {{3000, 6000, 8000, 9000}, {1000, 5000, 3000, -2000}}, true));
    spans.push_back(line(b, c, 12, true));
    spans.push_back(dwell(c, 5, false));
    return make_plan(std::move(spans));
}

/// A pacing clock for tests: records every wait, reports `lag` ticks after the last wait.
class ScriptedClock final : public hal::Clock {
public:
    explicit ScriptedClock(std::uint64_t lag) : lag_(lag) {}
    std::uint64_t now() const override { return waits.empty() ? 0 : waits.back() + lag_; }
    void wait_until(std::uint64_t tick) override { waits.push_back(tick); }
    std::vector<std::uint64_t> waits;

private:
    std::uint64_t lag_;
};

}  // namespace

TEST_CASE("the simulated device plays a plan tick for tick as the core's evaluate_at predicts",
          "[sim]") {
    const Plan plan = drawing_plan();
    const MachineProfile profile = profile_for(2);
    std::vector<double> fractions;
    const SimulationResult r =
        sim::simulate(plan.spans, profile, SimOptions{}, [&](double f) { fractions.push_back(f); });

    REQUIRE(r.axes == 2);
    REQUIRE(r.plan_ticks == plan.total_ticks);
    REQUIRE(r.ticks == plan.total_ticks + 1);  // every span tick, then the end point
    std::uint64_t k = 0;
    for (const CoreSpan& s : plan.spans) {
        for (std::uint32_t j = 0; j < s.ticks; ++j, ++k) {
            for (std::size_t a = 0; a < 2; ++a) {
                INFO("tick " << k << " axis " << a);
                REQUIRE(r.setpoint(k, a) == host::core_value_at(s, a, j));
                REQUIRE(r.position(k, a) == r.setpoint(k, a) * profile.mm_per_lsb);
            }
            REQUIRE(r.pen[k] == (s.pen_down ? 1 : 0));
        }
    }
    CHECK(r.setpoint(k, 0) == 1000);  // the end point, held
    CHECK(r.setpoint(k, 1) == 4000);
    CHECK(r.pen[k] == 0);

    // The pen switches at the first tick of the spans that change it: the plan's pen events.
    REQUIRE(r.pen_switch_ticks == std::vector<std::uint64_t>{10, 43});
    REQUIRE(plan.pen.size() == 2);
    CHECK(plan.pen[0].tick == 10);
    CHECK(plan.pen[1].tick == 43);

    CHECK(r.underruns == 0);
    CHECK(r.spans_pushed == 5);
    CHECK(r.stream.spans_completed == 5);
    CHECK(r.stream.last_completed_tag == 5);
    CHECK(r.stream.ticks_executed == plan.total_ticks);
    CHECK(r.stream.idle_ticks == 1);
    CHECK(r.stream.max_queued <= sim::kQueueCapacity);
    CHECK_FALSE(r.paced);
    CHECK(r.late_ticks == 0);
    for (const auto& f : r.following) {
        CHECK(f.max_mm == 0);  // ideal plant: position = setpoint
        CHECK(f.rms_mm == 0);
    }
    CHECK(r.simulated_seconds == Approx(49.0 / 1000));
    REQUIRE_FALSE(fractions.empty());
    CHECK(std::is_sorted(fractions.begin(), fractions.end()));
    CHECK(fractions.back() == 1.0);

    const auto setpoints = host::setpoint_series(r);
    CHECK(setpoints.ticks() == r.ticks);
    CHECK(setpoints.quantum_mm == 0.001);
    CHECK(setpoints.at(10, 0) == Approx(3.0));
    const auto summary = host::run_summary(r);
    CHECK(summary.pen_switches == 2);
    CHECK(summary.spans == 5);
    CHECK(summary.max_following_error_mm.empty());
}

TEST_CASE("every axis count from 1 to 8 runs on its own SetpointStream instance", "[sim]") {
    for (std::size_t axes = 1; axes <= 8; ++axes) {
        LsbPoint from(axes), to(axes);
        for (std::size_t a = 0; a < axes; ++a) {
            from[a] = static_cast<std::int32_t>(100 * a);
            to[a] = static_cast<std::int32_t>(-700 + 333 * a);
        }
        // More spans than the queue holds: the producer must refill it as it drains.
        std::vector<CoreSpan> spans;
        for (int i = 0; i < 40; ++i)
            spans.push_back(line(i % 2 ? to : from, i % 2 ? from : to, 3, i % 3 == 0));
        const Plan plan = make_plan(spans);
        const SimulationResult r = sim::simulate(plan.spans, profile_for(axes), SimOptions{});
        INFO("axes " << axes);
        CHECK(r.axes == axes);
        CHECK(r.ticks == 121);
        CHECK(r.underruns == 0);
        CHECK(r.stream.spans_completed == 40);
        CHECK(r.stream.queue_full > 0);
        CHECK(r.stream.max_queued == sim::kQueueCapacity);
        for (std::size_t a = 0; a < axes; ++a) CHECK(r.setpoint(120, a) == from[a]);
    }
}

TEST_CASE("servo plant on a ramp lags by the analytic steady-state error", "[sim]") {
    const MachineProfile profile = profile_for(1);
    // 50 LSB per tick = 50 mm/s, exactly linear, across a span joint.
    const Plan plan =
        make_plan({line({0}, {100000}, 2000, true), line({100000}, {200000}, 2000, true)});
    for (double zeta : {1.0, 0.7, 2.0}) {
        SimOptions options;
        options.plant = PlantModel::kServo;
        options.servo.bandwidth_hz = 20;
        options.servo.damping = zeta;
        const SimulationResult r = sim::simulate(plan.spans, profile, options);
        const double omega = 2 * std::numbers::pi * 20, v = 50.0, t = 0.001;
        // Continuous lag 2 zeta v / omega; the setpoint held over the tick (zero-order hold)
        // adds half a tick, since the position is sampled at the instant the setpoint is issued.
        const double expected = v * (2 * zeta / omega + t / 2);
        INFO("zeta " << zeta << ", expected lag " << expected << " mm");
        for (std::uint64_t k = 1500; k < 4000; k += 250) {
            const double lag = r.setpoint(k, 0) * 0.001 - r.position(k, 0);
            CHECK(lag == Approx(expected).epsilon(1e-6));
        }
        if (zeta >= 1) {  // no overshoot: the lag rises monotonically to its steady value
            CHECK(r.following[0].max_mm == Approx(expected).epsilon(1e-6));
            CHECK(r.following[0].max_tick > 500);
        }
        CHECK(r.following[0].rms_mm > 0);
        CHECK(r.following[0].rms_mm < r.following[0].max_mm);
        const auto summary = host::run_summary(r);
        REQUIRE(summary.max_following_error_mm.size() == 1);
        CHECK(summary.plant.find("servo") != std::string::npos);
    }
}

TEST_CASE("servo plant step response matches the analytic one and settles", "[sim]") {
    const MachineProfile profile = profile_for(1);
    const double big = 10.0;  // mm
    const Plan plan =
        make_plan({dwell({0}, 10, true), step({0}, {10000}), dwell({10000}, 600, true)});
    for (double zeta : {1.0, 0.5}) {
        SimOptions options;
        options.plant = PlantModel::kServo;
        options.servo.bandwidth_hz = 25;
        options.servo.damping = zeta;
        options.settle_ticks = 100;
        const SimulationResult r = sim::simulate(plan.spans, profile, options);
        CHECK(r.ticks == 10 + 1 + 600 + 1 + 100);
        const double omega = 2 * std::numbers::pi * 25;
        const double wd = omega * std::sqrt(std::fabs(1 - zeta * zeta));
        double peak = 0;
        for (std::uint64_t k = 0; k < r.ticks; ++k) {
            // The step is the setpoint from tick 11 on (the 1-tick span's tick 0 is still 0).
            const double t = k >= 11 ? static_cast<double>(k - 11) * 0.001 : 0;
            double expected = 0;
            if (k >= 11) {
                expected =
                    zeta == 1.0
                        ? big * (1 - (1 + omega * t) * std::exp(-omega * t))
                        : big * (1 - std::exp(-zeta * omega * t) *
                                         (std::cos(wd * t) + zeta * omega / wd * std::sin(wd * t)));
            }
            INFO("zeta " << zeta << " tick " << k);
            REQUIRE(r.position(k, 0) == Approx(expected).margin(1e-9));
            peak = std::max(peak, r.position(k, 0));
        }
        if (zeta == 1.0) {
            CHECK(peak <= big + 1e-9);  // critically damped: no overshoot
            // 2 % settling time of a critically damped system: 5.834 / omega (37 ms here).
            const auto settled = static_cast<std::uint64_t>(11 + std::ceil(5.834 / omega / 0.001));
            for (std::uint64_t k = settled; k < r.ticks; ++k)
                REQUIRE(std::fabs(r.position(k, 0) - big) < 0.02 * big);
        } else {
            CHECK(peak > big * 1.10);  // 16.3 % overshoot in continuous time, sampled a bit less
            CHECK(peak < big * 1.17);
        }
        CHECK(std::fabs(r.position(r.ticks - 1, 0) - big) < 1e-6);
        CHECK(r.following[0].max_mm == Approx(big).margin(1e-9));  // the step itself
        CHECK(r.following[0].max_tick == 11);
    }
}

TEST_CASE("servo parameters are validated", "[sim]") {
    CHECK_THROWS_AS(sim::ServoAxis({0, 1}, 0.001, 0), std::invalid_argument);
    CHECK_THROWS_AS(sim::ServoAxis({10, -1}, 0.001, 0), std::invalid_argument);
    CHECK_THROWS_AS(sim::ServoAxis({10, 1}, 0, 0), std::invalid_argument);
    CHECK_THROWS_AS(sim::ServoAxis({NAN, 1}, 0.001, 0), std::invalid_argument);
    // Stable whatever the bandwidth against the tick: 10 kHz natural frequency at a 1 kHz tick.
    sim::ServoAxis fast({10000, 1}, 0.001, 0);
    for (int i = 0; i < 100; ++i) fast.step(1.0);
    CHECK(fast.position() == Approx(1.0).margin(1e-12));
    CHECK(std::string(sim::plant_name(PlantModel::kServo)) == "servo");
}

TEST_CASE("a plan the device refuses stops the simulation with the core's status", "[sim]") {
    const MachineProfile profile = profile_for(2);
    SECTION("discontinuous span") {
        const Plan plan =
            make_plan({line({0, 0}, {100, 0}, 4, true), line({101, 0}, {200, 0}, 4, true)});
        try {
            (void)sim::simulate(plan.spans, profile, SimOptions{});
            FAIL("expected a runtime_error");
        } catch (const std::runtime_error& e) {
            CHECK(std::string(e.what()) ==
                  "span 1 (tag 2): the device refused it: span does not start where the previous "
                  "one ends");
        }
    }
    SECTION("invalid span") {
        Plan plan = make_plan({line({0, 0}, {100, 0}, 4, true), line({100, 0}, {200, 0}, 4, true)});
        plan.spans[1].ticks = 0;  // hand-broken after validation
        CHECK_THROWS_WITH(sim::simulate(plan.spans, profile, SimOptions{}),
                          "span 1 (tag 2): the device refused it: tick count out of range");
    }
    SECTION("axis counts") {
        const Plan plan = make_plan({line({0, 0}, {100, 0}, 4, true)});
        CHECK_THROWS_AS(sim::simulate(plan.spans, profile_for(3), SimOptions{}),
                        std::invalid_argument);
        CHECK_THROWS_AS(sim::simulate({}, profile, SimOptions{}), std::invalid_argument);
    }
}

TEST_CASE("a producer that cannot keep up starves the queue: underruns are counted", "[sim]") {
    std::vector<CoreSpan> spans;
    for (int i = 0; i < 20; ++i) spans.push_back(line({i * 100}, {(i + 1) * 100}, 4, true));
    const Plan plan = make_plan(spans);
    SimOptions options;
    options.producer_interval_ticks = 10;  // one span every 10 ticks, each lasting 4
    options.max_pushes_per_run = 1;
    const SimulationResult r = sim::simulate(plan.spans, profile_for(1), options);
    CHECK(r.underruns == 19 * 6);  // after the first span, 6 idle ticks per 10
    CHECK(r.stream.spans_completed == 20);
    CHECK(r.stream.ticks_executed == 80);
    CHECK(r.ticks == 80 + r.underruns + 1);
    CHECK(r.setpoint(r.ticks - 1, 0) == 2000);
    // Holding while starved never jumps: every step is 0 or the 25 LSB/tick of the lines.
    for (std::uint64_t k = 1; k < r.ticks; ++k) {
        const auto d = r.setpoint(k, 0) - r.setpoint(k - 1, 0);
        REQUIRE((d == 0 || d == 25));
    }
    CHECK(sim::simulate(plan.spans, profile_for(1), SimOptions{}).underruns == 0);
}

TEST_CASE("pacing waits for every tick on the clock, in order, and counts late ticks", "[sim]") {
    const Plan plan = drawing_plan();
    SECTION("on time") {
        ScriptedClock clock(0);
        const SimulationResult r =
            sim::simulate_paced(plan.spans, profile_for(2), SimOptions{}, clock);
        REQUIRE(clock.waits.size() == r.ticks);
        for (std::uint64_t k = 0; k < r.ticks; ++k) REQUIRE(clock.waits[k] == k);
        CHECK(r.paced);
        CHECK(r.late_ticks == 0);
        CHECK(r.pen_switch_ticks == std::vector<std::uint64_t>{10, 43});  // device ticks
        CHECK(host::run_summary(r).realtime);
    }
    SECTION("behind") {
        ScriptedClock clock(2);
        const SimulationResult r =
            sim::simulate_paced(plan.spans, profile_for(2), SimOptions{}, clock);
        CHECK(r.late_ticks == r.ticks);
        CHECK(r.pen_switch_ticks ==
              std::vector<std::uint64_t>{10, 43});  // lateness does not move them
    }
    SECTION("the real-time option uses the Linux clock") {
        SimOptions options;
        options.realtime = true;
        const SimulationResult r = sim::simulate(plan.spans, profile_for(2), options);
        CHECK(r.paced);
        CHECK(r.ticks == 49);
    }
}

TEST_CASE("clocks and the simulated output keep their contracts", "[sim]") {
    sim::VirtualClock v;
    CHECK(v.now() == 0);
    v.wait_until(7);
    CHECK(v.now() == 7);
    v.wait_until(3);  // never goes back
    CHECK(v.now() == 7);

    sim::SimulatedOutput out(v);
    out.set(false);  // already inactive: no switch
    out.set(true);
    out.set(true);
    v.wait_until(9);
    out.set(false);
    CHECK(out.switch_ticks() == std::vector<std::uint64_t>{7, 9});
    CHECK_FALSE(out.state());

    hal::LinuxClock linux_clock(100000);  // 10 us ticks
    linux_clock.wait_until(20);
    CHECK(linux_clock.now() >= 20);
    CHECK_THROWS_AS(hal::LinuxClock(0), std::invalid_argument);
}

TEST_CASE("a simulator fed span by span runs as the whole plan, keeping no tick unless asked",
          "[sim]") {
    // 120 spans (more than the queue holds), pen changes, a servo plant; a fast, a starving and
    // a throttled producer, settling.
    std::vector<CoreSpan> spans;
    LsbPoint at{0, 0};
    for (int i = 0; i < 120; ++i) {
        const LsbPoint to{at[0] + 300 + 7 * i, at[1] + (i % 2 ? 250 : -180)};
        spans.push_back(i % 10 == 9 ? dwell(at, 6, i % 20 < 10)
                                    : line(at, to, 3 + i % 5, i % 20 < 10));
        if (i % 10 != 9) at = to;
    }
    const MachineProfile profile = profile_for(2);
    for (int variant = 0; variant < 4; ++variant) {
        SimOptions options;
        options.plant = PlantModel::kServo;
        options.servo.bandwidth_hz = 40;
        if (variant == 1) {
            options.producer_interval_ticks = 10;  // one span per 10 ticks: it starves
            options.max_pushes_per_run = 1;
        }
        if (variant == 2) options.settle_ticks = 50;
        if (variant == 3) {
            options.producer_interval_ticks = 2;  // three spans per 2 ticks: kept full
            options.max_pushes_per_run = 3;
        }
        INFO("variant " << variant);
        const SimulationResult whole = sim::simulate(spans, profile, options);

        SimOptions streamed = options;
        streamed.record_ticks = false;
        std::vector<Lsb> setpoints;
        std::vector<double> positions;
        std::vector<std::uint8_t> pen;
        sim::TickProbe last;
        streamed.tick_observer = [&](const sim::TickProbe& p) {
            setpoints.insert(setpoints.end(), p.setpoints, p.setpoints + 2);
            positions.insert(positions.end(), p.positions, p.positions + 2);
            pen.push_back(p.pen_down ? 1 : 0);
            last = p;
        };
        sim::Simulator simulator(profile, streamed);
        for (std::size_t i = 0; i < spans.size(); ++i) {
            simulator.push(spans[i]);
            // The device is kept fed: at most a queue and one span wait beyond what it took.
            if (variant == 0 && i > sim::kQueueCapacity + 1) {
                const std::size_t taken = last.last_completed_tag + last.queued_spans;
                REQUIRE(taken + sim::kQueueCapacity + 1 >= i + 1);
            }
        }
        const SimulationResult r = simulator.finish();
        CHECK(r.setpoints.empty());
        CHECK(r.positions.empty());
        CHECK(r.pen.empty());
        CHECK(setpoints == whole.setpoints);
        CHECK(positions == whole.positions);
        CHECK(pen == whole.pen);
        CHECK(r.ticks == whole.ticks);
        CHECK(r.plan_ticks == whole.plan_ticks);
        CHECK(r.spans_pushed == whole.spans_pushed);
        CHECK(r.underruns == whole.underruns);
        CHECK(r.pen_switch_ticks == whole.pen_switch_ticks);
        CHECK(r.stream.idle_ticks == whole.stream.idle_ticks);
        CHECK(r.stream.queue_full == whole.stream.queue_full);
        CHECK(r.stream.max_queued == whole.stream.max_queued);
        CHECK(r.stream.ticks_executed == whole.stream.ticks_executed);
        CHECK(last.ticks_pushed == whole.plan_ticks);
        for (std::size_t a = 0; a < 2; ++a) {
            CHECK(r.following[a].max_mm == whole.following[a].max_mm);
            CHECK(r.following[a].max_tick == whole.following[a].max_tick);
            CHECK(r.following[a].rms_mm == whole.following[a].rms_mm);
        }
        if (variant == 1) CHECK(r.underruns > 0);
    }
    sim::Simulator empty(profile, SimOptions{});
    CHECK_THROWS_AS(empty.finish(), std::invalid_argument);
    sim::Simulator wrong(profile, SimOptions{});
    wrong.push(spans[0]);
    CHECK_THROWS_WITH(wrong.push(line({0}, {10}, 2, true)), "span 1 has 1 axes, the first span 2");
}
