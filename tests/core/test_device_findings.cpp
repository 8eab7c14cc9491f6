// Regression tests for seven ways the device once broke its first promise (the axes move only
// along what was sent, within the limits, and stop when told). Each test failed on the device
// layer as it was before the task side and the tick side were split (tests named "finding N").
// The threaded ones are tagged [threads]: the ThreadSanitizer preset runs them too.
#include <array>
#include <atomic>
#include <catch2/catch.hpp>
#include <cstdint>
#include <cstdlib>
#include <random>
#include <thread>
#include <vector>

#include "core/device_fixture.hpp"
#include "pathstream/device/motion_device.hpp"

using namespace pathstream;
using namespace pathstream::device;
using pathstream::test::batch_bytes;
using pathstream::test::test_limits;
using pathstream::test::trapezoid_move;

namespace {

constexpr unsigned kAxes = 2;
using Point = std::array<Lsb, kAxes>;

template <std::uint32_t Capacity>
Status send(MotionDevice<kAxes, Capacity>& d, std::uint32_t sequence,
            const std::vector<WireSpan>& spans, std::size_t first, std::size_t count) {
    const auto bytes = batch_bytes<kAxes>(spans, first, count);
    return d.accept_batch(sequence, static_cast<std::uint16_t>(count), bytes.data(), bytes.size());
}

// Every tick's setpoints, and whether it was a path tick (ticks_executed advanced).
template <std::uint32_t Capacity>
struct Trace {
    std::vector<Point> ticks;
    std::vector<bool> path;
    std::vector<std::uint8_t> outputs;

    void run(MotionDevice<kAxes, Capacity>& d, std::size_t count) {
        for (std::size_t i = 0; i < count; ++i) {
            const std::uint64_t before = d.ticks_executed();
            Lsb out[kAxes];
            d.tick(out);
            ticks.push_back({out[0], out[1]});
            path.push_back(d.ticks_executed() != before);
            outputs.push_back(d.outputs());
        }
    }
    Point last() const { return ticks.back(); }
};

// Feeds `spans` from sequence `base` as room appears (batches of up to 8).
template <std::uint32_t Capacity>
void feed(MotionDevice<kAxes, Capacity>& d, const std::vector<WireSpan>& spans, std::uint32_t base,
          std::size_t& sent) {
    const std::size_t n = std::min<std::size_t>({d.free_slots(), spans.size() - sent, 8});
    if (n == 0) return;
    REQUIRE(send(d, base + static_cast<std::uint32_t>(sent), spans, sent, n) == Status::kOk);
    sent += n;
}

}  // namespace

TEST_CASE("finding 1: after a stop or an e-stop, a start with nothing queued moves nothing",
          "[device][findings]") {
    const Lsb start[kAxes] = {0, 0};
    MotionDevice<kAxes, 16> d(start);
    REQUIRE(d.configure(test_limits<kAxes>()) == Status::kOk);
    const auto spans = trapezoid_move<kAxes>(start, 60000, 8);
    REQUIRE(send(d, 1, spans, 0, 16) == Status::kOk);
    REQUIRE(d.command(Command::kStart) == Status::kOk);
    Trace<16> t;
    t.run(d, 100);  // mid-move, at speed
    SECTION("e-stop, then reset") {
        d.set_estop_input(true);
        t.run(d, 1);
        d.set_estop_input(false);
        REQUIRE(d.command(Command::kReset) == Status::kOk);
        t.run(d, 1);
    }
    SECTION("stop, run to rest") {
        REQUIRE(d.command(Command::kStop) == Status::kOk);
        t.run(d, 400);
    }
    REQUIRE(d.state() == DeviceState::kIdle);
    REQUIRE(d.queued_spans() == 0);
    const Point rest = t.last();
    const std::uint32_t underruns = d.underruns();
    CHECK(d.command(Command::kStart) == Status::kNothingToResume);
    t.run(d, 400);
    for (std::size_t k = t.ticks.size() - 400; k < t.ticks.size(); ++k) {
        INFO("tick " << k);
        REQUIRE(t.ticks[k] == rest);
    }
    CHECK(d.state() == DeviceState::kIdle);
    CHECK(d.underruns() == underruns);
}

TEST_CASE("finding 2: no span sent before an e-stop runs after it (threads)",
          "[device][findings][threads]") {
    // A feeder queues batches while the tick runs; the e-stop comes at a random tick, often
    // while a batch is being queued. Whatever the feeder queued, nothing may move after the
    // e-stop, and after a reset a start has nothing to run.
    const Lsb start[kAxes] = {0, 0};
    const auto spans = trapezoid_move<kAxes>(start, 400000, 8);
    std::mt19937 rng(20260612);
    int trials_with_spans_left = 0, trials_started = 0, trials_moved = 0;
    for (int trial = 0; trial < 100; ++trial) {
        INFO("trial " << trial);
        MotionDevice<kAxes, 64> d(start);
        REQUIRE(d.configure(test_limits<kAxes>()) == Status::kOk);
        REQUIRE(send(d, 1, spans, 0, 32) == Status::kOk);
        REQUIRE(d.command(Command::kStart) == Status::kOk);
        std::atomic<bool> done{false};
        std::atomic<int> unexpected{0};
        std::thread feeder([&] {
            std::size_t sent = 32;
            while (sent < spans.size()) {
                const std::size_t n =
                    std::min<std::size_t>({d.free_slots(), spans.size() - sent, 32});
                if (n == 0) {
                    if (d.state() == DeviceState::kEstop) break;
                    std::this_thread::yield();
                    continue;
                }
                const Status s = send(d, static_cast<std::uint32_t>(sent + 1), spans, sent, n);
                if (s == Status::kOk) {
                    sent += n;
                } else if (s == Status::kWrongState) {
                    break;
                } else if (s != Status::kQueueFull) {
                    unexpected.store(static_cast<int>(s));
                    break;
                }
            }
            done.store(true);
        });
        const int estop_at = std::uniform_int_distribution<int>(20, 400)(rng);
        Point frozen{};
        std::vector<Point> after;
        for (int k = 0; !done.load() || k <= estop_at; ++k) {
            if (k == estop_at) d.set_estop_input(true);
            Lsb out[kAxes];
            d.tick(out);
            if (k == estop_at - 1) frozen = {out[0], out[1]};
            if (k >= estop_at) after.push_back({out[0], out[1]});
            // Paced: about one tick per microsecond, so batches are queued while it ticks.
            const auto until = std::chrono::steady_clock::now() + std::chrono::microseconds(1);
            while (std::chrono::steady_clock::now() < until) {
            }
        }
        feeder.join();
        REQUIRE(unexpected.load() == 0);
        Trace<64> t;
        t.run(d, 4);
        CHECK(d.state() == DeviceState::kEstop);
        if (d.queued_spans() != 0) ++trials_with_spans_left;
        d.set_estop_input(false);
        REQUIRE(d.command(Command::kReset) == Status::kOk);
        t.run(d, 2);
        if (d.command(Command::kStart) == Status::kOk) ++trials_started;
        t.run(d, 400);
        bool moved = false;
        for (const Point& p : after) moved = moved || p != frozen;
        for (const Point& p : t.ticks) moved = moved || p != frozen;
        if (moved) ++trials_moved;
    }
    CHECK(trials_with_spans_left == 0);
    CHECK(trials_started == 0);
    CHECK(trials_moved == 0);
}

TEST_CASE(
    "finding 3: a stop after an underrun starts from the last span's own end velocity (threads)",
    "[device][findings][threads]") {
    // One-tick spans, one per batch, while the tick runs as fast as it can: the queue keeps
    // running dry, and every controlled stop must start from the velocity of the span that
    // just ended, never a stale one (the second difference stays within the limit).
    const Lsb start[kAxes] = {0, 0};
    MotionDevice<kAxes, 16> d(start);
    MotionLimits<kAxes> limits;
    limits.tick_hz = 1000;
    for (unsigned a = 0; a < kAxes; ++a)
        limits.axis[a] = {200000, 4000000};  // 200 LSB/tick, 4 LSB/tick^2
    REQUIRE(d.configure(limits) == Status::kOk);
    constexpr int kSpans = 20000;
    std::atomic<bool> done{false}, give_up{false};
    std::atomic<int> unexpected{0};
    std::thread feeder([&] {
        std::mt19937 rng(7);
        std::int32_t p[kAxes] = {0, 0}, v[kAxes] = {0, 0};
        bool started = false;
        for (int i = 0; i < kSpans && !give_up.load();) {
            if (started && d.state() == DeviceState::kHolding && d.held_by_underrun() &&
                d.queued_spans() > 0) {
                (void)d.command(Command::kResume);
            }
            WireSpan w;
            w.ticks = 1;
            w.outputs = kOutputPenDown;
            std::int32_t nv[kAxes];
            for (unsigned a = 0; a < kAxes; ++a) {
                nv[a] =
                    std::clamp(v[a] + 2 * std::uniform_int_distribution<int>(-1, 1)(rng), -40, 40);
                w.start_tangent[a] = v[a];
                w.end_tangent[a] = nv[a];
                w.end[a] = p[a] + (v[a] + nv[a]) / 2;
            }
            std::uint8_t bytes[4 + 12 * kAxes];
            const std::size_t n = encode_wire_span(w, kAxes, bytes, sizeof bytes);
            const Status s = d.accept_batch(static_cast<std::uint32_t>(i + 1), 1, bytes, n);
            if (s == Status::kQueueFull) {
                std::this_thread::yield();
                continue;
            }
            if (s != Status::kOk) {
                unexpected.store(static_cast<int>(s));
                break;
            }
            for (unsigned a = 0; a < kAxes; ++a) {
                p[a] = w.end[a];
                v[a] = nv[a];
            }
            ++i;
            if (!started) started = d.command(Command::kStart) == Status::kOk;
        }
        done.store(true);
    });
    std::vector<Point> ticks;
    bool capped = false;
    while (!done.load() || d.queued_spans() > 0 || d.state() == DeviceState::kHolding) {
        Lsb out[kAxes];
        d.tick(out);
        ticks.push_back({out[0], out[1]});
        // Holding: the device waits for the feeder (more spans, a resume). Let it run: on a
        // loaded machine a tick loop that never yields starves it for whole time slices.
        if (d.state() == DeviceState::kHolding) std::this_thread::yield();
        if (done.load() && d.state() == DeviceState::kHolding && d.queued_spans() > 0)
            (void)d.command(Command::kResume);
        if (done.load() && d.state() == DeviceState::kHolding && d.queued_spans() == 0) break;
        if (ticks.size() > 20'000'000) {
            capped = true;  // the feeder may be waiting for room that no tick will make
            break;
        }
    }
    give_up.store(true);
    feeder.join();
    REQUIRE_FALSE(capped);
    REQUIRE(unexpected.load() == 0);
    REQUIRE(ticks.size() > 1000);
    // The core rounds each setpoint once: allow 2 LSB/tick^2 on top of the 4 configured.
    for (std::size_t k = 2; k < ticks.size(); ++k) {
        for (unsigned a = 0; a < kAxes; ++a) {
            const std::int64_t acc = std::int64_t{ticks[k][a]} - 2 * std::int64_t{ticks[k - 1][a]} +
                                     std::int64_t{ticks[k - 2][a]};
            INFO("tick " << k << " axis " << a);
            REQUIRE(std::llabs(acc) <= 4 + 2);
        }
    }
}

TEST_CASE("finding 4: the pen is up on every tick that is not a path tick", "[device][findings]") {
    const Lsb start[kAxes] = {0, 0};
    MotionDevice<kAxes, 16> d(start);
    REQUIRE(d.configure(test_limits<kAxes>()) == Status::kOk);
    const auto spans = trapezoid_move<kAxes>(start, 60000, 8);  // pen down throughout
    std::size_t sent = 0;
    feed(d, spans, 1, sent);
    REQUIRE(d.command(Command::kStart) == Status::kOk);
    Trace<16> t;
    for (int i = 0; i < 10; ++i) {
        feed(d, spans, 1, sent);
        t.run(d, 8);
    }
    REQUIRE(d.command(Command::kHold) == Status::kOk);  // a stop along the tangent...
    t.run(d, 300);
    REQUIRE(d.state() == DeviceState::kHolding);
    REQUIRE(d.command(Command::kResume) == Status::kOk);  // ...and a re-entry
    for (int i = 0; i < 10; ++i) {
        feed(d, spans, 1, sent);
        t.run(d, 8);
    }
    t.run(d, 400);  // the queue runs dry: an underrun stop, then rest
    REQUIRE(d.underruns() == 1);
    std::size_t path = 0, other = 0;
    for (std::size_t k = 0; k < t.ticks.size(); ++k) {
        INFO("tick " << k);
        if (t.path[k]) {
            ++path;
            CHECK((t.outputs[k] & kOutputPenDown) != 0);
        } else {
            ++other;
            REQUIRE((t.outputs[k] & kOutputPenDown) == 0);
        }
    }
    CHECK(path > 100);
    CHECK(other > 300);
}

TEST_CASE("finding 5: the status is read whole and every command value is checked",
          "[device][findings]") {
    const Lsb start[kAxes] = {0, 0};
    MotionDevice<kAxes, 16> d(start);
    REQUIRE(d.configure(test_limits<kAxes>()) == Status::kOk);
    for (std::uint16_t v : {0, 6, 7, 16, 255, 0xFFFF}) {
        INFO("command " << v);
        CHECK(d.command(static_cast<Command>(v)) == Status::kUnknownCommand);
    }
    Lsb out[kAxes];
    d.tick(out);
    CHECK(d.state() == DeviceState::kIdle);
}

TEST_CASE("finding 5: a status read never mixes two ticks (threads)",
          "[device][findings][threads]") {
    // Constant velocity (2 LSB per tick from the first path tick on): in any one status, the
    // setpoint of a path tick is a function of the path ticks executed.
    const Lsb start[kAxes] = {1000, -1000};
    MotionDevice<kAxes, 16> d(start);
    REQUIRE(d.configure(test_limits<kAxes>()) == Status::kOk);
    constexpr std::uint32_t kTicks = 4096;
    std::vector<WireSpan> spans(16);
    for (std::size_t i = 0; i < spans.size(); ++i) {
        WireSpan& w = spans[i];
        w.ticks = kTicks;
        for (unsigned a = 0; a < kAxes; ++a) {
            w.start_tangent[a] = w.end_tangent[a] = static_cast<std::int32_t>(2 * kTicks);
            w.end[a] = start[a] + static_cast<Lsb>(2 * kTicks * (i + 1));
        }
    }
    REQUIRE(send(d, 1, spans, 0, spans.size()) == Status::kOk);
    REQUIRE(d.command(Command::kStart) == Status::kOk);
    std::atomic<bool> done{false}, reading{false};
    std::atomic<std::uint64_t> checked{0};
    std::thread ticker([&] {
        while (!reading.load()) std::this_thread::yield();
        for (std::uint32_t k = 0;
             k < 16 * kTicks && checked.load(std::memory_order_relaxed) < 20000; ++k) {
            Lsb out[kAxes];
            d.tick(out);
            if (k % 64 == 0) std::this_thread::yield();  // let the reader in on a loaded machine
        }
        done.store(true);
    });
    std::uint64_t reads = 0, mixed = 0;
    reading.store(true);
    while (!done.load()) {
        const DeviceStatus<kAxes> s = d.status();
        ++reads;
        if (s.tick_count != s.tick_check) ++mixed;
        if (!s.path_tick()) continue;
        checked.fetch_add(1, std::memory_order_relaxed);
        const std::int64_t k = static_cast<std::int64_t>(s.ticks_executed()) - 1;  // this path tick
        for (unsigned a = 0; a < kAxes; ++a) {
            if (s.position[a] != start[a] + 2 * k) ++mixed;
        }
    }
    ticker.join();
    INFO(reads << " reads, " << checked.load() << " checked");
    CHECK(checked.load() > 100);
    CHECK(mixed == 0);
}

TEST_CASE("finding 6: a job ends idle at rest, and a second job follows with no manual step",
          "[device][findings]") {
    const Lsb start[kAxes] = {0, 0};
    MotionDevice<kAxes, 16> d(start);
    REQUIRE(d.configure(test_limits<kAxes>()) == Status::kOk);
    Trace<16> t;
    std::uint32_t base = 1;
    Point from{start[0], start[1]};
    for (int job = 0; job < 2; ++job) {
        INFO("job " << job);
        const Lsb here[kAxes] = {from[0], from[1]};
        auto spans = trapezoid_move<kAxes>(here, job == 0 ? 20000 : -30000, 8);
        spans.back().flags |= kWireJobEnd;
        std::uint64_t ticks = 0;
        for (const WireSpan& w : spans) ticks += w.ticks;
        std::size_t sent = 0;
        feed(d, spans, base, sent);
        REQUIRE(d.command(Command::kStart) == Status::kOk);
        for (int i = 0; i < 1000 && !(sent == spans.size() && d.state() == DeviceState::kIdle);
             ++i) {
            feed(d, spans, base, sent);
            t.run(d, 8);
        }
        CHECK(d.state() == DeviceState::kIdle);
        CHECK(d.finished_job() == base);
        CHECK(d.finished_job_ticks() == ticks);
        CHECK(d.queued_spans() == 0);
        CHECK(t.last()[0] == spans.back().end[0]);
        CHECK(t.last()[1] == spans.back().end[1]);
        t.run(d, 50);
        CHECK(t.last()[0] == spans.back().end[0]);  // idle: stays there
        from = t.last();
        base += static_cast<std::uint32_t>(spans.size());
    }
    CHECK(d.underruns() == 0);
}

TEST_CASE("finding 7: a velocity step at a join is refused", "[device][findings]") {
    const Lsb start[kAxes] = {0, 0};
    MotionDevice<kAxes, 16> d(start);
    REQUIRE(d.configure(test_limits<kAxes>()) == Status::kOk);  // 2 LSB/tick^2 at 1 kHz
    auto cruise = [](std::int32_t from, std::int32_t v, std::uint32_t n) {
        WireSpan w;
        w.ticks = n;
        for (unsigned a = 0; a < kAxes; ++a) {
            w.start_tangent[a] = w.end_tangent[a] = v * static_cast<std::int32_t>(n);
            w.end[a] = from + v * static_cast<std::int32_t>(n);
        }
        return w;
    };
    SECTION("the first span starts at 100 LSB/tick from rest") {
        CHECK(send(d, 1, {cruise(0, 100, 8)}, 0, 1) == Status::kVelocityStep);
        CHECK(d.queued_spans() == 0);
        CHECK(d.last_accepted_sequence() == 0);
    }
    SECTION("T0 differs from the previous span's T1") {
        const WireSpan first = cruise(0, 2, 8);  // 2 LSB/tick from rest: one tick of acceleration
        REQUIRE(send(d, 1, {first}, 0, 1) == Status::kOk);
        WireSpan faster = cruise(16, 10, 8);  // 2 -> 10 LSB/tick at the join
        CHECK(send(d, 2, {faster}, 0, 1) == Status::kVelocityStep);
        WireSpan same_in_other_length = cruise(16, 2, 16);  // the same velocity, T0 = 32
        CHECK(send(d, 2, {same_in_other_length}, 0, 1) == Status::kOk);
        WireSpan step_within = cruise(48, 4, 16);  // 2 -> 4 LSB/tick: one tick at 2 LSB/tick^2
        CHECK(send(d, 3, {step_within}, 0, 1) == Status::kOk);
    }
    SECTION("a job's last span must end at rest") {
        WireSpan w = cruise(0, 2, 8);
        w.flags = kWireJobEnd;
        CHECK(send(d, 1, {w}, 0, 1) == Status::kJobEndMoving);
    }
}
