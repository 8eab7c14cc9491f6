// The travel (soft limits) of each axis: the exact proof that a span stays inside, the
// device refusing a batch that could leave it, jogs that must end inside it (and may come back
// from outside), and the configuration over Modbus (zeros: no limits).
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <random>

#include "pathstream/device/jog.hpp"
#include "pathstream/device/modbus_register_map.hpp"
#include "pathstream/device/motion_limits.hpp"
#include "pathstream/tick_cubic.hpp"

using namespace pathstream;
using namespace pathstream::device;

namespace {

constexpr unsigned kAxes = 2;
using Device = MotionDevice<kAxes, 16>;

// Position of a Hermite span at u (double, from the Hermite form itself).
double hermite(double p0, double p1, double t0, double t1, double u) {
    const double h00 = 2 * u * u * u - 3 * u * u + 1, h10 = u * u * u - 2 * u * u + u;
    const double h01 = -2 * u * u * u + 3 * u * u, h11 = u * u * u - u * u;
    return h00 * p0 + h10 * t0 + h01 * p1 + h11 * t1;
}

MotionLimits<kAxes> limits(std::int32_t min_position, std::int32_t max_position) {
    MotionLimits<kAxes> l;
    l.tick_hz = 1000;
    for (auto& a : l.axis) {
        a.max_velocity = 250000;
        a.max_acceleration = 3000000;
        a.min_position = min_position;
        a.max_position = max_position;
    }
    return l;
}

// One rest-to-rest move of axis 0 from the device's position to `to` (AxisMove), as a batch.
Status queue_move(Device& d, std::int32_t to) {
    Lsb from[kAxes];
    for (unsigned a = 0; a < kAxes; ++a) from[a] = d.position(a);
    AxisMove<kAxes> m;
    if (Status s = m.plan(from, 0, to - from[0], 100000, d.limits()); s != Status::kOk) return s;
    std::uint8_t bytes[64 * (4 + 12 * kAxes)];
    std::size_t length = 0;
    std::uint16_t count = 0;
    while (m.pending()) {
        WireSpan w;
        REQUIRE(m.next(w));
        if (!m.pending()) w.flags |= kWireJobEnd;
        length += encode_wire_span(w, kAxes, bytes + length, sizeof bytes - length);
        ++count;
    }
    return d.accept_batch(d.last_accepted_sequence() + 1, count, bytes, length);
}

void run_to_idle(Device& d, OperatorCommands<kAxes, 16>* c = nullptr) {
    for (int i = 0; i < 100000; ++i) {
        if (c != nullptr) c->service();
        Lsb out[kAxes];
        d.tick(out);
        if (d.state() == DeviceState::kIdle && d.queued_spans() == 0) return;
    }
    FAIL("the device did not come to rest");
}

}  // namespace

TEST_CASE("travel proof: never passes a span whose curve leaves, exact at the edge",
          "[device][travel]") {
    std::mt19937_64 rng(20261125);
    std::uniform_int_distribution<std::int32_t> position(-1000000, 1000000);
    std::uniform_int_distribution<std::int32_t> tangent(-400000, 400000);
    std::uniform_int_distribution<std::uint32_t> ticks(1, 2000);
    int passed = 0, refused_outside = 0, refused_grazing = 0;
    for (int trial = 0; trial < 4000; ++trial) {
        const std::int32_t control[4] = {position(rng), position(rng), tangent(rng), tangent(rng)};
        SpanTiming timing;
        REQUIRE(make_span_timing(Basis::kHermite, ticks(rng), timing) == Status::kOk);
        TickCubic cubic;
        if (make_tick_cubic(Basis::kHermite, control, timing, cubic) != Status::kOk) continue;
        double low = 1e18, high = -1e18;
        for (int i = 0; i <= 4000; ++i) {
            const double p = hermite(control[0], control[1], control[2], control[3], i / 4000.0);
            low = std::min(low, p);
            high = std::max(high, p);
        }
        // Limits around the curve's true range: inside, just outside, or in between.
        std::uniform_real_distribution<double> margin(-0.2, 0.2);
        const double span = std::max(1.0, high - low);
        AxisLimits l;
        l.min_position = static_cast<std::int32_t>(std::floor(low - margin(rng) * span));
        l.max_position = static_cast<std::int32_t>(std::ceil(high + margin(rng) * span));
        if (l.min_position >= l.max_position) continue;
        const Status s = check_axis_travel(cubic, timing, l);
        const bool curve_inside = low >= l.min_position - 1e-6 && high <= l.max_position + 1e-6;
        if (!curve_inside) {
            INFO("trial " << trial);
            REQUIRE(s == Status::kOutsideTravel);  // sound: a curve that leaves never passes
            ++refused_outside;
        } else if (s == Status::kOk) {
            ++passed;
        } else {
            ++refused_grazing;  // the hull pokes out while the curve stays in
        }
    }
    CHECK(passed > 500);
    CHECK(refused_outside > 500);
    INFO("grazing refusals " << refused_grazing);
    CHECK(refused_grazing < passed);
    // Exact at the edge: a rest-to-rest span from 0 to 1000 reaches exactly 1000.
    const std::int32_t control[4] = {0, 1000, 0, 0};
    SpanTiming timing;
    REQUIRE(make_span_timing(Basis::kHermite, 16, timing) == Status::kOk);
    TickCubic cubic;
    REQUIRE(make_tick_cubic(Basis::kHermite, control, timing, cubic) == Status::kOk);
    AxisLimits edge;
    edge.min_position = 0;
    edge.max_position = 1000;
    CHECK(check_axis_travel(cubic, timing, edge) == Status::kOk);
    edge.max_position = 999;
    CHECK(check_axis_travel(cubic, timing, edge) == Status::kOutsideTravel);
    edge.max_position = 1000;
    edge.min_position = 1;
    CHECK(check_axis_travel(cubic, timing, edge) == Status::kOutsideTravel);
}

TEST_CASE("travel: bad limits refused, a batch leaving it refused whole", "[device][travel]") {
    CHECK(check_limits(limits(5, 5)) == Status::kBadLimits);
    CHECK(check_limits(limits(-static_cast<std::int32_t>(kMaxPositionLsb) - 1, 0)) ==
          Status::kBadLimits);
    const Lsb start[kAxes] = {46000, 1000};
    Device d(start);
    REQUIRE(d.configure(limits(0, 50000)) == Status::kOk);
    CHECK(queue_move(d, 50001) == Status::kOutsideTravel);
    CHECK(d.queued_spans() == 0);
    CHECK(queue_move(d, 50000) == Status::kOk);  // to the very edge
}

TEST_CASE("travel: a jog must end inside, from outside it may come back in", "[device][travel]") {
    const Lsb start[kAxes] = {-3000, 1000};  // outside on x (homing's pull-off past the edge)
    Device d(start);
    REQUIRE(d.configure(limits(0, 50000)) == Status::kOk);
    OperatorCommands<kAxes, 16> c(d);
    OperatorCommand jog;
    jog.command = kCommandJog;
    jog.axis = 0;
    jog.value = -1000;  // further out
    CHECK(c.execute(jog) == Status::kOutsideTravel);
    jog.value = 4000;  // back in, to x = 1000
    REQUIRE(c.execute(jog) == Status::kOk);
    run_to_idle(d, &c);
    CHECK(d.position(0) == 1000);
    // The check holds again: a host's batch leaving the travel is refused.
    CHECK(queue_move(d, -10) == Status::kOutsideTravel);
    jog.value = 49001;
    CHECK(c.execute(jog) == Status::kOutsideTravel);
    jog.value = 49000;
    REQUIRE(c.execute(jog) == Status::kOk);
    run_to_idle(d, &c);
    CHECK(d.position(0) == 50000);
}

TEST_CASE("travel over Modbus: written with the limits, read back, zeros mean none",
          "[device][travel]") {
    const Lsb start[kAxes] = {0, 0};
    Device d(start);
    ModbusRegisterMap<kAxes, 16> m(d);
    std::uint16_t r[modbus::config_registers(kAxes)] = {};
    r[1] = 1000;
    r[2] = kAxes;
    for (unsigned a = 0; a < kAxes; ++a) {
        r[modbus::kConfigAxisBase + 4 * a + 1] = 60000;
        r[modbus::kConfigAxisBase + 4 * a + 2] = 4;
    }
    REQUIRE(m.write_holding_registers(modbus::kConfig, modbus::config_registers(kAxes), r) ==
            modbus::Exception::kNone);
    CHECK(d.limits().axis[1].max_position == kMaxPositionLsb);  // zeros: the whole range
    const std::uint16_t t = modbus::config_travel_register(kAxes, 1);
    const auto minus = static_cast<std::uint32_t>(-2500);
    r[t] = static_cast<std::uint16_t>(minus >> 16);
    r[t + 1] = static_cast<std::uint16_t>(minus & 0xFFFFu);
    r[t + 3] = 7000;
    REQUIRE(m.write_holding_registers(modbus::kConfig, modbus::config_registers(kAxes), r) ==
            modbus::Exception::kNone);
    CHECK((d.limits().axis[1].min_position == -2500 && d.limits().axis[1].max_position == 7000));
    std::uint16_t back[modbus::config_registers(kAxes)] = {};
    REQUIRE(m.read_holding_registers(modbus::kConfig, modbus::config_registers(kAxes), back) ==
            modbus::Exception::kNone);
    CHECK((back[t] == r[t] && back[t + 1] == r[t + 1] && back[t + 3] == 7000));
    r[t + 3] = 0;  // max -2500 .. 0 ... min -2500, max 0: still a valid range
    r[t + 1] = 0;
    r[t] = 0;
    r[t + 2] = 0;
    r[t + 3] = 0;
    REQUIRE(m.write_holding_registers(modbus::kConfig, modbus::config_registers(kAxes), r) ==
            modbus::Exception::kNone);
    CHECK(d.limits().axis[1].min_position == -kMaxPositionLsb);
}
