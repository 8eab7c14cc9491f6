// Programmed pauses (wire flag kWirePause): the device holds at the end of the marked span with
// the pen up, says so in its status and on both buses, and a resume plays on from exactly there.
#include <catch2/catch.hpp>
#include <cstdint>
#include <vector>

#include "core/device_fixture.hpp"
#include "pathstream/device/can_node.hpp"
#include "pathstream/device/modbus_register_map.hpp"
#include "pathstream/device/motion_device.hpp"

using namespace pathstream;
using namespace pathstream::device;
using pathstream::test::batch_bytes;
using pathstream::test::test_limits;
using pathstream::test::trapezoid_move;

namespace {

constexpr unsigned kAxes = 2;
using Device = MotionDevice<kAxes, 64>;

Status send_all(Device& d, const std::vector<WireSpan>& spans) {
    const auto bytes = batch_bytes<kAxes>(spans, 0, spans.size());
    return d.accept_batch(1, static_cast<std::uint16_t>(spans.size()), bytes.data(), bytes.size());
}

// Two moves from rest to rest, the pause after the first one's last span, the job's end after
// the second's.
std::vector<WireSpan> two_moves(const Lsb (&start)[kAxes], std::size_t& first_move_spans) {
    std::vector<WireSpan> spans = trapezoid_move<kAxes>(start, 3000, 8);
    first_move_spans = spans.size();
    spans.back().flags = static_cast<std::uint8_t>(spans.back().flags | kWirePause);
    const Lsb middle[kAxes] = {spans.back().end[0], spans.back().end[1]};
    std::vector<WireSpan> back = trapezoid_move<kAxes>(middle, -3000, 8);
    back.front().flags = 0;  // T0 sent: 0, the first move ended at rest
    back.back().flags = static_cast<std::uint8_t>(back.back().flags | kWireJobEnd);
    spans.insert(spans.end(), back.begin(), back.end());
    return spans;
}

// Ticks the device until it rests at a pause (at most 5000 ticks).
void tick_until_paused(Device& d) {
    for (int i = 0; i < 5000 && !d.paused(); ++i) {
        Lsb p[kAxes];
        d.tick(p);
    }
}

}  // namespace

TEST_CASE("pause: the device holds at the marked span's end, pen up, until resumed",
          "[device][pause]") {
    const Lsb start[kAxes] = {1000, 2000};
    Device d(start);
    REQUIRE(d.configure(test_limits<kAxes>()) == Status::kOk);
    std::size_t first = 0;
    const std::vector<WireSpan> spans = two_moves(start, first);
    REQUIRE(send_all(d, spans) == Status::kOk);
    REQUIRE(d.command(Command::kStart) == Status::kOk);
    std::uint64_t first_ticks = 0;
    for (std::size_t i = 0; i < first; ++i) first_ticks += spans[i].ticks;
    std::vector<std::array<Lsb, kAxes>> out;
    const auto tick = [&](unsigned n) {
        for (unsigned i = 0; i < n; ++i) {
            Lsb p[kAxes];
            d.tick(p);
            out.push_back({p[0], p[1]});
        }
    };
    tick(static_cast<unsigned>(first_ticks) + 1);  // the start tick, then the first move
    CHECK(d.ticks_executed() == first_ticks);
    tick(1);  // the boundary: the pause is taken
    CHECK(d.state() == DeviceState::kHolding);
    CHECK(d.paused());
    CHECK_FALSE(d.held_by_underrun());
    CHECK(d.outputs() == 0);
    tick(500);  // it waits for the operator, at rest where the first move ended
    CHECK(d.state() == DeviceState::kHolding);
    CHECK(d.paused());
    CHECK(d.ticks_executed() == first_ticks);
    CHECK(out.back()[0] == spans[first - 1].end[0]);
    CHECK(out.back()[1] == spans[first - 1].end[1]);
    REQUIRE(d.command(Command::kResume) == Status::kOk);
    while (d.state() != DeviceState::kIdle && out.size() < 100000) tick(1);
    CHECK_FALSE(d.paused());
    CHECK(d.finished_job() == 1);
    CHECK(out.back()[0] == start[0]);
    CHECK(out.back()[1] == start[1]);
    std::uint64_t total = 0;
    for (const WireSpan& w : spans) total += w.ticks;
    CHECK(d.ticks_executed() == total);
}

TEST_CASE("pause: a stop at a pause drops the rest and clears the pause", "[device][pause]") {
    const Lsb start[kAxes] = {0, 0};
    Device d(start);
    REQUIRE(d.configure(test_limits<kAxes>()) == Status::kOk);
    std::size_t first = 0;
    const std::vector<WireSpan> spans = two_moves(start, first);
    REQUIRE(send_all(d, spans) == Status::kOk);
    REQUIRE(d.command(Command::kStart) == Status::kOk);
    tick_until_paused(d);
    REQUIRE(d.paused());
    REQUIRE(d.command(Command::kStop) == Status::kOk);
    Lsb p[kAxes];
    d.tick(p);
    CHECK(d.state() == DeviceState::kIdle);
    CHECK_FALSE(d.paused());
    CHECK(d.queued_spans() == 0);
}

TEST_CASE("pause: a span marked for a pause must end at rest", "[device][pause]") {
    const Lsb start[kAxes] = {0, 0};
    Device d(start);
    REQUIRE(d.configure(test_limits<kAxes>()) == Status::kOk);
    std::vector<WireSpan> spans = trapezoid_move<kAxes>(start, 3000, 8);
    spans[spans.size() / 2].flags =
        static_cast<std::uint8_t>(spans[spans.size() / 2].flags | kWirePause);
    CHECK(send_all(d, spans) == Status::kPauseMoving);
    CHECK(d.queued_spans() == 0);
    CHECK(d.last_accepted_sequence() == 0);
}

TEST_CASE("pause: the paused flag on Modbus (register 35 bit 6) and CAN (status A bit 6)",
          "[device][pause]") {
    const Lsb start[kAxes] = {0, 0};
    Device d(start);
    REQUIRE(d.configure(test_limits<kAxes>()) == Status::kOk);
    ModbusRegisterMap<kAxes, 64> map(d);
    can::CanNode<kAxes, 64> node{d, 5};
    const auto flags = [&] {
        std::uint16_t modbus_flags = 0;
        REQUIRE(map.read_input_registers(modbus::status::kFlags, 1, &modbus_flags) ==
                modbus::Exception::kNone);
        std::vector<can::Frame> out;
        node.handle(can::encode_command(5, can::kCommandStatusRequest),
                    [&](const can::Frame& f) { out.push_back(f); });
        can::Status3 s;
        for (const can::Frame& f : out) REQUIRE(can::decode_status_part(f, s));
        return std::make_pair(modbus_flags & modbus::flags::kPaused, s.flags & can::kFlagPaused);
    };
    std::size_t first = 0;
    const std::vector<WireSpan> spans = two_moves(start, first);
    REQUIRE(send_all(d, spans) == Status::kOk);
    REQUIRE(d.command(Command::kStart) == Status::kOk);
    CHECK(flags() == std::make_pair(0, 0));
    tick_until_paused(d);
    REQUIRE(d.paused());
    CHECK(flags() == std::make_pair(int{modbus::flags::kPaused}, int{can::kFlagPaused}));
    REQUIRE(d.command(Command::kResume) == Status::kOk);
    Lsb p[kAxes];
    d.tick(p);
    CHECK(flags() == std::make_pair(0, 0));
}
