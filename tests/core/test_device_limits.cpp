// The exact limit check against an independent double-precision scan of the same cubic, and
// the wire span encoding round trip.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <random>

#include "pathstream/device/motion_limits.hpp"
#include "pathstream/device/wire_span.hpp"
#include "pathstream/span.hpp"
#include "pathstream/tick_cubic.hpp"

using namespace pathstream;
using namespace pathstream::device;

namespace {

// Velocity (LSB/s) and acceleration (LSB/s^2) extremes of a Hermite span, scanned densely in
// double precision from the Hermite form itself (not from the core's coefficients).
struct Extremes {
    double velocity = 0;
    double acceleration = 0;
};

Extremes scan_hermite(double p0, double p1, double t0, double t1, double n, double hz) {
    Extremes e;
    const int samples = 20000;
    for (int i = 0; i <= samples; ++i) {
        const double u = static_cast<double>(i) / samples;
        const double dh00 = 6 * u * u - 6 * u, dh10 = 3 * u * u - 4 * u + 1;
        const double dh01 = -6 * u * u + 6 * u, dh11 = 3 * u * u - 2 * u;
        const double velocity = (dh00 * p0 + dh10 * t0 + dh01 * p1 + dh11 * t1) * hz / n;
        const double ddh00 = 12 * u - 6, ddh10 = 6 * u - 4, ddh01 = -12 * u + 6, ddh11 = 6 * u - 2;
        const double accel =
            (ddh00 * p0 + ddh10 * t0 + ddh01 * p1 + ddh11 * t1) * hz * hz / (n * n);
        e.velocity = std::max(e.velocity, std::fabs(velocity));
        e.acceleration = std::max(e.acceleration, std::fabs(accel));
    }
    return e;
}

}  // namespace

TEST_CASE("limit check agrees with a dense scan of the Hermite curve", "[device][limits]") {
    std::mt19937_64 rng(20261122);
    std::uniform_int_distribution<std::int32_t> position(-1000000, 1000000);
    std::uniform_int_distribution<std::int32_t> tangent(-400000, 400000);
    std::uniform_int_distribution<std::uint32_t> ticks(1, 2000);
    int velocity_refusals = 0, acceleration_refusals = 0, accepted = 0, near_misses = 0;
    for (int trial = 0; trial < 3000; ++trial) {
        const std::int32_t control[4] = {position(rng), position(rng), tangent(rng), tangent(rng)};
        SpanTiming timing;
        const std::uint32_t n = ticks(rng);
        REQUIRE(make_span_timing(Basis::kHermite, n, timing) == Status::kOk);
        TickCubic cubic;
        if (make_tick_cubic(Basis::kHermite, control, timing, cubic) != Status::kOk) continue;
        const std::uint32_t hz = 1000;
        const Extremes e = scan_hermite(control[0], control[1], control[2], control[3], n, hz);
        // Limits placed just around the true extremes, so both outcomes are exercised; extremes
        // beyond what a 32-bit limit can say are not a case for this comparison.
        std::uniform_real_distribution<double> factor(0.9, 1.1);
        const double v_limit = std::max(1.0, e.velocity * factor(rng));
        const double a_limit = std::max(1.0, e.acceleration * factor(rng));
        if (v_limit >= 4294967295.0 || a_limit >= 4294967295.0) continue;
        AxisLimits limits;
        limits.max_velocity = static_cast<std::uint32_t>(v_limit);
        limits.max_acceleration = static_cast<std::uint32_t>(a_limit);
        const Status s = check_axis_limits(cubic, timing, limits, hz);
        const bool velocity_ok = e.velocity <= limits.max_velocity;
        const bool accel_ok = e.acceleration <= limits.max_acceleration;
        // The scan can miss the true maximum by a hair; only judge clear cases.
        const bool clear_v = std::fabs(e.velocity - limits.max_velocity) > 1e-6 * e.velocity + 1e-3;
        const bool clear_a =
            std::fabs(e.acceleration - limits.max_acceleration) > 1e-6 * e.acceleration + 1e-3;
        if (!clear_v || !clear_a) {
            ++near_misses;
            continue;
        }
        if (!accel_ok) {
            CHECK(s == Status::kAccelerationLimit);
            ++acceleration_refusals;
        } else if (!velocity_ok) {
            CHECK(s == Status::kVelocityLimit);
            ++velocity_refusals;
        } else {
            CHECK(s == Status::kOk);
            ++accepted;
        }
    }
    CHECK(accepted > 300);
    CHECK(velocity_refusals > 300);
    CHECK(acceleration_refusals > 300);
    CHECK(near_misses < 100);
}

TEST_CASE("limit check is exact at the boundary", "[device][limits]") {
    // Constant acceleration from rest: p(u) = 500 u^2 over 10 ticks at 1 kHz (Hermite P0 0,
    // P1 500, T0 0, T1 1000): velocity ends at 1000/10 LSB/tick = 100,000 LSB/s, acceleration
    // 1000 LSB / (10 ticks)^2 per tick^2 = 10 LSB/tick^2 = 10,000,000 LSB/s^2 everywhere.
    const std::int32_t control[4] = {0, 500, 0, 1000};
    SpanTiming timing;
    REQUIRE(make_span_timing(Basis::kHermite, 10, timing) == Status::kOk);
    TickCubic cubic;
    REQUIRE(make_tick_cubic(Basis::kHermite, control, timing, cubic) == Status::kOk);
    CHECK(check_axis_limits(cubic, timing, {100000, 10000000}, 1000) == Status::kOk);
    CHECK(check_axis_limits(cubic, timing, {99999, 10000000}, 1000) == Status::kVelocityLimit);
    CHECK(check_axis_limits(cubic, timing, {100000, 9999999}, 1000) == Status::kAccelerationLimit);
}

TEST_CASE("interior velocity extremum is found", "[device][limits]") {
    // A bump: P0 = 0, P1 = 10,000, zero end tangents over 100 ticks at 1 kHz. The velocity is
    // zero at both ends and peaks inside: p'(u) = 60,000 u (1 - u), max 15,000 LSB per span
    // at u = 1/2, i.e. 150 LSB/tick = 150,000 LSB/s. Only the interior check can refuse it.
    const std::int32_t bump[4] = {0, 10000, 0, 0};
    SpanTiming timing;
    REQUIRE(make_span_timing(Basis::kHermite, 100, timing) == Status::kOk);
    TickCubic cubic;
    REQUIRE(make_tick_cubic(Basis::kHermite, bump, timing, cubic) == Status::kOk);
    CHECK(check_axis_limits(cubic, timing, {150000, 100000000}, 1000) == Status::kOk);
    CHECK(check_axis_limits(cubic, timing, {149999, 100000000}, 1000) == Status::kVelocityLimit);
}

TEST_CASE("wire span round trip and malformed input", "[device][wire]") {
    WireSpan w;
    w.ticks = 65536;
    w.flags = 0;
    w.outputs = kOutputPenDown;
    for (unsigned a = 0; a < 3; ++a) {
        w.end[a] = -123456789 + static_cast<std::int32_t>(a);
        w.end_tangent[a] = 0x7FFFFFFF - static_cast<std::int32_t>(a);
        w.start_tangent[a] = -0x7FFFFFFF - 1 + static_cast<std::int32_t>(a);
    }
    std::uint8_t bytes[64];
    REQUIRE(encode_wire_span(w, 3, bytes, sizeof bytes) == wire_span_bytes(3, false));
    CHECK(bytes[0] == 0xFF);
    CHECK(bytes[1] == 0xFF);  // ticks - 1, big-endian
    WireSpan back;
    std::size_t used = 0;
    REQUIRE(decode_wire_span(bytes, sizeof bytes, 3, back, used) == Status::kOk);
    CHECK(used == 40);
    CHECK(back.ticks == 65536);
    CHECK(back.outputs == kOutputPenDown);
    for (unsigned a = 0; a < 3; ++a) {
        CHECK(back.end[a] == w.end[a]);
        CHECK(back.end_tangent[a] == w.end_tangent[a]);
        CHECK(back.start_tangent[a] == w.start_tangent[a]);
    }
    CHECK(decode_wire_span(bytes, used - 1, 3, back, used) == Status::kBadBatch);
    bytes[2] = 0x80;  // unknown flag
    CHECK(decode_wire_span(bytes, sizeof bytes, 3, back, used) == Status::kBadBatch);
    w.flags = kWireContinueTangent;
    CHECK(encode_wire_span(w, 2, bytes, sizeof bytes) == wire_span_bytes(2, true));
    CHECK(wire_span_bytes(2, true) == 20);
    CHECK(encode_wire_span(w, 2, bytes, 19) == 0);
}

TEST_CASE("CRC-16/MODBUS matches the standard check value", "[device][wire]") {
    const std::uint8_t check[] = {'1', '2', '3', '4', '5', '6', '7', '8', '9'};
    CHECK(crc16_modbus(check, sizeof check) == 0x4B37);
}
