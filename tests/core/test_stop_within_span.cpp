// A hold or a stop acts inside a span: the controlled stop starts in the tick that takes the
// command, from the setpoint the span would have supplied there and the span's velocity at
// that tick, planned like a stop at a span's end; a resume re-enters there and the rest of
// the span plays. Checked on a 65,536-tick span (which once kept "running" for its whole
// minute after a stop) and at every tick offset of short spans.
#include <array>
#include <catch2/catch.hpp>
#include <cstdint>
#include <cstdlib>
#include <random>
#include <vector>

#include "core/device_fixture.hpp"
#include "pathstream/device/motion_device.hpp"
#include "pathstream/device/stop_spans.hpp"

using namespace pathstream;
using namespace pathstream::device;
using pathstream::test::batch_bytes;
using pathstream::test::test_limits;
using pathstream::test::trapezoid_move;

namespace {

constexpr unsigned kAxes = 2;
using Device = MotionDevice<kAxes, 64>;
using Point = std::array<Lsb, kAxes>;

// Every tick's setpoints, whether it was a path tick, and the state after it.
struct Run {
    std::vector<Point> ticks;
    std::vector<bool> path;
    std::vector<DeviceState> states;

    void tick(Device& d) {
        const std::uint64_t before = d.ticks_executed();
        Lsb out[kAxes];
        d.tick(out);
        ticks.push_back({out[0], out[1]});
        path.push_back(d.ticks_executed() != before);
        states.push_back(d.state());
    }
    void run(Device& d, std::size_t count) {
        for (std::size_t i = 0; i < count; ++i) tick(d);
    }
    // Ticks until `done` holds after a tick (at most `limit`): how many were run.
    template <typename Done>
    std::size_t run_until(Device& d, Done done, std::size_t limit) {
        for (std::size_t i = 1; i <= limit; ++i) {
            tick(d);
            if (done()) return i;
        }
        return limit + 1;
    }
    std::vector<Point> path_ticks() const {
        std::vector<Point> out;
        for (std::size_t i = 0; i < ticks.size(); ++i) {
            if (path[i]) out.push_back(ticks[i]);
        }
        return out;
    }
    // Every step within the velocity limit and every second difference within the
    // acceleration limit, plus the core's one rounding (1 LSB in a step, 2 in a second
    // difference), per axis over the whole run.
    void check_limits(const MotionLimits<kAxes>& l) const {
        for (unsigned a = 0; a < kAxes; ++a) {
            const double v = static_cast<double>(l.axis[a].max_velocity) / l.tick_hz + 1;
            const double acc =
                static_cast<double>(l.axis[a].max_acceleration) / l.tick_hz / l.tick_hz + 2;
            for (std::size_t i = 1; i < ticks.size(); ++i) {
                INFO("axis " << a << " tick " << i);
                REQUIRE(std::llabs(std::int64_t{ticks[i][a]} - ticks[i - 1][a]) <= v);
                if (i >= 2) {
                    REQUIRE(std::llabs(std::int64_t{ticks[i][a]} -
                                       2 * std::int64_t{ticks[i - 1][a]} + ticks[i - 2][a]) <= acc);
                }
            }
        }
    }
};

// One span of `ticks` ticks from rest at `start` to rest `distance` LSB further on axis 0
// (half as far on axis 1): the job's only span.
WireSpan long_span(const Lsb (&start)[kAxes], std::int32_t distance, std::uint32_t ticks) {
    WireSpan w;
    w.ticks = ticks;
    w.flags = kWireJobEnd;
    w.outputs = kOutputPenDown;
    w.end[0] = start[0] + distance;
    w.end[1] = start[1] + distance / 2;
    return w;
}

Status send(Device& d, const std::vector<WireSpan>& spans, std::size_t first, std::size_t count) {
    const auto bytes = batch_bytes<kAxes>(spans, first, count);
    return d.accept_batch(d.last_accepted_sequence() + 1, static_cast<std::uint16_t>(count),
                          bytes.data(), bytes.size());
}

// 0.2 LSB/tick^2: a stop from ~40 LSB/tick needs ~200 ticks, more than the shortest base.
MotionLimits<kAxes> gentle_limits() {
    MotionLimits<kAxes> l = test_limits<kAxes>();
    for (unsigned a = 0; a < kAxes; ++a) l.axis[a].max_acceleration = 200000;
    return l;
}

bool own_move(const Device& d) {
    return (d.status().flags & kStatusOwnMove) != 0;
}

constexpr std::uint32_t kLongTicks = 65536;
constexpr std::size_t kStopAt = 20000;  // the command's tick: 0.31 of the span, ~39 LSB/tick

}  // namespace

TEST_CASE("velocity_within_span is the span's velocity at the tick, rounded on the base",
          "[device][stop]") {
    std::mt19937_64 rng(20261126);
    const auto pick = [&](std::int64_t lo, std::int64_t hi) {
        return std::uniform_int_distribution<std::int64_t>(lo, hi)(rng);
    };
    MotionLimits<1> limits;
    limits.tick_hz = 1000;
    for (int trial = 0; trial < 20000; ++trial) {
        const auto n =
            static_cast<std::uint32_t>(trial % 3 == 0 ? pick(1, 16) : pick(1, kMaxSpanTicks));
        const auto k = static_cast<std::uint32_t>(pick(0, n));
        const std::int32_t chord[1] = {static_cast<std::int32_t>(pick(-(1 << 28), 1 << 28))};
        const std::int32_t t0[1] = {static_cast<std::int32_t>(pick(-(1 << 29), 1 << 29))};
        const std::int32_t t1[1] = {static_cast<std::int32_t>(pick(-(1 << 29), 1 << 29))};
        limits.axis[0].max_acceleration = static_cast<std::uint32_t>(pick(1, 0xFFFFFFFF));
        std::int32_t tangent[1];
        std::uint32_t base = 0;
        const Status s = velocity_within_span(chord, t0, t1, n, k, limits, tangent, base);
        // The exact velocity, M / n^3 LSB per tick, in 128-bit host arithmetic.
        const __int128 nn = n, kk = k;
        const __int128 m = 6 * kk * (nn - kk) * chord[0] + (nn - kk) * (nn - 3 * kk) * t0[0] +
                           kk * (3 * kk - 2 * nn) * t1[0];
        const __int128 cube = nn * nn * nn;
        INFO("n " << n << " k " << k << " chord " << chord[0] << " t0 " << t0[0] << " t1 "
                  << t1[0]);
        if (s != Status::kOk) {
            // Only a tangent beyond the range refuses.
            REQUIRE(s == Status::kStopTooLong);
            REQUIRE((m < 0 ? -m : m) * base > cube * kMaxTangentLsb);
            continue;
        }
        REQUIRE(base >= 1);
        REQUIRE(base <= n);
        // tangent / base within half a unit of base * M / n^3.
        const __int128 error = static_cast<__int128>(tangent[0]) * cube - m * base;
        REQUIRE((error < 0 ? -error : error) * 2 <= cube);
        if (n <= kMinInSpanStopBase) REQUIRE(base == n);
        if (base != n) REQUIRE(base >= kMinInSpanStopBase);
        if (k == n && base == n) REQUIRE(tangent[0] == t1[0]);  // a stop at the end: exactly T1
        if (k == 0 && base == n) REQUIRE(tangent[0] == t0[0]);
    }
}

TEST_CASE("a hold inside a 65,536-tick span stops from the tick that takes it, and resumes there",
          "[device][stop]") {
    const Lsb start[kAxes] = {1000, -1000};
    const auto limits = gentle_limits();
    const std::vector<WireSpan> spans = {long_span(start, 2000000, kLongTicks)};
    Device twin(start), d(start);
    for (Device* x : {&twin, &d}) {
        REQUIRE(x->configure(limits) == Status::kOk);
        REQUIRE(send(*x, spans, 0, 1) == Status::kOk);
        REQUIRE(x->command(Command::kStart) == Status::kOk);
    }
    Run whole, r;
    whole.run(twin, kLongTicks + 1);
    REQUIRE(twin.state() == DeviceState::kIdle);
    REQUIRE(twin.finished_job() == 1);

    r.run(d, kStopAt);
    REQUIRE(d.command(Command::kHold) == Status::kOk);
    r.tick(d);
    // Reaction: the tick that takes the hold already belongs to the stop. It outputs the
    // setpoint the span would have supplied and supplies none of the span's ticks.
    CHECK(d.state() == DeviceState::kHolding);
    CHECK_FALSE(r.path.back());
    CHECK(r.ticks.back() == whole.ticks[kStopAt]);
    CHECK(d.ticks_executed() == kStopAt);
    // The stop takes the fewest ticks the acceleration limit allows from there (~194 at
    // 0.2 LSB/tick^2 from ~39 LSB/tick), not the span's remaining 45,536.
    const double v = static_cast<double>(whole.ticks[kStopAt + 1][0] - whole.ticks[kStopAt][0]);
    const double fewest = v / (limits.axis[0].max_acceleration / 1e6);
    const std::size_t to_rest = r.run_until(
        d, [&] { return !own_move(d); }, kLongTicks);
    CHECK(to_rest + 1 >= static_cast<std::size_t>(fewest));
    CHECK(to_rest <= 2 * static_cast<std::size_t>(fewest + 1));
    CHECK(d.state() == DeviceState::kHolding);
    // The first step of the stop continues the span's velocity (within the rounding).
    for (unsigned a = 0; a < kAxes; ++a) {
        const std::int64_t path_step =
            std::int64_t{whole.ticks[kStopAt + 1][a]} - whole.ticks[kStopAt][a];
        const std::int64_t stop_step = std::int64_t{r.ticks[kStopAt + 1][a]} - r.ticks[kStopAt][a];
        CHECK(std::llabs(stop_step - path_step) <= 1);
    }
    r.run(d, 100);
    CHECK(r.ticks.back() == r.ticks[r.ticks.size() - 101]);  // holding still

    REQUIRE(d.command(Command::kResume) == Status::kOk);
    r.run_until(
        d, [&] { return d.state() == DeviceState::kIdle; }, 2 * kLongTicks);
    REQUIRE(d.state() == DeviceState::kIdle);
    CHECK(d.finished_job() == 1);
    // Every tick of the span was supplied exactly once, the same setpoints as without the hold.
    CHECK(d.ticks_executed() == kLongTicks);
    CHECK(r.path_ticks() == whole.path_ticks());
    CHECK(r.ticks.back() == whole.ticks.back());
    r.check_limits(limits);
}

TEST_CASE("a stop inside a 65,536-tick span ends within the stopping distance, not the span",
          "[device][stop]") {
    const Lsb start[kAxes] = {0, 0};
    const auto limits = gentle_limits();
    const std::vector<WireSpan> spans = {long_span(start, 2000000, kLongTicks)};
    Device d(start);
    REQUIRE(d.configure(limits) == Status::kOk);
    REQUIRE(send(d, spans, 0, 1) == Status::kOk);
    REQUIRE(d.command(Command::kStart) == Status::kOk);
    Run r;
    r.run(d, kStopAt);
    REQUIRE(d.command(Command::kStop) == Status::kOk);
    r.tick(d);
    CHECK(d.state() == DeviceState::kStopping);
    CHECK_FALSE(r.path.back());
    const std::size_t to_idle = r.run_until(
        d, [&] { return d.state() == DeviceState::kIdle; }, kLongTicks);
    CHECK(to_idle <= 2 * 200);  // ~195 ticks needed from ~39 LSB/tick at 0.2 LSB/tick^2
    CHECK(d.queued_spans() == 0);
    CHECK(d.finished_job() == 0);  // the job was stopped, not finished
    CHECK(d.ticks_executed() == kStopAt);
    r.run(d, 10);
    CHECK(r.ticks.back() == r.ticks[r.ticks.size() - 11]);
    r.check_limits(limits);
    // The next batch starts where the axes stopped, at rest.
    const Lsb here[kAxes] = {r.ticks.back()[0], r.ticks.back()[1]};
    const std::vector<WireSpan> again = {long_span(here, 5000, 512)};
    CHECK(send(d, again, 0, 1) == Status::kOk);
}

TEST_CASE("a hold at any tick of a span leaves the path in the tick that takes it",
          "[device][stop]") {
    const Lsb start[kAxes] = {0, 0};
    const auto limits = test_limits<kAxes>();
    auto spans = trapezoid_move<kAxes>(start, 20000, 8);
    REQUIRE(spans.size() <= 64);
    spans.back().flags |= kWireJobEnd;
    std::uint64_t total = 0;
    for (const auto& s : spans) total += s.ticks;
    Device twin(start);
    REQUIRE(twin.configure(limits) == Status::kOk);
    REQUIRE(send(twin, spans, 0, spans.size()) == Status::kOk);
    REQUIRE(twin.command(Command::kStart) == Status::kOk);
    Run whole;
    whole.run(twin, total + 1);
    for (std::size_t at = 40; at < 56; ++at) {  // at speed: two spans' worth of offsets
        INFO("hold taken at tick " << at);
        Device d(start);
        REQUIRE(d.configure(limits) == Status::kOk);
        REQUIRE(send(d, spans, 0, spans.size()) == Status::kOk);
        REQUIRE(d.command(Command::kStart) == Status::kOk);
        Run r;
        r.run(d, at);
        REQUIRE(d.command(Command::kHold) == Status::kOk);
        r.tick(d);
        CHECK(d.state() == DeviceState::kHolding);
        CHECK_FALSE(r.path.back());
        CHECK(r.ticks.back() == whole.ticks[at]);
        r.run(d, 200);
        REQUIRE(d.command(Command::kResume) == Status::kOk);
        r.run_until(
            d, [&] { return d.state() == DeviceState::kIdle; }, 2000);
        CHECK(d.finished_job() == 1);
        CHECK(d.ticks_executed() == total);
        CHECK(r.path_ticks() == whole.path_ticks());
        r.check_limits(limits);
    }
}

TEST_CASE("an underrun after a long moving span stops within the stopping distance, not the span",
          "[device][stop]") {
    // 8,192 ticks from rest at 0.004 LSB/tick^2 to ~33 LSB/tick, then (sent late) 8,192 ticks
    // back to rest. With nothing queued at the first span's end, the device stops there by
    // itself: planned like a stop inside a span, it takes the ~164 ticks 0.2 LSB/tick^2 needs,
    // not the span's 8,192 (a stop on the span's own length once ran on for ~134,000 LSB).
    constexpr std::uint32_t kTicks = 8192;
    constexpr std::int32_t kDistance = 134217;
    const Lsb start[kAxes] = {1000, -1000};
    const auto limits = gentle_limits();
    std::vector<WireSpan> spans(2);
    for (unsigned a = 0; a < kAxes; ++a) {
        const std::int32_t d = kDistance / static_cast<std::int32_t>(a + 1);
        spans[0].end[a] = start[a] + d;
        spans[0].end_tangent[a] = 2 * d;
        spans[1].start_tangent[a] = 2 * d;
        spans[1].end[a] = start[a] + 2 * d;
    }
    spans[0].ticks = spans[1].ticks = kTicks;
    spans[0].outputs = spans[1].outputs = kOutputPenDown;
    spans[1].flags = kWireJobEnd;
    Device twin(start), d(start);
    for (Device* x : {&twin, &d}) REQUIRE(x->configure(limits) == Status::kOk);
    REQUIRE(send(twin, spans, 0, 2) == Status::kOk);
    REQUIRE(twin.command(Command::kStart) == Status::kOk);
    Run whole, r;
    whole.run_until(
        twin, [&] { return twin.state() == DeviceState::kIdle; }, 4 * kTicks);
    REQUIRE(twin.finished_job() == 1);
    REQUIRE(twin.underruns() == 0);

    REQUIRE(send(d, spans, 0, 1) == Status::kOk);
    REQUIRE(d.command(Command::kStart) == Status::kOk);
    r.run(d, kTicks);
    REQUIRE(d.ticks_executed() == kTicks);
    const std::size_t to_rest = r.run_until(
        d, [&] { return !own_move(d) && d.state() == DeviceState::kHolding; }, 4 * kTicks);
    CHECK(d.underruns() == 1);
    CHECK(d.held_by_underrun());
    const double v = static_cast<double>(whole.ticks[kTicks][0] - whole.ticks[kTicks - 1][0]);
    const double fewest = v / (limits.axis[0].max_acceleration / 1e6);
    CHECK(to_rest + 1 >= static_cast<std::size_t>(fewest));
    CHECK(to_rest <= 2 * static_cast<std::size_t>(fewest + 1));
    // The stop starts at the boundary point and its first step continues the span's velocity
    // (within the rounding).
    CHECK(r.ticks[kTicks] == whole.ticks[kTicks]);
    for (unsigned a = 0; a < kAxes; ++a) {
        const std::int64_t path_step =
            std::int64_t{whole.ticks[kTicks + 1][a]} - whole.ticks[kTicks][a];
        const std::int64_t stop_step = std::int64_t{r.ticks[kTicks + 1][a]} - r.ticks[kTicks][a];
        CHECK(std::llabs(stop_step - path_step) <= 1);
    }
    r.run(d, 100);
    CHECK(r.ticks.back() == r.ticks[r.ticks.size() - 101]);  // holding still

    // The next span arrives: resume re-enters at the boundary and the rest plays as queued.
    REQUIRE(send(d, spans, 1, 1) == Status::kOk);
    REQUIRE(d.command(Command::kResume) == Status::kOk);
    r.run_until(
        d, [&] { return d.state() == DeviceState::kIdle; }, 4 * kTicks);
    REQUIRE(d.state() == DeviceState::kIdle);
    CHECK(d.finished_job() == 1);
    CHECK(d.ticks_executed() == 2 * kTicks);
    CHECK(r.path_ticks() == whole.path_ticks());
    CHECK(r.ticks.back() == whole.ticks.back());
    r.check_limits(limits);
}
