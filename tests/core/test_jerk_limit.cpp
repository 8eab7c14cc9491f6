// The exact jerk limit: a span's constant jerk, and the acceleration step at every join
// (rest included), at their boundaries, on their own and through the device's receiver.
#include <catch2/catch.hpp>
#include <cstdint>
#include <vector>

#include "core/device_fixture.hpp"
#include "pathstream/device/motion_device.hpp"
#include "pathstream/device/motion_limits.hpp"
#include "pathstream/tick_cubic.hpp"

using namespace pathstream;
using namespace pathstream::device;
using pathstream::test::batch_bytes;
using pathstream::test::test_limits;
using pathstream::test::trapezoid_move;

namespace {

struct Cubic {
    SpanTiming timing;
    TickCubic cubic;
};

Cubic cubic_of(Basis basis, std::int32_t p0, std::int32_t p1, std::int32_t p2, std::int32_t p3,
               std::uint32_t ticks) {
    Cubic c;
    REQUIRE(make_span_timing(basis, ticks, c.timing) == Status::kOk);
    const std::int32_t control[4] = {p0, p1, p2, p3};
    REQUIRE(make_tick_cubic(basis, control, c.timing, c.cubic) == Status::kOk);
    return c;
}

AxisLimits with_jerk(std::uint32_t max_jerk) {
    AxisLimits l{200000, 2000000};
    l.max_jerk = max_jerk;
    return l;
}

// A straight move (both axes alike) built from constant-jerk phases of whole 8-tick spans with jerk
// j = 3/256 LSB/tick^3: `rise` spans of +j, `hold` spans of constant acceleration, `rise` spans of
// -j, `cruise` spans, then the mirror image down to rest. Every boundary has integer position and
// tangent, so every span is its phase exactly: jerk 0 or +-j inside, no acceleration step anywhere.
std::vector<WireSpan> s_curve(unsigned rise, unsigned hold, unsigned cruise) {
    std::vector<int> jerk;  // in units of j per span
    for (unsigned i = 0; i < rise; ++i) jerk.push_back(1);
    for (unsigned i = 0; i < hold; ++i) jerk.push_back(0);
    for (unsigned i = 0; i < rise; ++i) jerk.push_back(-1);
    for (unsigned i = 0; i < cruise; ++i) jerk.push_back(0);
    for (unsigned i = 0; i < rise; ++i) jerk.push_back(-1);
    for (unsigned i = 0; i < hold; ++i) jerk.push_back(0);
    for (unsigned i = 0; i < rise; ++i) jerk.push_back(1);
    // Exact state in scaled integers: position p, tangent T = 8v, and a32 = 32a (a multiple
    // of 3, since a changes by 8j = 3/32 per jerk span).
    std::int64_t p = 0, tangent = 0, a32 = 0;
    std::vector<WireSpan> out;
    for (std::size_t i = 0; i < jerk.size(); ++i) {
        // Over 8 ticks: dp = 8v + 32a + 512 J / 6 = T + a32 + sign; dT = 8 (8a + 32 J) = 2 a32 + 3
        // sign.
        const int sign = jerk[i];
        const std::int64_t dp = tangent + a32 + sign;
        const std::int64_t dt = 2 * a32 + 3 * sign;
        WireSpan w;
        w.ticks = 8;
        w.flags = i == 0 ? 0 : kWireContinueTangent;
        p += dp;
        tangent += dt;
        a32 += 3 * sign;
        for (unsigned a = 0; a < 2; ++a) {
            w.end[a] = static_cast<std::int32_t>(p);
            w.end_tangent[a] = static_cast<std::int32_t>(tangent);
        }
        out.push_back(w);
    }
    REQUIRE(tangent == 0);
    REQUIRE(a32 == 0);
    out.back().flags = static_cast<std::uint8_t>(out.back().flags | kWireJobEnd);
    return out;
}

// 2 kHz: j = 3/256 LSB/tick^3 is 3/256 * 8e9 = 93,750,000 LSB/s^3 = 937,500 units exactly.
constexpr std::uint32_t kHz = 2000;
constexpr std::uint32_t kSCurveJerk = 937500;

MotionLimits<2> limits_2khz(std::uint32_t max_jerk) {
    MotionLimits<2> l = test_limits<2>();
    l.tick_hz = kHz;
    for (auto& axis : l.axis) axis.max_jerk = max_jerk;
    return l;
}

Status send(MotionDevice<2, 256>& d, const std::vector<WireSpan>& spans) {
    const auto bytes = batch_bytes<2>(spans, 0, spans.size());
    return d.accept_batch(1, static_cast<std::uint16_t>(spans.size()), bytes.data(), bytes.size());
}

}  // namespace

TEST_CASE("jerk inside a span: exactly at the limit passes, one LSB more is refused",
          "[device][jerk]") {
    // Hermite, n = 10 at 1 kHz: jerk 6(2P0 - 2P1 + T0 + T1)/n^3 LSB/tick^3 = 6e6 (..) LSB/s^3;
    // T1 = 5 gives 3e7 LSB/s^3 = 300,000 units.
    const Cubic five = cubic_of(Basis::kHermite, 0, 0, 0, 5, 10);
    const Cubic six = cubic_of(Basis::kHermite, 0, 0, 0, 6, 10);
    CHECK(check_axis_jerk(five.cubic, five.timing, with_jerk(300000), 1000) == Status::kOk);
    CHECK(check_axis_jerk(six.cubic, six.timing, with_jerk(300000), 1000) == Status::kJerkLimit);
    CHECK(check_axis_jerk(five.cubic, five.timing, with_jerk(299999), 1000) == Status::kJerkLimit);
    // Negative jerk: P1 one LSB further (2P0 - 2P1 = -2, with T1 = -1: -3).
    const Cubic negative = cubic_of(Basis::kHermite, 0, 1, 0, -1, 10);
    CHECK(check_axis_jerk(negative.cubic, negative.timing, with_jerk(180000), 1000) == Status::kOk);
    CHECK(check_axis_jerk(negative.cubic, negative.timing, with_jerk(179999), 1000) ==
          Status::kJerkLimit);
    // Any basis: a uniform B-spline's jerk is (-P0 + 3P1 - 3P2 + P3) / n^3 (scale 6).
    const Cubic bspline = cubic_of(Basis::kUniformBSpline, 0, 0, 0, 3, 10);
    CHECK(check_axis_jerk(bspline.cubic, bspline.timing, with_jerk(30000), 1000) == Status::kOk);
    CHECK(check_axis_jerk(bspline.cubic, bspline.timing, with_jerk(29999), 1000) ==
          Status::kJerkLimit);
    // No jerk limit: no check.
    CHECK(check_axis_jerk(six.cubic, six.timing, with_jerk(0), 1000) == Status::kOk);
}

TEST_CASE("acceleration step at a join of spans of 8 and 12 ticks is exact", "[device][jerk]") {
    // 8 ticks, C 0, T0 0, T1 1: a_end = (-6C + 2T0 + 4T1)/64 = 4/64. 12 ticks, C 3, T0 T1 0:
    // a_start = (6C - 4T0 - 2T1)/144 = 18/144. The step is 1/16 LSB/tick^2; at 100 Hz one tick
    // of jerk is max_jerk * 100 / 1e6 LSB/tick^2: 625 units exactly.
    const Cubic previous = cubic_of(Basis::kHermite, 0, 0, 0, 1, 8);
    const Cubic next = cubic_of(Basis::kHermite, 0, 3, 0, 0, 12);
    const TickAcceleration end = end_acceleration(previous.cubic, previous.timing);
    const TickAcceleration start = start_acceleration(next.cubic, next.timing);
    CHECK(end.numerator * 64 == 4 * static_cast<std::int64_t>(end.denominator));
    CHECK(start.numerator * 144 == 18 * static_cast<std::int64_t>(start.denominator));
    // The Hermite shortcut the receiver keeps is the same fraction.
    const TickAcceleration shortcut = hermite_end_acceleration(0, 0, 1, 8);
    CHECK(shortcut.numerator * static_cast<std::int64_t>(end.denominator) ==
          end.numerator * static_cast<std::int64_t>(shortcut.denominator));

    CHECK(check_acceleration_step(start, end, with_jerk(625), 100) == Status::kOk);
    CHECK(check_acceleration_step(start, end, with_jerk(624), 100) == Status::kAccelerationStep);
    // Either order, and a hair more step (19/144 - 4/64 > 1/16) refused at 625.
    CHECK(check_acceleration_step(end, start, with_jerk(625), 100) == Status::kOk);
    CHECK(check_acceleration_step(TickAcceleration{19, 144}, end, with_jerk(625), 100) ==
          Status::kAccelerationStep);
    CHECK(check_acceleration_step(start, end, with_jerk(0), 100) == Status::kOk);

    // Ending at rest: 4/64 = 1/16 within one tick of jerk at 625 units, not at 624.
    CHECK(check_end_at_rest(end, with_jerk(625), 100) == Status::kOk);
    CHECK(check_end_at_rest(end, with_jerk(624), 100) == Status::kAccelerationStep);
}

TEST_CASE("jerk arithmetic holds at the extremes of the ranges", "[device][jerk]") {
    // The largest tangents on a 1024-tick span at 100 kHz against the largest limit: no
    // overflow (the span's jerk, 6 * 2^30 / 2^30 LSB/tick^3 * 1e15, is far above the limit).
    const Cubic wild = cubic_of(Basis::kHermite, 0, 0, 1 << 29, 1 << 29, 1024);
    CHECK(check_axis_jerk(wild.cubic, wild.timing, with_jerk(0xFFFFFFFFu), kMaxTickHz) ==
          Status::kJerkLimit);
    const TickAcceleration at_end = end_acceleration(wild.cubic, wild.timing);
    const TickAcceleration slow{1, 6ull * 65536 * 65536};
    CHECK(check_acceleration_step(slow, at_end, with_jerk(0xFFFFFFFFu), kMaxTickHz) ==
          Status::kAccelerationStep);
    // A dwell of the longest span at 10 Hz with the smallest limit: no jerk, no step.
    const Cubic dwell = cubic_of(Basis::kHermite, 5, 5, 0, 0, kMaxSpanTicks);
    CHECK(check_axis_jerk(dwell.cubic, dwell.timing, with_jerk(1), kMinTickHz) == Status::kOk);
    CHECK(check_acceleration_step(start_acceleration(dwell.cubic, dwell.timing), TickAcceleration{},
                                  with_jerk(1), kMinTickHz) == Status::kOk);
    // Every max_jerk is a valid configuration; 0 is none.
    MotionLimits<1> l = test_limits<1>();
    l.axis[0].max_jerk = 0xFFFFFFFFu;
    CHECK(check_limits(l) == Status::kOk);
    l.axis[0].max_jerk = 0;
    CHECK(check_limits(l) == Status::kOk);
}

TEST_CASE("device: an S-curve at exactly the jerk limit is accepted, one unit less refuses it",
          "[device][jerk]") {
    const std::vector<WireSpan> spans = s_curve(4, 2, 3);
    {
        const Lsb start[2] = {0, 0};
        MotionDevice<2, 256> d(start);
        REQUIRE(d.configure(limits_2khz(kSCurveJerk)) == Status::kOk);
        CHECK(send(d, spans) == Status::kOk);
        REQUIRE(d.command(Command::kStart) == Status::kOk);
        Lsb out[2] = {};
        for (int i = 0; i < 2000 && d.finished_job() == 0; ++i) d.tick(out);
        CHECK(d.finished_job() == 1);
        CHECK(out[0] == spans.back().end[0]);
    }
    {
        const Lsb start[2] = {0, 0};
        MotionDevice<2, 256> d(start);
        REQUIRE(d.configure(limits_2khz(kSCurveJerk - 1)) == Status::kOk);
        CHECK(send(d, spans) == Status::kJerkLimit);
        CHECK(d.last_accepted_sequence() == 0);
    }
}

TEST_CASE("device: a trapezoid's acceleration steps are refused under a jerk limit only",
          "[device][jerk]") {
    const Lsb start[2] = {0, 0};
    std::vector<WireSpan> spans = trapezoid_move<2>(start, 3000, 8);
    spans.back().flags = static_cast<std::uint8_t>(spans.back().flags | kWireJobEnd);
    {
        MotionDevice<2, 256> d(start);
        REQUIRE(d.configure(limits_2khz(0)) == Status::kOk);
        CHECK(send(d, spans) == Status::kOk);
    }
    {
        // The first span starts from rest with ~0.28 LSB/tick^2: far over one tick of a
        // 1e8 LSB/s^3 jerk at 2 kHz (0.0125 LSB/tick^2), though its own jerk is ~0.
        MotionDevice<2, 256> d(start);
        REQUIRE(d.configure(limits_2khz(1000000)) == Status::kOk);
        CHECK(send(d, spans) == Status::kAccelerationStep);
        CHECK(d.last_accepted_sequence() == 0);
    }
}

TEST_CASE("device: a job end or a pause must end within one tick of jerk of rest",
          "[device][jerk]") {
    // Span 1 from rest with a = 0: P 0 -> 1, T 0 -> 3 (jerk 6/512, a_end 6/64). Span 2 joins
    // it without a step: P 1 -> 4, T 3 -> 0 (a_start (18 - 12)/64 = 6/64, jerk -18/512), and
    // ends at v = 0 but a = -12/64. Jerk 18/512 LSB/tick^3 at 2 kHz is 2,812,500 units.
    std::vector<WireSpan> spans(2);
    spans[0].ticks = spans[1].ticks = 8;
    for (unsigned a = 0; a < 2; ++a) {
        spans[0].end[a] = 1;
        spans[0].end_tangent[a] = 3;
        spans[1].end[a] = 4;
        spans[1].end_tangent[a] = 0;
    }
    spans[1].flags = kWireContinueTangent;
    const Lsb start[2] = {0, 0};
    for (const std::uint8_t flag : {kWireJobEnd, kWirePause}) {
        spans[1].flags = static_cast<std::uint8_t>(kWireContinueTangent | flag);
        {
            MotionDevice<2, 256> d(start);
            REQUIRE(d.configure(limits_2khz(2812500)) == Status::kOk);
            CHECK(send(d, spans) == Status::kAccelerationStep);
        }
        {
            // 12/64 LSB/tick^2 is one tick of 15,000,000 units: at rest within it.
            MotionDevice<2, 256> d(start);
            REQUIRE(d.configure(limits_2khz(15000000)) == Status::kOk);
            CHECK(send(d, spans) == Status::kOk);
        }
        {
            MotionDevice<2, 256> d(start);
            REQUIRE(d.configure(limits_2khz(0)) == Status::kOk);
            CHECK(send(d, spans) == Status::kOk);
        }
    }
    // Without the job end or pause the same two spans are a valid start of a longer job.
    spans[1].flags = kWireContinueTangent;
    MotionDevice<2, 256> d(start);
    REQUIRE(d.configure(limits_2khz(2812500)) == Status::kOk);
    CHECK(send(d, spans) == Status::kOk);
}

TEST_CASE("device: the first span after a pause starts from rest", "[device][jerk]") {
    // Two S-curves, a pause after the first: the second starts at a = 0, exactly from rest.
    std::vector<WireSpan> spans = s_curve(2, 0, 1);
    const std::size_t first = spans.size();
    spans.back().flags = static_cast<std::uint8_t>(kWireContinueTangent | kWirePause);
    std::vector<WireSpan> second = s_curve(2, 0, 1);
    for (WireSpan& w : second) {
        for (unsigned a = 0; a < 2; ++a) w.end[a] += spans[first - 1].end[a];
    }
    spans.insert(spans.end(), second.begin(), second.end());
    const Lsb start[2] = {0, 0};
    MotionDevice<2, 256> d(start);
    REQUIRE(d.configure(limits_2khz(kSCurveJerk)) == Status::kOk);
    CHECK(send(d, spans) == Status::kOk);
    CHECK(d.last_accepted_sequence() == spans.size());
}
