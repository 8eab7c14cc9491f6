// Jog and set position as bus commands (Modbus register map, native CAN node): the device
// plans the jog itself, within its limits on every tick, feeds it as the queue drains, ends
// idle at the exact target as a finished job; every refusal leaves it as it was.
#include <catch2/catch.hpp>
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "pathstream/device/can_node.hpp"
#include "pathstream/device/jog.hpp"
#include "pathstream/device/modbus_register_map.hpp"

using namespace pathstream;
using namespace pathstream::device;
using Ex = modbus::Exception;

namespace {

constexpr unsigned kAxes = 2;
constexpr std::uint32_t kCapacity = 16;
using Device = MotionDevice<kAxes, kCapacity>;
using Map = ModbusRegisterMap<kAxes, kCapacity>;

// The example pen plotter in LSB: 1 kHz, 250,000 LSB/s, 3,000,000 LSB/s^2.
MotionLimits<kAxes> plotter_limits() {
    MotionLimits<kAxes> l;
    l.tick_hz = 1000;
    for (auto& a : l.axis) a = {250000, 3000000};
    l.pen_down_ticks = 80;
    return l;
}

std::vector<std::uint16_t> jog_registers(unsigned axis, std::int32_t distance, std::uint16_t feed,
                                         std::uint16_t command = kCommandJog) {
    const auto v = static_cast<std::uint32_t>(distance);
    return {command, static_cast<std::uint16_t>(axis), static_cast<std::uint16_t>(v >> 16),
            static_cast<std::uint16_t>(v & 0xFFFFu), feed};
}

// Runs the task loop and the tick until idle (at most `limit` ticks); checks every tick's
// step and second difference against the limits (exact cubic + one LSB of rounding per
// difference) and that the pen stays up. Returns the ticks run.
template <typename Service>
std::uint64_t run_to_idle(Device& d, Service&& service, const MotionLimits<kAxes>& l,
                          std::uint64_t limit) {
    Lsb previous[kAxes], before[kAxes];
    for (unsigned a = 0; a < kAxes; ++a) previous[a] = before[a] = d.position(a);
    std::uint64_t ticks = 0;
    bool seen_moving = false;
    while (ticks < limit) {
        service();
        Lsb out[kAxes];
        d.tick(out);
        ++ticks;
        REQUIRE(d.outputs() == 0);
        for (unsigned a = 0; a < kAxes; ++a) {
            const double v = static_cast<double>(l.axis[a].max_velocity) / l.tick_hz;
            const double acc =
                static_cast<double>(l.axis[a].max_acceleration) / l.tick_hz / l.tick_hz;
            const std::int64_t step = static_cast<std::int64_t>(out[a]) - previous[a];
            const std::int64_t second = step - (static_cast<std::int64_t>(previous[a]) - before[a]);
            INFO("tick " << ticks << " axis " << a);
            REQUIRE(static_cast<double>(std::llabs(step)) <= v + 1.0);
            // (the first tick's second difference needs the tick before the call: not known)
            if (ticks > 1) REQUIRE(static_cast<double>(std::llabs(second)) <= acc + 2.0);
            before[a] = previous[a];
            previous[a] = out[a];
        }
        if (d.state() != DeviceState::kIdle) seen_moving = true;
        if (seen_moving && d.state() == DeviceState::kIdle) return ticks;
    }
    FAIL("the jog did not end within " << limit << " ticks");
    return ticks;
}

}  // namespace

TEST_CASE(
    "a jog over Modbus: planned by the device, fed as the queue drains, exact end, a finished job",
    "[device][jog][modbus]") {
    const Lsb start[kAxes] = {1000, -2000};
    Device d(start);
    Map m(d);
    const MotionLimits<kAxes> l = plotter_limits();
    REQUIRE(d.configure(l) == Status::kOk);
    // 200 mm at full speed: about 100 spans of 8 ticks, far more than the queue's 16.
    const std::int32_t distance = 200000;
    const auto regs = jog_registers(0, distance, 0);
    REQUIRE(m.write_holding_registers(modbus::kCommand, 5, regs.data()) == Ex::kNone);
    CHECK(d.queued_spans() == kCapacity);
    const std::uint64_t ticks = run_to_idle(
        d, [&] { m.service(); }, l, 100000);
    CHECK(d.position(0) == start[0] + distance);
    CHECK(d.position(1) == start[1]);
    CHECK(d.finished_job() == 1);  // the first sequence number: the jog's job id
    CHECK(d.last_accepted_sequence() > kCapacity);
    // 200 mm at 250 mm/s is 0.8 s plus the ramps (0.083 s each at 3 m/s^2).
    CHECK(ticks > 800);
    CHECK(ticks < 1000);
    // A slower feed takes longer: 10 % of the max velocity, 20 mm back.
    const auto slow = jog_registers(0, -20000, 100);
    REQUIRE(m.write_holding_registers(modbus::kCommand, 5, slow.data()) == Ex::kNone);
    const std::uint64_t slow_ticks = run_to_idle(
        d, [&] { m.service(); }, l, 100000);
    CHECK(d.position(0) == start[0] + distance - 20000);
    CHECK(slow_ticks >= 800);
}

TEST_CASE("jog and set position refusals leave the device as it was", "[device][jog][modbus]") {
    const Lsb start[kAxes] = {0, 0};
    Device d(start);
    Map m(d);
    auto write = [&](const std::vector<std::uint16_t>& r) {
        return m.write_holding_registers(modbus::kCommand, static_cast<std::uint16_t>(r.size()),
                                         r.data());
    };
    std::vector<std::uint16_t> s(modbus::status::kCount);
    auto refusal = [&] {
        REQUIRE(m.read_input_registers(0, modbus::status::kCount, s.data()) == Ex::kNone);
        return static_cast<Status>(s[modbus::status::kLastRefusal]);
    };
    CHECK(write(jog_registers(0, 100, 0)) == Ex::kServerDeviceFailure);
    CHECK(refusal() == Status::kNotConfigured);
    REQUIRE(d.configure(plotter_limits()) == Status::kOk);
    CHECK(write(jog_registers(2, 100, 0)) == Ex::kIllegalDataValue);  // no axis 2
    CHECK(refusal() == Status::kControlValueOutOfRange);
    CHECK(write(jog_registers(0, 0, 0)) == Ex::kIllegalDataValue);  // nothing to move
    CHECK(write(jog_registers(0, 100, 1001)) ==
          Ex::kIllegalDataValue);  // feed above 1000 per mille
    CHECK(write(jog_registers(0, kMaxPositionLsb + 1, 0)) ==
          Ex::kIllegalDataValue);                                         // end off the range
    CHECK(write(jog_registers(0, 100, 0, 10)) == Ex::kIllegalDataValue);  // no such command
    CHECK(refusal() == Status::kUnknownCommand);
    const std::uint16_t plain_jog = kCommandJog;  // a jog without its arguments
    CHECK(m.write_holding_registers(modbus::kCommand, 1, &plain_jog) == Ex::kIllegalDataValue);
    CHECK(d.queued_spans() == 0);
    CHECK(d.last_accepted_sequence() == 0);
    // Set position: one axis redefined, the other kept; only idle with nothing queued.
    CHECK(write(jog_registers(1, 12345, 0, kCommandSetPosition)) == Ex::kNone);
    Lsb out[kAxes];
    d.tick(out);
    CHECK((d.position(0) == 0 && d.position(1) == 12345));
    CHECK(write(jog_registers(1, 5, 7, kCommandSetPosition)) ==
          Ex::kIllegalDataValue);  // feed must be 0
    // While a jog runs, neither a second jog nor set position is taken.
    REQUIRE(write(jog_registers(0, 50000, 0)) == Ex::kNone);
    d.tick(out);
    CHECK(write(jog_registers(0, 10, 0)) == Ex::kServerDeviceFailure);
    CHECK(refusal() == Status::kWrongState);
    CHECK(write(jog_registers(0, 10, 0, kCommandSetPosition)) == Ex::kServerDeviceFailure);
}

TEST_CASE("a jog whose last short span fits no length is refused before any span is queued",
          "[device][jog][modbus]") {
    // Found by fuzz_modbus_map: a slow tick-rate-heavy axis (117 LSB/s^2 at 63,744 Hz) jogged
    // 256 LSB. The ramps fit, the remainder at rest fits no span length up to kMaxSpanTicks;
    // the jog used to find that out after queuing its first eight spans.
    const Lsb start[kAxes] = {0, 0};
    Device d(start);
    Map m(d);
    MotionLimits<kAxes> l;
    l.tick_hz = 63744;
    l.axis[0] = {2281701465u, 117};
    l.axis[1] = {3860742, 4218880};
    l.pen_down_ticks = 29952;
    REQUIRE(d.configure(l) == Status::kOk);
    const std::vector<std::uint16_t> r = jog_registers(0, 256, 0);
    CHECK(m.write_holding_registers(modbus::kCommand, 5, r.data()) == Ex::kIllegalDataValue);
    std::vector<std::uint16_t> s(modbus::status::kCount);
    REQUIRE(m.read_input_registers(0, modbus::status::kCount, s.data()) == Ex::kNone);
    CHECK(static_cast<Status>(s[modbus::status::kLastRefusal]) == Status::kBadLimits);
    CHECK(d.queued_spans() == 0);
    CHECK(d.last_accepted_sequence() == 0);
    CHECK(d.free_slots() == kCapacity);
    // On these limits a move is refused at plan() or every one of its spans passes the
    // device's check and the last ends on the target; some are taken.
    int taken = 0;
    for (std::int64_t distance = -300; distance <= 300; ++distance) {
        if (distance == 0) continue;
        AxisMove<kAxes> move;
        const Lsb from[kAxes] = {1000, -7};
        if (move.plan(from, 0, distance, l.axis[0].max_velocity, l) != Status::kOk) continue;
        ++taken;
        Lsb at[kAxes] = {from[0], from[1]};
        WireSpan w;
        while (move.pending()) {
            REQUIRE(move.next(w));
            REQUIRE(stop_detail::check_span(to_core_span<kAxes>(w, at, 0), l) == Status::kOk);
            for (unsigned a = 0; a < kAxes; ++a) at[a] = w.end[a];
        }
        CHECK(!move.next(w));
        CHECK(at[0] == from[0] + distance);
        CHECK(at[1] == from[1]);
    }
    CHECK(taken > 0);
}

TEST_CASE("a jog under a jerk limit passes the device's jerk rules and ends on its target",
          "[device][jog][jerk]") {
    // The device checks its own moves like a host's spans: a constant-acceleration move at the
    // axis's full acceleration is refused under these limits, the jog's own plan is taken.
    for (const std::uint32_t max_jerk : {100000u, 1000000u, 30000000u, 4000000000u}) {
        MotionLimits<kAxes> l = plotter_limits();
        for (auto& a : l.axis) a.max_jerk = max_jerk;  // units of 100 LSB/s^3
        for (const std::int32_t distance : {1, -3, 7, 100, -5001, 40000, -123457}) {
            INFO("max_jerk " << max_jerk << " distance " << distance);
            const Lsb start[kAxes] = {2000, -1000};
            Device d(start);
            REQUIRE(d.configure(l) == Status::kOk);
            Jog<kAxes, kCapacity> jog(d);
            REQUIRE(jog.start(1, distance, 0) == Status::kOk);
            run_to_idle(
                d, [&] { jog.service(); }, l, 2000000);
            CHECK_FALSE(jog.feeding());
            CHECK(d.position(1) == start[1] + distance);
            CHECK(d.position(0) == start[0]);
            CHECK(d.finished_job() == 1);
            CHECK(d.status().underruns == 0);
        }
        // The same move planned without the jerk limit: refused where its acceleration steps.
        MotionLimits<kAxes> no_jerk = l;
        for (auto& a : no_jerk.axis) a.max_jerk = 0;
        if (static_cast<std::uint64_t>(max_jerk) * kJerkUnitLsb / l.tick_hz >=
            l.axis[1].max_acceleration) {
            continue;  // one tick of jerk reaches the full acceleration: nothing to refuse
        }
        const Lsb start[kAxes] = {0, 0};
        Device d(start);
        REQUIRE(d.configure(l) == Status::kOk);
        AxisMove<kAxes> move;
        REQUIRE(move.plan(start, 1, 40000, l.axis[1].max_velocity, no_jerk) == Status::kOk);
        WireSpan w;
        REQUIRE(move.next(w));
        std::uint8_t bytes[64];
        const std::size_t length = encode_wire_span(w, kAxes, bytes, sizeof bytes);
        CHECK(d.accept_batch(1, 1, bytes, length) == Status::kAccelerationStep);
    }
}

TEST_CASE(
    "a stop in the middle of a jog: the device stops within its limits and the jog is fed no more",
    "[device][jog]") {
    const Lsb start[kAxes] = {0, 0};
    Device d(start);
    Jog<kAxes, kCapacity> jog(d);
    const MotionLimits<kAxes> l = plotter_limits();
    REQUIRE(d.configure(l) == Status::kOk);
    REQUIRE(jog.start(1, -300000, 500) == Status::kOk);
    Lsb out[kAxes];
    for (int i = 0; i < 300; ++i) {
        jog.service();
        d.tick(out);
    }
    REQUIRE(jog.feeding());
    REQUIRE(d.command(Command::kStop) == Status::kOk);
    run_to_idle(
        d, [&] { jog.service(); }, l, 10000);
    CHECK_FALSE(jog.feeding());
    CHECK(d.queued_spans() == 0);
    CHECK(d.position(1) > -300000);
    CHECK(d.finished_job() == 0);  // cut short: never reported finished
}

TEST_CASE("jog and set position over native CAN: the CommandArgs frame, acked like a command",
          "[device][jog][can]") {
    const Lsb start[kAxes] = {0, 0};
    Device d(start);
    can::CanNode<kAxes, kCapacity> node(d, 3);
    const MotionLimits<kAxes> l = plotter_limits();
    REQUIRE(d.configure(l) == Status::kOk);
    std::vector<can::Frame> out;
    auto send = [&](const can::Frame& f) { out.push_back(f); };
    can::CommandArgs c;
    c.command = kCommandJog;
    c.axis = 1;
    c.value = 7777;
    c.feed = 250;
    node.handle(can::encode_command_args(3, c), send);
    REQUIRE(out.size() == 1);
    can::Ack ack;
    REQUIRE(can::decode_ack(out[0], ack));
    CHECK((ack.kind == can::kAckCommand && ack.sequence == kCommandJog && ack.result == 0));
    run_to_idle(
        d, [&] { node.service(); }, l, 10000);
    CHECK(d.position(1) == 7777);
    c.command = kCommandSetPosition;
    c.axis = 0;
    c.value = -42;
    c.feed = 0;
    out.clear();
    node.handle(can::encode_command_args(3, c), send);
    REQUIRE((out.size() == 1 && can::decode_ack(out[0], ack) && ack.result == 0));
    Lsb o[kAxes];
    d.tick(o);
    CHECK((d.position(0) == -42 && d.position(1) == 7777));
    c.command = 5;  // a plain command sent with arguments
    out.clear();
    node.handle(can::encode_command_args(3, c), send);
    REQUIRE((out.size() == 1 && can::decode_ack(out[0], ack)));
    CHECK(ack.result == static_cast<std::uint8_t>(Status::kUnknownCommand));
    can::Frame short_frame = can::encode_command_args(3, c);
    short_frame.length = 6;
    out.clear();
    node.handle(short_frame, send);
    REQUIRE((out.size() == 1 && can::decode_ack(out[0], ack)));
    CHECK(ack.result == can::kResultBadFrame);
}
