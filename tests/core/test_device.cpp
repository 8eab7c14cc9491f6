// The device state machine, black box: batches in, commands, ticks out. Every run checks the
// limits on every tick of what the axes were given (integer setpoints, with the rounding
// allowance of one LSB per tick in velocity and two in acceleration).
#include <catch2/catch.hpp>
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "core/device_fixture.hpp"
#include "pathstream/device/motion_device.hpp"
#include "pathstream/setpoint_stream.hpp"

using namespace pathstream;
using namespace pathstream::device;
using pathstream::test::batch_bytes;
using pathstream::test::test_limits;
using pathstream::test::trapezoid_move;

namespace {

constexpr unsigned kAxes = 2;
using Device = MotionDevice<kAxes, 16>;

struct Recorder {
    std::vector<std::array<Lsb, kAxes>> ticks;
    std::vector<DeviceState> states;

    void run(Device& d, std::uint64_t count) {
        for (std::uint64_t i = 0; i < count; ++i) {
            Lsb out[kAxes];
            d.tick(out);
            ticks.push_back({out[0], out[1]});
            states.push_back(d.state());
        }
    }
    // Largest |first| and |second| difference per axis over every recorded tick, LSB/tick^k.
    void check_limits(const MotionLimits<kAxes>& limits) const {
        for (unsigned a = 0; a < kAxes; ++a) {
            const double v_max =
                static_cast<double>(limits.axis[a].max_velocity) / limits.tick_hz + 1;
            const double a_max = static_cast<double>(limits.axis[a].max_acceleration) /
                                     limits.tick_hz / limits.tick_hz +
                                 2;
            for (std::size_t k = 1; k < ticks.size(); ++k) {
                const double v = ticks[k][a] - ticks[k - 1][a];
                INFO("axis " << a << " tick " << k);
                REQUIRE(std::abs(v) <= v_max);
                if (k >= 2) {
                    const double acc = ticks[k][a] - 2.0 * ticks[k - 1][a] + ticks[k - 2][a];
                    REQUIRE(std::abs(acc) <= a_max);
                }
            }
        }
    }
};

Status send(Device& d, std::uint32_t sequence, const std::vector<WireSpan>& spans,
            std::size_t first, std::size_t count) {
    const auto bytes = batch_bytes<kAxes>(spans, first, count);
    return d.accept_batch(sequence, static_cast<std::uint16_t>(count), bytes.data(), bytes.size());
}

// The same spans through a bare SetpointStream: what the device must reproduce tick for tick.
std::vector<std::array<Lsb, kAxes>> reference_ticks(const Lsb (&start)[kAxes],
                                                    const std::vector<WireSpan>& spans) {
    SetpointStream<kAxes, 1024> stream(start);
    Lsb from[kAxes] = {start[0], start[1]};
    std::int32_t tangent[kAxes] = {0, 0};
    std::uint64_t total = 0;
    for (std::size_t i = 0; i < spans.size(); ++i) {
        WireSpan w = spans[i];
        if ((w.flags & kWireContinueTangent) != 0) {
            for (unsigned a = 0; a < kAxes; ++a) w.start_tangent[a] = tangent[a];
        }
        REQUIRE(stream.push(to_core_span<kAxes>(w, from, static_cast<std::uint32_t>(i + 1))) ==
                Status::kOk);
        for (unsigned a = 0; a < kAxes; ++a) {
            from[a] = w.end[a];
            tangent[a] = w.end_tangent[a];
        }
        total += w.ticks;
    }
    std::vector<std::array<Lsb, kAxes>> out;
    for (std::uint64_t k = 0; k <= total; ++k) {
        Lsb p[kAxes];
        (void)stream.tick(p);
        out.push_back({p[0], p[1]});
    }
    return out;
}

}  // namespace

TEST_CASE("device executes accepted batches tick for tick like the bare stream", "[device]") {
    const Lsb start[kAxes] = {1000, -2000};
    Device d(start);
    REQUIRE(d.configure(test_limits<kAxes>()) == Status::kOk);
    const auto spans = trapezoid_move<kAxes>(start, 60000, 8);
    REQUIRE(spans.size() > 40);
    REQUIRE(send(d, 1, spans, 0, 10) == Status::kOk);
    CHECK(d.last_accepted_sequence() == 10);
    CHECK(d.state() == DeviceState::kIdle);
    REQUIRE(d.command(Command::kStart) == Status::kOk);

    Recorder r;
    std::size_t sent = 10;
    while (sent < spans.size() || d.queued_spans() > 0) {
        const std::size_t room = std::min<std::size_t>(d.free_slots(), spans.size() - sent);
        if (room >= 4 || (room > 0 && sent + room == spans.size())) {
            REQUIRE(send(d, static_cast<std::uint32_t>(sent + 1), spans, sent, room) ==
                    Status::kOk);
            sent += room;
        }
        r.run(d, 5);
    }
    r.run(d, 3);
    const auto expected = reference_ticks(start, spans);
    REQUIRE(r.ticks.size() >= expected.size());
    for (std::size_t k = 0; k < expected.size(); ++k) {
        INFO("tick " << k);
        REQUIRE(r.ticks[k] == expected[k]);
    }
    CHECK(d.underruns() == 0);
    CHECK(d.state() == DeviceState::kRunning);
    CHECK(d.last_completed_sequence() == spans.size());
    CHECK(d.ticks_executed() == expected.size() - 1);
    CHECK(d.position(0) == spans.back().end[0]);
    r.check_limits(test_limits<kAxes>());
}

TEST_CASE("batches are all or nothing", "[device]") {
    const Lsb start[kAxes] = {0, 0};
    Device d(start);
    const auto spans = trapezoid_move<kAxes>(start, 20000, 8);

    SECTION("unconfigured") {
        CHECK(send(d, 1, spans, 0, 3) == Status::kNotConfigured);
    }

    REQUIRE(d.configure(test_limits<kAxes>()) == Status::kOk);
    SECTION("a span over the acceleration limit in the middle refuses the whole batch") {
        auto bad = spans;
        bad[2].end[0] += 4000;  // a kink: far more than 2 LSB/tick^2
        CHECK(send(d, 1, bad, 0, 5) == Status::kAccelerationLimit);
        CHECK(d.queued_spans() == 0);
        CHECK(d.last_accepted_sequence() == 0);
        CHECK(send(d, 1, spans, 0, 5) == Status::kOk);
        CHECK(d.queued_spans() == 5);
    }
    SECTION("velocity over the limit") {
        auto bad = spans;
        bad[0].end[1] = 2000;                 // 2000 LSB in 8 ticks from rest
        bad[0].end_tangent[1] = 2 * 8 * 250;  // ends at 500 LSB/tick
        CHECK(send(d, 1, bad, 0, 1) != Status::kOk);
        CHECK(d.queued_spans() == 0);
    }
    SECTION("sequence numbers") {
        REQUIRE(send(d, 1, spans, 0, 3) == Status::kOk);
        CHECK(send(d, 5, spans, 3, 2) == Status::kBadSequence);  // gap
        CHECK(send(d, 3, spans, 2, 2) == Status::kBadSequence);  // partial overlap
        CHECK(send(d, 1, spans, 0, 3) == Status::kOk);           // retry of the last batch
        CHECK(d.duplicates() == 1);
        CHECK(d.queued_spans() == 3);
        CHECK(send(d, 4, spans, 3, 2) == Status::kOk);
        CHECK(d.last_accepted_sequence() == 5);
    }
    SECTION("length and count") {
        auto bytes = batch_bytes<kAxes>(spans, 0, 3);
        CHECK(d.accept_batch(1, 4, bytes.data(), bytes.size()) == Status::kBadBatch);
        CHECK(d.accept_batch(1, 2, bytes.data(), bytes.size()) == Status::kBadBatch);
        CHECK(d.accept_batch(1, 0, bytes.data(), 0) == Status::kBadBatch);
        bytes.push_back(0);
        CHECK(d.accept_batch(1, 3, bytes.data(), bytes.size()) == Status::kBadBatch);
        CHECK(d.queued_spans() == 0);
    }
    SECTION("queue full") {
        REQUIRE(send(d, 1, spans, 0, 14) == Status::kOk);
        CHECK(send(d, 15, spans, 14, 3) == Status::kQueueFull);
        CHECK(send(d, 15, spans, 14, 2) == Status::kOk);
    }
    SECTION("limits cannot change with spans queued") {
        REQUIRE(send(d, 1, spans, 0, 2) == Status::kOk);
        CHECK(d.configure(test_limits<kAxes>()) == Status::kWrongState);
        auto zero = test_limits<kAxes>();
        zero.axis[1].max_acceleration = 0;
        CHECK(d.configure(zero) == Status::kBadLimits);
    }
}

TEST_CASE("queue running dry mid-move: controlled stop within limits, then resume", "[device]") {
    const Lsb start[kAxes] = {0, 0};
    Device d(start);
    REQUIRE(d.configure(test_limits<kAxes>()) == Status::kOk);
    const auto spans = trapezoid_move<kAxes>(start, 80000, 8);
    const std::size_t half = spans.size() / 2;  // cruising at full speed there
    REQUIRE(send(d, 1, spans, 0, 16) == Status::kOk);
    REQUIRE(d.command(Command::kStart) == Status::kOk);
    Recorder r;
    std::size_t sent = 16;
    while (sent < half) {
        r.run(d, 8);
        const std::size_t n = std::min<std::size_t>(d.free_slots(), half - sent);
        if (n > 0) {
            REQUIRE(send(d, static_cast<std::uint32_t>(sent + 1), spans, sent, n) == Status::kOk);
            sent += n;
        }
    }
    r.run(d, 16 * 8 + 400);  // the queue runs dry, the device stops by itself
    CHECK(d.underruns() == 1);
    CHECK(d.state() == DeviceState::kHolding);
    CHECK(d.held_by_underrun());
    CHECK(d.last_completed_sequence() == half);
    const auto rest = r.ticks.back();
    r.run(d, 10);
    CHECK(r.ticks.back() == rest);  // at rest
    CHECK(d.command(Command::kResume) == Status::kNothingToResume);

    // The link comes back: the rest of the move, then resume.
    while (sent < spans.size()) {
        const std::size_t n = std::min<std::size_t>(d.free_slots(), spans.size() - sent);
        if (n > 0) {
            REQUIRE(send(d, static_cast<std::uint32_t>(sent + 1), spans, sent, n) == Status::kOk);
            sent += n;
        }
        if (d.state() == DeviceState::kHolding) REQUIRE(d.command(Command::kResume) == Status::kOk);
        r.run(d, 64);
    }
    r.run(d, 2000);
    CHECK(d.state() == DeviceState::kRunning);
    CHECK(d.last_completed_sequence() == spans.size());
    CHECK(r.ticks.back()[0] == spans.back().end[0]);
    CHECK(r.ticks.back()[1] == spans.back().end[1]);
    // Every path tick was executed exactly once: the stream's own count.
    std::uint64_t path_ticks = 0;
    for (const auto& s : spans) path_ticks += s.ticks;
    CHECK(d.ticks_executed() == path_ticks);
    CHECK(d.generated_ticks() > 0);
    r.check_limits(test_limits<kAxes>());
}

TEST_CASE("hold and resume mid-move, and stop", "[device]") {
    const Lsb start[kAxes] = {500, 500};
    Device d(start);
    REQUIRE(d.configure(test_limits<kAxes>()) == Status::kOk);
    const auto spans = trapezoid_move<kAxes>(start, 40000, 8);
    REQUIRE(spans.size() <= 64);
    Recorder r;
    std::size_t sent = 0;
    auto feed = [&] {
        const std::size_t n = std::min<std::size_t>(d.free_slots(), spans.size() - sent);
        if (n > 0 && d.state() != DeviceState::kStopping) {
            REQUIRE(send(d, static_cast<std::uint32_t>(sent + 1), spans, sent, n) == Status::kOk);
            sent += n;
        }
    };
    feed();
    REQUIRE(d.command(Command::kStart) == Status::kOk);
    r.run(d, 80);
    feed();
    r.run(d, 40);
    REQUIRE(d.command(Command::kHold) == Status::kOk);
    r.run(d, 300);
    CHECK(d.state() == DeviceState::kHolding);
    CHECK_FALSE(d.held_by_underrun());
    CHECK(d.command(Command::kStart) == Status::kWrongState);
    REQUIRE(d.command(Command::kResume) == Status::kOk);
    for (int i = 0; i < 200; ++i) {
        feed();
        r.run(d, 8);
    }
    CHECK(d.last_completed_sequence() == spans.size());
    CHECK(r.ticks.back()[0] == spans.back().end[0]);
    r.check_limits(test_limits<kAxes>());

    SECTION("stop drops the queue and the next batch starts where the axes stopped") {
        const Lsb here[kAxes] = {r.ticks.back()[0], r.ticks.back()[1]};
        const auto back = trapezoid_move<kAxes>(here, -30000, 8);
        REQUIRE(send(d, static_cast<std::uint32_t>(spans.size() + 1), back, 0, 12) == Status::kOk);
        r.run(d, 100);
        REQUIRE(d.command(Command::kStop) == Status::kOk);
        r.run(d, 400);
        CHECK(d.state() == DeviceState::kIdle);
        CHECK(d.queued_spans() == 0);
        const Lsb stopped[kAxes] = {r.ticks.back()[0], r.ticks.back()[1]};
        const auto again = trapezoid_move<kAxes>(stopped, 5000, 8);
        const std::uint32_t next = d.last_accepted_sequence() + 1;
        REQUIRE(send(d, next, again, 0, 3) == Status::kOk);
        r.check_limits(test_limits<kAxes>());
    }
}

TEST_CASE("e-stop freezes within one tick and needs an explicit reset", "[device]") {
    const Lsb start[kAxes] = {0, 0};
    Device d(start);
    REQUIRE(d.configure(test_limits<kAxes>()) == Status::kOk);
    const auto spans = trapezoid_move<kAxes>(start, 40000, 8);
    REQUIRE(send(d, 1, spans, 0, 16) == Status::kOk);
    REQUIRE(d.command(Command::kStart) == Status::kOk);
    Recorder r;
    r.run(d, 100);
    d.set_estop_input(true);
    r.run(d, 1);
    CHECK(d.state() == DeviceState::kEstop);
    CHECK(r.ticks[100] == r.ticks[99]);  // the tick after the edge repeats the last setpoint
    r.run(d, 20);
    CHECK(r.ticks.back() == r.ticks[99]);
    CHECK(d.queued_spans() == 0);
    CHECK(d.command(Command::kReset) == Status::kWrongState);  // input still active
    CHECK(send(d, 17, spans, 16, 2) == Status::kWrongState);
    d.set_estop_input(false);
    REQUIRE(d.command(Command::kReset) == Status::kOk);
    r.run(d, 1);
    CHECK(d.state() == DeviceState::kIdle);
    // The chain restarts where the axes froze.
    const Lsb here[kAxes] = {r.ticks.back()[0], r.ticks.back()[1]};
    const auto again = trapezoid_move<kAxes>(here, 1000, 8);
    CHECK(send(d, 17, again, 0, 2) == Status::kOk);
}

TEST_CASE("faults stop at once and keep the first code", "[device]") {
    const Lsb start[kAxes] = {0, 0};
    Device d(start);
    REQUIRE(d.configure(test_limits<kAxes>()) == Status::kOk);
    const auto spans = trapezoid_move<kAxes>(start, 40000, 8);
    REQUIRE(send(d, 1, spans, 0, 16) == Status::kOk);
    REQUIRE(d.command(Command::kStart) == Status::kOk);
    Recorder r;
    r.run(d, 50);
    d.raise_fault(static_cast<FaultCode>(0x0103));
    d.raise_fault(FaultCode::kExternal);
    r.run(d, 5);
    CHECK(d.state() == DeviceState::kFault);
    CHECK(static_cast<unsigned>(d.fault_code()) == 0x0103u);
    CHECK(r.ticks[50] == r.ticks[49]);
    CHECK(d.command(Command::kStart) == Status::kWrongState);
    REQUIRE(d.command(Command::kReset) == Status::kOk);
    r.run(d, 1);
    CHECK(d.state() == DeviceState::kIdle);
    CHECK(d.fault_code() == FaultCode::kNone);
}

TEST_CASE("a request the tick has not taken yet is replaced by the next one, a stop is not",
          "[device]") {
    // Each section runs on its own device (Catch2 runs the case again per section): 16 spans
    // of a move queued and started.
    const Lsb start[kAxes] = {0, 0};
    const auto spans = trapezoid_move<kAxes>(start, 80000, 8);
    Device d(start);
    REQUIRE(d.configure(test_limits<kAxes>()) == Status::kOk);
    REQUIRE(send(d, 1, spans, 0, 16) == Status::kOk);
    REQUIRE(d.command(Command::kStart) == Status::kOk);
    Recorder r;

    SECTION("a hold right after a resume to an underrun: the device stays holding") {
        // The race a streaming host met under load: it sent resume to a device held by
        // underrun, then hold (Ctrl-C) before the tick took the resume. The hold was judged
        // "already in effect" from the published state and not posted, so the resume ran.
        r.run(d, 16 * 8 + 400);
        REQUIRE(d.state() == DeviceState::kHolding);
        REQUIRE(d.held_by_underrun());
        REQUIRE(send(d, 17, spans, 16, 8) == Status::kOk);
        REQUIRE(d.command(Command::kResume) == Status::kOk);
        REQUIRE(d.command_pending());
        REQUIRE(d.command(Command::kHold) == Status::kOk);
        const auto rest = r.ticks.back();
        r.run(d, 50);
        CHECK(d.state() == DeviceState::kHolding);
        CHECK(r.ticks.back() == rest);
        CHECK_FALSE(d.command_pending());
        // Settled: a hold while holding is kOk and posts nothing.
        CHECK(d.command(Command::kHold) == Status::kOk);
        CHECK_FALSE(d.command_pending());
        REQUIRE(d.command(Command::kResume) == Status::kOk);
        r.run(d, 50);
        CHECK(d.state() == DeviceState::kRunning);
        r.check_limits(test_limits<kAxes>());
    }
    SECTION("a resume right after a hold while running: the device keeps running") {
        r.run(d, 40);
        REQUIRE(d.state() == DeviceState::kRunning);
        REQUIRE(d.command(Command::kHold) == Status::kOk);
        REQUIRE(d.command(Command::kResume) == Status::kOk);  // posted: replaces the hold
        r.run(d, 40);
        CHECK(d.state() == DeviceState::kRunning);
        CHECK(d.generated_ticks() == 0);
    }
    SECTION("a stop not yet taken stays: start, hold and resume are refused") {
        r.run(d, 40);
        REQUIRE(d.command(Command::kStop) == Status::kOk);
        CHECK(d.command(Command::kResume) == Status::kWrongState);
        CHECK(d.command(Command::kHold) == Status::kWrongState);
        CHECK(d.command(Command::kStart) == Status::kWrongState);
        CHECK(d.command(Command::kStop) == Status::kOk);
        r.run(d, 400);
        CHECK(d.state() == DeviceState::kIdle);
        CHECK(d.queued_spans() == 0);
        r.check_limits(test_limits<kAxes>());
    }
}
