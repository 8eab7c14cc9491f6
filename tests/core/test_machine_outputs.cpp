// The machine functions among a span's outputs (spindle, its direction, mist and flood
// coolant): unlike the pen they stay on while a job holds, underruns, stops within a span or
// re-enters, and drop when the job ends or stops, on a fault and on the e-stop. A span with an
// undefined output bit is refused.
#include <catch2/catch.hpp>
#include <cstdint>
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
constexpr std::uint32_t kCapacity = 16;
using Device = MotionDevice<kAxes, kCapacity>;
constexpr std::uint8_t kCutting = kOutputSpindle | kOutputFlood;

// Every tick's outputs and whether it was a path tick.
struct Trace {
    std::vector<std::uint8_t> outputs;
    std::vector<bool> path;
    void run(Device& d, std::size_t count) {
        for (std::size_t i = 0; i < count; ++i) {
            const std::uint64_t before = d.ticks_executed();
            Lsb out[kAxes];
            d.tick(out);
            path.push_back(d.ticks_executed() != before);
            outputs.push_back(d.outputs());
        }
    }
};

// `spans` with the spindle and flood on, the pen as the fixture made it (down).
std::vector<WireSpan> cutting(std::vector<WireSpan> spans) {
    for (WireSpan& w : spans) w.outputs = static_cast<std::uint8_t>(w.outputs | kCutting);
    return spans;
}

void feed(Device& d, const std::vector<WireSpan>& spans, std::size_t& sent) {
    const std::size_t n = std::min<std::size_t>({d.free_slots(), spans.size() - sent, 8});
    if (n == 0) return;
    const auto bytes = batch_bytes<kAxes>(spans, sent, n);
    REQUIRE(d.accept_batch(static_cast<std::uint32_t>(sent + 1), static_cast<std::uint16_t>(n),
                           bytes.data(), bytes.size()) == Status::kOk);
    sent += n;
}

}  // namespace

TEST_CASE("machine outputs stay on through a hold, a re-entry and an underrun",
          "[device][outputs]") {
    const Lsb start[kAxes] = {0, 0};
    Device d(start);
    REQUIRE(d.configure(test_limits<kAxes>()) == Status::kOk);
    const auto spans = cutting(trapezoid_move<kAxes>(start, 60000, 8));
    std::size_t sent = 0;
    feed(d, spans, sent);
    REQUIRE(d.command(Command::kStart) == Status::kOk);
    Trace t;
    for (int i = 0; i < 10; ++i) {
        feed(d, spans, sent);
        t.run(d, 8);
    }
    REQUIRE(d.command(Command::kHold) == Status::kOk);  // a stop inside a span
    t.run(d, 300);
    REQUIRE(d.state() == DeviceState::kHolding);
    CHECK(d.outputs() == kCutting);  // held: the spindle and the coolant run, the pen is up
    REQUIRE(d.command(Command::kResume) == Status::kOk);  // a re-entry
    for (int i = 0; i < 10; ++i) {
        feed(d, spans, sent);
        t.run(d, 8);
    }
    t.run(d, 400);  // the queue runs dry: an underrun stop, then rest
    REQUIRE(d.underruns() == 1);
    REQUIRE(d.state() == DeviceState::kHolding);
    std::size_t path = 0, other = 0;
    for (std::size_t k = 0; k < t.outputs.size(); ++k) {
        INFO("tick " << k);
        REQUIRE((t.outputs[k] & kOutputMachineMask) == kCutting);
        if (t.path[k]) {
            ++path;
        } else {
            ++other;
            REQUIRE((t.outputs[k] & kOutputPenDown) == 0);
        }
    }
    CHECK(path > 100);
    CHECK(other > 300);
    // A stop from the hold: idle, everything off.
    REQUIRE(d.command(Command::kStop) == Status::kOk);
    t.run(d, 1);
    CHECK(d.state() == DeviceState::kIdle);
    CHECK(d.outputs() == 0);
}

TEST_CASE("machine outputs drop at the job end, a fault and the e-stop", "[device][outputs]") {
    const Lsb start[kAxes] = {0, 0};
    auto spans = cutting(trapezoid_move<kAxes>(start, 3000, 8));
    spans.back().flags = static_cast<std::uint8_t>(spans.back().flags | kWireJobEnd);
    Trace t;
    SECTION("job end") {
        Device d(start);
        REQUIRE(d.configure(test_limits<kAxes>()) == Status::kOk);
        std::size_t sent = 0;
        feed(d, spans, sent);
        REQUIRE(d.command(Command::kStart) == Status::kOk);
        while (sent < spans.size()) {
            t.run(d, 8);
            feed(d, spans, sent);
        }
        while (d.ticks_executed() < 8 * spans.size()) t.run(d, 1);
        CHECK(d.outputs() == (kCutting | kOutputPenDown));  // the last span's last tick
        t.run(d, 1);
        CHECK(d.state() == DeviceState::kIdle);
        CHECK(d.outputs() == 0);
    }
    SECTION("fault and e-stop, while moving and while held") {
        for (int mode = 0; mode < 4; ++mode) {
            INFO("mode " << mode);
            Device d(start);
            REQUIRE(d.configure(test_limits<kAxes>()) == Status::kOk);
            std::size_t sent = 0;
            feed(d, spans, sent);
            REQUIRE(d.command(Command::kStart) == Status::kOk);
            t.run(d, 20);
            if (mode >= 2) {
                REQUIRE(d.command(Command::kHold) == Status::kOk);
                t.run(d, 300);
                REQUIRE(d.state() == DeviceState::kHolding);
            }
            REQUIRE((d.outputs() & kOutputMachineMask) == kCutting);
            if (mode % 2 == 0) {
                d.raise_fault(FaultCode::kExternal);
            } else {
                d.set_estop_input(true);
            }
            t.run(d, 1);
            CHECK(d.outputs() == 0);
            t.run(d, 10);
            CHECK(d.outputs() == 0);
        }
    }
}

TEST_CASE("a span with an undefined output bit is refused", "[device][outputs]") {
    const Lsb start[kAxes] = {0, 0};
    Device d(start);
    REQUIRE(d.configure(test_limits<kAxes>()) == Status::kOk);
    auto spans = trapezoid_move<kAxes>(start, 3000, 8);
    for (unsigned bit = 5; bit < 8; ++bit) {
        INFO("bit " << bit);
        spans[0].outputs = static_cast<std::uint8_t>(kOutputPenDown | (1u << bit));
        const auto bytes = batch_bytes<kAxes>(spans, 0, 1);
        CHECK(d.accept_batch(1, 1, bytes.data(), bytes.size()) == Status::kBadBatch);
    }
    spans[0].outputs = kOutputKnownMask;
    const auto bytes = batch_bytes<kAxes>(spans, 0, 1);
    CHECK(d.accept_batch(1, 1, bytes.data(), bytes.size()) == Status::kOk);
}
