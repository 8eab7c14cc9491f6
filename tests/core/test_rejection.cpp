// What the core refuses, and that refusing changes nothing: tick counts, control value
// ranges, curves and per-tick differences that would overflow, unknown bases, ticks outside a
// span. Then the converse as a seeded property: every span the core accepts really stays
// inside the documented bounds at every tick (checked exactly with the independent reference,
// at the ticks where each bound is tightest), i.e. acceptance is sound.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "core/property_settings.hpp"
#include "core/reference.hpp"
#include "pathstream/basis.hpp"
#include "pathstream/forward_difference.hpp"
#include "pathstream/setpoint_stream.hpp"
#include "pathstream/span.hpp"
#include "pathstream/tick_cubic.hpp"

using pathstream::Basis;
using pathstream::DifferenceState;
using pathstream::kMaxCurveLsb;
using pathstream::kMaxDifferenceLsb;
using pathstream::kMaxPositionLsb;
using pathstream::kMaxSpanTicks;
using pathstream::kMaxTangentLsb;
using pathstream::Lsb;
using pathstream::PreparedSpan;
using pathstream::SetpointStream;
using pathstream::Span;
using pathstream::SpanTiming;
using pathstream::Status;
using pathstream::TickCubic;
using pathstream::TickState;
using pathstream::test::i128;
using pathstream::test::reference_setpoint;
using pathstream::test::reference_value;
using pathstream::test::SpanGenerator;

namespace {

std::string name(Status s) {
    return pathstream::status_name(s);
}

std::string str(i128 v) {
    if (v == 0) return "0";
    const bool negative = v < 0;
    unsigned __int128 m =
        negative ? -static_cast<unsigned __int128>(v) : static_cast<unsigned __int128>(v);
    std::string s;
    while (m != 0) {
        s.insert(s.begin(), static_cast<char>('0' + static_cast<int>(m % 10)));
        m /= 10;
    }
    return negative ? "-" + s : s;
}

std::string describe(Basis b, const std::int32_t (&p)[4], std::int64_t n) {
    std::ostringstream os;
    os << "basis " << static_cast<int>(b) << " n=" << n << " control {" << p[0] << ", " << p[1]
       << ", " << p[2] << ", " << p[3] << "}";
    return os.str();
}

#define EXPECT(cond, context)                                  \
    do {                                                       \
        if (!(cond)) FAIL(#cond << "  [" << (context) << "]"); \
    } while (0)

constexpr Basis kAllBases[] = {Basis::kUniformBSpline, Basis::kCatmullRom, Basis::kBezier,
                               Basis::kHermite};

/// Validates one axis the way prepare_span does.
Status build(Basis basis, const std::int32_t (&p)[4], std::uint32_t n, SpanTiming& timing,
             TickCubic& cubic) {
    if (const Status s = pathstream::make_span_timing(basis, n, timing); s != Status::kOk) return s;
    return pathstream::make_tick_cubic(basis, p, timing, cubic);
}
Status build(Basis basis, const std::int32_t (&p)[4], std::uint32_t n) {
    SpanTiming timing;
    TickCubic cubic;
    return build(basis, p, n, timing, cubic);
}

/// Byte image of an object, to prove a failed call wrote nothing at all.
template <typename T>
std::vector<unsigned char> bytes(const T& object) {
    std::vector<unsigned char> image(sizeof(T));
    std::memcpy(image.data(), static_cast<const void*>(&object), sizeof(T));
    return image;
}

/// The exact span, from the reference alone, as a cubic in Newton form over ticks:
///   N(k) = v0 + f1 C(k,1) + f2 C(k,2) + f3 C(k,3),  value = N(k) / den,
/// so the forward differences per tick are
///   Delta1(k) = f1 + f2 k + f3 C(k,2),  Delta2(k) = f2 + f3 k,  Delta3 = f3  (over den).
/// All integer, all exact, any k (including past the end, where the differencer's state at
/// tick n looks).
struct ExactSpan {
    i128 v0, f1, f2, f3, den;
    explicit ExactSpan(Basis b, const std::int32_t (&p)[4], std::int64_t n) {
        i128 v[4];
        for (int j = 0; j < 4; ++j) {
            const auto r = reference_value(b, p, n, j);
            v[j] = r.numerator;
            den = r.denominator;
        }
        v0 = v[0];
        f1 = v[1] - v[0];
        f2 = v[2] - 2 * v[1] + v[0];
        f3 = v[3] - 3 * v[2] + 3 * v[1] - v[0];
    }
    static i128 choose2(i128 k) { return k * (k - 1) / 2; }
    static i128 choose3(i128 k) { return k * (k - 1) * (k - 2) / 6; }
    i128 value(i128 k) const { return v0 + f1 * k + f2 * choose2(k) + f3 * choose3(k); }
    i128 delta1(i128 k) const { return f1 + f2 * k + f3 * choose2(k); }
    i128 delta2(i128 k) const { return f2 + f3 * k; }
    i128 delta3() const { return f3; }
};

i128 abs128(i128 v) {
    return v < 0 ? -v : v;
}

/// The core's tick-0 (`start`) and tick-n (`end`) values of a valid span, every axis: what
/// SetpointStream::push compares with the end of the chain.
template <unsigned Axes>
void core_ends(const Span<Axes>& span, Lsb (&start)[Axes], Lsb (&end)[Axes]) {
    for (unsigned a = 0; a < Axes; ++a) {
        SpanTiming timing;
        TickCubic cubic;
        REQUIRE(build(span.basis, span.control[a], span.ticks, timing, cubic) == Status::kOk);
        REQUIRE(pathstream::evaluate_at(cubic, timing, 0, start[a]) == Status::kOk);
        REQUIRE(pathstream::evaluate_at(cubic, timing, span.ticks, end[a]) == Status::kOk);
    }
}

/// Translates the valid `span` so that it starts exactly at `at` (the end of the chain so
/// far): the same offset per axis on every position control value (Hermite: P0, P1, not the
/// tangents), exact in the core. Writes the span's new end point to `end` (which may be `at`).
template <unsigned Axes>
void chain_after(Span<Axes>& span, const Lsb (&at)[Axes], Lsb (&end)[Axes]) {
    Lsb target[Axes], start[Axes], old_end[Axes], new_start[Axes];
    for (unsigned a = 0; a < Axes; ++a) target[a] = at[a];
    core_ends(span, start, old_end);
    const int positions = span.basis == Basis::kHermite ? 2 : 4;
    for (unsigned a = 0; a < Axes; ++a) {
        const std::int64_t offset = std::int64_t{target[a]} - start[a];
        for (int j = 0; j < positions; ++j) {
            const std::int64_t v = span.control[a][j] + offset;
            REQUIRE(v <= kMaxPositionLsb);
            REQUIRE(v >= -kMaxPositionLsb);
            span.control[a][j] = static_cast<std::int32_t>(v);
        }
    }
    core_ends(span, new_start, end);
    for (unsigned a = 0; a < Axes; ++a) {
        REQUIRE(new_start[a] == target[a]);
        REQUIRE(std::int64_t{end[a]} - old_end[a] == std::int64_t{target[a]} - start[a]);
    }
}

/// Integers of [0, n] next to the real roots of q2 k^2 + q1 k + q0 (long double, +/-2 ticks).
void ticks_near_roots(long double q2, long double q1, long double q0, std::int64_t n,
                      std::vector<std::int64_t>& out) {
    std::vector<long double> roots;
    if (q2 == 0) {
        if (q1 != 0) roots.push_back(-q0 / q1);
    } else {
        const long double disc = q1 * q1 - 4 * q2 * q0;
        if (disc >= 0) {
            const long double sq = std::sqrt(disc);
            const long double q = -0.5L * (q1 + (q1 >= 0 ? sq : -sq));
            roots.push_back(q / q2);
            if (q != 0) roots.push_back(q0 / q);
        }
    }
    for (long double r : roots) {
        if (!(r > -3 && r < static_cast<long double>(n) + 3)) continue;
        const auto base = static_cast<std::int64_t>(std::floor(r));
        for (std::int64_t k = base - 2; k <= base + 3; ++k) {
            if (k >= 0 && k <= n) out.push_back(k);
        }
    }
}

}  // namespace

// ---- Tick counts ------------------------------------------------------------------------

TEST_CASE("Tick counts 0 and above 65536 are rejected, 1 and 65536 accepted", "[rejection]") {
    const std::int32_t flat[4] = {5, 5, 5, 5};
    for (Basis b : kAllBases) {
        INFO("basis " << static_cast<int>(b));
        for (std::uint32_t n : {0u, kMaxSpanTicks + 1, 100000u, 0x80000000u, 0xFFFFFFFFu}) {
            INFO("n=" << n);
            SpanTiming timing;
            timing.ticks = 77;
            timing.denominator = 1234;
            const Status s = pathstream::make_span_timing(b, n, timing);
            REQUIRE(name(s) == name(Status::kTickCountOutOfRange));
            Span<2> span;
            span.basis = b;
            span.ticks = n;
            PreparedSpan<2> out;
            const Status sp = pathstream::prepare_span(span, out);
            REQUIRE(name(sp) == name(Status::kTickCountOutOfRange));
            SetpointStream<2, 2> stream;
            const Status ss = stream.push(span);
            REQUIRE(name(ss) == name(Status::kTickCountOutOfRange));
            REQUIRE(stream.queued_spans() == 0);
        }
        for (std::uint32_t n : {1u, 2u, kMaxSpanTicks - 1, kMaxSpanTicks}) {
            INFO("n=" << n);
            SpanTiming timing;
            const Status s = pathstream::make_span_timing(b, n, timing);
            REQUIRE(name(s) == name(Status::kOk));
            REQUIRE(timing.ticks == n);
            REQUIRE(timing.denominator ==
                    std::uint64_t{pathstream::basis_matrix(b).scale} * n * n * n);
            TickCubic cubic;
            const Status c = pathstream::make_tick_cubic(b, flat, timing, cubic);
            REQUIRE(name(c) == name(Status::kOk));
            Lsb v = 0;
            const Status e = pathstream::evaluate_at(cubic, timing, n, v);
            REQUIRE(name(e) == name(Status::kOk));
            // Every basis ends at 5 here (Hermite: P1; its tangents are 5 too).
            REQUIRE(v == 5);
        }
    }
}

// ---- Control value ranges ---------------------------------------------------------------

TEST_CASE("Control values outside their range are rejected, boundary values accepted",
          "[rejection]") {
    const std::uint32_t n = kMaxSpanTicks;  // long: no difference limit comes near
    for (Basis b : kAllBases) {
        for (int slot = 0; slot < 4; ++slot) {
            const bool tangent = b == Basis::kHermite && slot >= 2;
            const std::int64_t limit = tangent ? kMaxTangentLsb : kMaxPositionLsb;
            INFO("basis " << static_cast<int>(b) << " slot " << slot << " limit " << limit);
            for (std::int64_t sign : {1, -1}) {
                std::int32_t p[4] = {0, 0, 0, 0};
                p[slot] = static_cast<std::int32_t>(sign * limit);
                const Status at = build(b, p, n);
                CHECK(name(at) == name(Status::kOk));
                p[slot] = static_cast<std::int32_t>(sign * (limit + 1));
                const Status past = build(b, p, n);
                CHECK(name(past) == name(Status::kControlValueOutOfRange));
                p[slot] = sign > 0 ? std::numeric_limits<std::int32_t>::max()
                                   : std::numeric_limits<std::int32_t>::min();
                const Status far = build(b, p, n);
                CHECK(name(far) == name(Status::kControlValueOutOfRange));
                // One past the position limit is a valid Hermite tangent, nothing else.
                p[slot] = static_cast<std::int32_t>(sign * (kMaxPositionLsb + 1));
                const Status pos_past = build(b, p, n);
                CHECK(name(pos_past) ==
                      name(tangent ? Status::kOk : Status::kControlValueOutOfRange));
            }
        }
        // All four at the limits at once (a flat or full-swing span over the longest span).
        const auto m = static_cast<std::int32_t>(kMaxPositionLsb);
        const std::int32_t high[4] = {m, m, m, m}, low[4] = {-m, -m, -m, -m};
        const std::int32_t swing[4] = {-m, m, -m, m};
        for (const auto* p : {&high, &low, &swing}) {
            const Status s = build(b, *p, n);
            CHECK(name(s) == name(Status::kOk));
        }
    }
    // Hermite tangents at +/-2^29 on both ends over the longest span.
    const auto t = static_cast<std::int32_t>(kMaxTangentLsb);
    const auto m = static_cast<std::int32_t>(kMaxPositionLsb);
    const std::int32_t hermite[4] = {-m, m, t, -t};
    const Status s = build(Basis::kHermite, hermite, n);
    CHECK(name(s) == name(Status::kOk));

    // A bad value on the last axis of a multi-axis span rejects the whole span.
    Span<3> span;
    span.basis = Basis::kBezier;
    span.ticks = 100;
    span.control[2][3] = static_cast<std::int32_t>(kMaxPositionLsb + 1);
    PreparedSpan<3> out;
    const Status sp = pathstream::prepare_span(span, out);
    CHECK(name(sp) == name(Status::kControlValueOutOfRange));
}

// ---- Curves and differences that would overflow ------------------------------------------

TEST_CASE("Spans whose per-tick differences would overflow are rejected", "[rejection]") {
    const auto m = static_cast<std::int32_t>(kMaxPositionLsb);
    const auto t = static_cast<std::int32_t>(kMaxTangentLsb);
    struct Case {
        Basis basis;
        std::int32_t p[4];
    };
    const Case cases[] = {
        {Basis::kUniformBSpline, {-m, m, -m, m}}, {Basis::kCatmullRom, {m, -m, m, -m}},
        {Basis::kCatmullRom, {-m, -m, m, m}},  // -m to m in one tick
        {Basis::kBezier, {-m, m, -m, m}},         {Basis::kBezier, {m, -m, m, -m}},
        {Basis::kHermite, {-m, m, t, t}},         {Basis::kHermite, {m, -m, -t, -t}},
        {Basis::kHermite, {0, 1, t, -t}},  // acceleration 2^30 + 6 per tick^2
    };
    for (const Case& c : cases) {
        INFO(describe(c.basis, c.p, 1));
        // n = 1: rejected, and the reference confirms some difference really is out of range
        // (the differencer's state at ticks 0 and 1 carries Delta1..Delta3 from there).
        SpanTiming timing;
        TickCubic cubic{11, 22, 33, 44};
        const Status s = build(c.basis, c.p, 1, timing, cubic);
        CHECK((name(s) == name(Status::kDifferenceOutOfRange) ||
               name(s) == name(Status::kCurveOutOfRange)));
        CHECK((cubic.a == 11 && cubic.b == 22 && cubic.c == 33 && cubic.d == 44));
        const ExactSpan exact(c.basis, c.p, 1);
        const i128 bound = i128{kMaxDifferenceLsb} * exact.den;
        bool beyond = abs128(exact.delta3()) > bound;
        for (int k = 0; k <= 1; ++k) {
            beyond = beyond || abs128(exact.delta1(k)) > bound || abs128(exact.delta2(k)) > bound;
        }
        CHECK(beyond);
        // The same points over the longest span are gentle: accepted.
        const Status slow = build(c.basis, c.p, kMaxSpanTicks);
        CHECK(name(slow) == name(Status::kOk));
        // Bisect the shortest accepted tick count; just below it the span is rejected, at it
        // the exact differences are within range.
        std::uint32_t lo = 1, hi = kMaxSpanTicks;  // lo rejected, hi accepted
        while (hi - lo > 1) {
            const std::uint32_t mid = lo + (hi - lo) / 2;
            (build(c.basis, c.p, mid) == Status::kOk ? hi : lo) = mid;
        }
        INFO("shortest accepted n=" << hi);
        const ExactSpan at(c.basis, c.p, hi);
        const i128 b2 = i128{kMaxDifferenceLsb} * at.den;
        CHECK(abs128(at.delta3()) <= b2);
        CHECK(abs128(at.delta2(0)) <= b2);
        CHECK(abs128(at.delta2(hi)) <= b2);
        CHECK(abs128(at.delta1(0)) <= b2);
        CHECK(abs128(at.delta1(hi)) <= b2);
    }
    // Each bound on its own: n = 1 spans where exactly one of velocity (at either tick),
    // acceleration at tick 0, acceleration at tick 1 or jerk exceeds 2^30 per tick^k while the
    // others stay below it. The reference proves the premise; the core must still refuse.
    {
        struct Single {
            const char* which;
            Basis basis;
            std::int32_t p[4];
        };
        const Single singles[] = {
            {"velocity", Basis::kBezier, {0, -m, -87480225, m}},
            {"acceleration at 0", Basis::kBezier, {-m, m, m, -54339179}},
            {"acceleration at 1", Basis::kBezier, {0, -67108864, -m, -25965319}},
            {"acceleration at 1", Basis::kUniformBSpline, {111259841, -m, m, -m}},
            {"jerk", Basis::kBezier, {-m, m, 45655727, -m}},
            {"jerk", Basis::kHermite, {m, 16264095, t, -t}},
        };
        for (const Single& c : singles) {
            INFO(c.which << " alone: " << describe(c.basis, c.p, 1));
            const ExactSpan e(c.basis, c.p, 1);
            const i128 bound = i128{kMaxDifferenceLsb} * e.den;
            const bool over[4] = {abs128(e.delta1(0)) > bound || abs128(e.delta1(1)) > bound,
                                  abs128(e.delta2(0)) > bound, abs128(e.delta2(1)) > bound,
                                  abs128(e.delta3()) > bound};
            const std::string which = c.which;
            const int expected_over = which == "velocity"            ? 0
                                      : which == "acceleration at 0" ? 1
                                      : which == "acceleration at 1" ? 2
                                                                     : 3;
            for (int q = 0; q < 4; ++q) REQUIRE(over[q] == (q == expected_over));
            const Status s = build(c.basis, c.p, 1);
            CHECK(name(s) == name(Status::kDifferenceOutOfRange));
        }
    }
    // Exactly at the limit is inside: Hermite n = 1 through 0 and 0 with tangents 2^29 and
    // -2^29 has acceleration exactly -2^30 per tick^2 (and velocity -2^30 at tick 1).
    {
        const std::int32_t edge[4] = {0, 0, t, -t};
        const Status s = build(Basis::kHermite, edge, 1);
        CHECK(name(s) == name(Status::kOk));
        const ExactSpan exact(Basis::kHermite, edge, 1);
        CHECK(exact.delta2(0) == -i128{kMaxDifferenceLsb} * exact.den);
        CHECK(exact.delta1(1) == -i128{kMaxDifferenceLsb} * exact.den);
        SetpointStream<1, 2> stream;
        Span<1> span;
        span.basis = Basis::kHermite;
        span.ticks = 1;
        for (int j = 0; j < 4; ++j) span.control[0][j] = edge[j];
        REQUIRE(stream.push(span) == Status::kOk);
        Lsb out[1];
        CHECK(stream.tick(out) == TickState::kMoving);
        CHECK(out[0] == 0);
        CHECK(stream.tick(out) == TickState::kIdle);
        CHECK(out[0] == 0);
    }
    // A multi-axis span: only axis 2 too steep.
    Span<3> span;
    span.basis = Basis::kBezier;
    span.ticks = 1;
    for (int j = 0; j < 4; ++j) span.control[2][j] = j % 2 ? m : -m;
    PreparedSpan<3> out;
    const Status sp = pathstream::prepare_span(span, out);
    CHECK((name(sp) == name(Status::kDifferenceOutOfRange) ||
           name(sp) == name(Status::kCurveOutOfRange)));
}

// ---- Unknown basis ----------------------------------------------------------------------

TEST_CASE("Basis ids outside the enumerators are rejected", "[rejection]") {
    for (unsigned id = 0; id < 256; ++id) {
        CHECK(pathstream::is_valid_basis(static_cast<std::uint8_t>(id)) == (id < 4));
    }
    const std::int32_t p[4] = {1, 2, 3, 4};
    for (unsigned id : {4u, 5u, 17u, 127u, 128u, 255u}) {
        INFO("basis id " << id);
        const auto b = static_cast<Basis>(id);
        SpanTiming timing;
        const Status t = pathstream::make_span_timing(b, 10, timing);
        CHECK(name(t) == name(Status::kUnknownBasis));
        // Even with a valid timing from a real basis.
        SpanTiming good;
        REQUIRE(pathstream::make_span_timing(Basis::kBezier, 10, good) == Status::kOk);
        TickCubic cubic{1, 2, 3, 4};
        const Status c = pathstream::make_tick_cubic(b, p, good, cubic);
        CHECK(name(c) == name(Status::kUnknownBasis));
        CHECK((cubic.a == 1 && cubic.b == 2 && cubic.c == 3 && cubic.d == 4));
        Span<1> span;
        span.basis = b;
        span.ticks = 10;
        PreparedSpan<1> out;
        const auto before = bytes(out);
        const Status s = pathstream::prepare_span(span, out);
        CHECK(name(s) == name(Status::kUnknownBasis));
        CHECK(bytes(out) == before);
        SetpointStream<1, 2> stream;
        const Status ps = stream.push(span);
        CHECK(name(ps) == name(Status::kUnknownBasis));
        CHECK(stream.queued_spans() == 0);
        Lsb o[1] = {99};
        CHECK(stream.tick(o) == TickState::kIdle);
        CHECK(o[0] == 0);
    }
}

// ---- Nothing half-written ---------------------------------------------------------------

TEST_CASE("A rejected span leaves the prepared span, the tick cubic and the stream untouched",
          "[rejection]") {
    const auto m = static_cast<std::int32_t>(kMaxPositionLsb);
    // A valid 3-axis span A and a family of spans that fail in different places.
    Span<3> good;
    good.basis = Basis::kCatmullRom;
    good.ticks = 40;
    good.tag = 7;
    for (int a = 0; a < 3; ++a) {
        for (int j = 0; j < 4; ++j) good.control[a][j] = 1000 * (a + 1) * j - 3 * a;
    }
    struct Bad {
        const char* what;
        Span<3> span;
        Status expected;
    };
    std::vector<Bad> bad;
    auto variant = [&](const char* what, Status expected, auto&& change) {
        Span<3> s = good;
        s.tag = 99;
        change(s);
        bad.push_back(Bad{what, s, expected});
    };
    variant("zero ticks", Status::kTickCountOutOfRange, [](Span<3>& s) { s.ticks = 0; });
    variant("too many ticks", Status::kTickCountOutOfRange, [](Span<3>& s) { s.ticks = 65537; });
    variant("unknown basis", Status::kUnknownBasis,
            [](Span<3>& s) { s.basis = static_cast<Basis>(9); });
    variant("axis 0 out of range", Status::kControlValueOutOfRange,
            [&](Span<3>& s) { s.control[0][0] = m + 1; });
    variant("axis 2 out of range", Status::kControlValueOutOfRange,
            [&](Span<3>& s) { s.control[2][3] = -m - 1; });
    variant("axis 2 too steep", Status::kDifferenceOutOfRange, [&](Span<3>& s) {
        s.basis = Basis::kBezier;
        s.ticks = 1;
        for (int a = 0; a < 2; ++a) {
            for (int j = 0; j < 4; ++j) s.control[a][j] = j;
        }
        for (int j = 0; j < 4; ++j) s.control[2][j] = j % 2 ? m : -m;
    });

    SECTION("prepare_span") {
        for (bool prepared : {false, true}) {
            PreparedSpan<3> out;
            if (prepared) REQUIRE(pathstream::prepare_span(good, out) == Status::kOk);
            const auto before = bytes(out);
            for (const Bad& b : bad) {
                INFO(b.what << (prepared ? " over a prepared span" : " over a fresh one"));
                const Status s = pathstream::prepare_span(b.span, out);
                if (b.expected == Status::kDifferenceOutOfRange) {
                    CHECK((name(s) == name(Status::kDifferenceOutOfRange) ||
                           name(s) == name(Status::kCurveOutOfRange)));
                } else {
                    CHECK(name(s) == name(b.expected));
                }
                CHECK(bytes(out) == before);
            }
        }
    }

    SECTION("make_tick_cubic") {
        const std::int32_t steep[4] = {-m, m, -m, m};
        const std::int32_t range[4] = {0, 0, m + 1, 0};
        SpanTiming timing;
        REQUIRE(pathstream::make_span_timing(Basis::kBezier, 1, timing) == Status::kOk);
        for (const auto* p : {&steep, &range}) {
            TickCubic cubic{-5, 6, -7, 8};
            const Status s = pathstream::make_tick_cubic(Basis::kBezier, *p, timing, cubic);
            CHECK(name(s) != name(Status::kOk));
            CHECK((cubic.a == -5 && cubic.b == 6 && cubic.c == -7 && cubic.d == 8));
        }
    }

    SECTION("SetpointStream::push") {
        // A continuous chain (push() accepts nothing else): good starts at the stream's start
        // position, and each later span is moved by translation to start where the previous
        // one ends.
        Lsb start[3], end[3];
        core_ends(good, start, end);
        SetpointStream<3, 4> stream(start);
        Span<3> second = good;
        second.tag = 8;
        for (int a = 0; a < 3; ++a) {
            for (int j = 0; j < 4; ++j) second.control[a][j] = good.control[a][3] - 17 * j;
        }
        chain_after(second, end, end);
        REQUIRE(stream.push(good) == Status::kOk);
        REQUIRE(stream.push(second) == Status::kOk);
        Lsb out[3];
        auto expect_tick = [&](const Span<3>& s, std::uint32_t k) {
            REQUIRE(stream.tick(out) == TickState::kMoving);
            for (int a = 0; a < 3; ++a) {
                REQUIRE(out[a] == reference_setpoint(s.basis, s.control[a], s.ticks, k));
            }
        };
        // Each refused push returns the span's own status (validation before continuity
        // before room: these bad spans do not continue the chain either) and changes nothing.
        auto expect_refused = [&](const Bad& b, std::uint32_t queued) {
            INFO(b.what << " with " << queued << " queued");
            const Status s = stream.push(b.span);
            if (b.expected == Status::kDifferenceOutOfRange) {
                CHECK((name(s) == name(Status::kDifferenceOutOfRange) ||
                       name(s) == name(Status::kCurveOutOfRange)));
            } else {
                CHECK(name(s) == name(b.expected));
            }
            CHECK(stream.queued_spans() == queued);
            CHECK(stream.free_slots() == 4 - queued);
            CHECK(stream.ticks_executed() == 5);
            CHECK(stream.spans_completed() == 0);
        };
        for (std::uint32_t k = 0; k < 5; ++k) expect_tick(good, k);
        // Failures with free slots (the slot claimed for them must not become visible).
        Span<3> third = second, fourth = second, fifth = good;
        third.tag = 9;
        fourth.tag = 10;
        fifth.tag = 11;
        for (int a = 0; a < 3; ++a) third.control[a][0] += 1;
        for (int a = 0; a < 3; ++a) fourth.control[a][1] -= 1;
        chain_after(third, end, end);
        // A valid span that does not continue the chain: third, 1 LSB off on axis 2.
        Span<3> third_off = third;
        for (int j = 0; j < 4; ++j) third_off.control[2][j] += 1;
        for (const Bad& b : bad) expect_refused(b, 2);
        expect_refused(Bad{"third, 1 LSB off", third_off, Status::kDiscontinuousSpan}, 2);
        // Fill the queue, then fail once more with no free slot: still each span's own status,
        // never kQueueFull.
        REQUIRE(stream.push(third) == Status::kOk);
        chain_after(fourth, end, end);
        REQUIRE(stream.push(fourth) == Status::kOk);
        chain_after(fifth, end, end);
        Span<3> fifth_off = fifth;
        for (int j = 0; j < 4; ++j) fifth_off.control[0][j] -= 1;
        for (const Bad& b : bad) expect_refused(b, 4);
        expect_refused(Bad{"fifth, 1 LSB off", fifth_off, Status::kDiscontinuousSpan}, 4);
        // The valid continuous fifth span only waits for room.
        const Status full = stream.push(fifth);
        CHECK(name(full) == name(Status::kQueueFull));
        CHECK(stream.queued_spans() == 4);
        // Playback is exactly good (from tick 5), second, third, fourth; none of the refused.
        for (std::uint32_t k = 5; k < good.ticks; ++k) expect_tick(good, k);
        CHECK(stream.last_completed_tag() == 7);
        // good's slot is free now: fifth is accepted.
        const Status late = stream.push(fifth);
        REQUIRE(name(late) == name(Status::kOk));
        for (const Span<3>* s : {&second, &third, &fourth, &fifth}) {
            for (std::uint32_t k = 0; k < s->ticks; ++k) expect_tick(*s, k);
            CHECK(stream.last_completed_tag() == s->tag);
        }
        CHECK(stream.spans_completed() == 5);
        CHECK(stream.ticks_executed() == 5u * good.ticks);
        CHECK(stream.tick(out) == TickState::kIdle);
        for (int a = 0; a < 3; ++a) CHECK(out[a] == end[a]);
    }
}

// ---- Ticks outside the span -------------------------------------------------------------

TEST_CASE("evaluate_at and start_differences past the end return kTickOutsideSpan", "[rejection]") {
    const std::int32_t p[4] = {10, -20, 30, -40};
    for (Basis b : kAllBases) {
        for (std::uint32_t n : {1u, 2u, 894u, 895u, 1625u, 1626u, kMaxSpanTicks}) {
            INFO("basis " << static_cast<int>(b) << " n=" << n);
            SpanTiming timing;
            TickCubic cubic;
            REQUIRE(build(b, p, n, timing, cubic) == Status::kOk);
            Lsb v = 0;
            const Status at_end = pathstream::evaluate_at(cubic, timing, n, v);
            CHECK(name(at_end) == name(Status::kOk));
            CHECK(v == reference_setpoint(b, p, n, n));
            for (std::uint32_t k : {n + 1, n + 2, 0x7FFFFFFFu, 0xFFFFFFFFu}) {
                const Status s = pathstream::evaluate_at(cubic, timing, k, v);
                CHECK(name(s) == name(Status::kTickOutsideSpan));
                pathstream::WideDifferences wide{};
                const Status w = pathstream::start_differences(cubic, timing, k, wide);
                CHECK(name(w) == name(Status::kTickOutsideSpan));
                if (pathstream::is_narrow(timing)) {
                    pathstream::NarrowDifferences narrow{};
                    const Status nr = pathstream::start_differences(cubic, timing, k, narrow);
                    CHECK(name(nr) == name(Status::kTickOutsideSpan));
                }
            }
            // k == n is inside: the differencer starts on the end point.
            if (pathstream::is_narrow(timing)) {
                pathstream::NarrowDifferences narrow{};
                REQUIRE(pathstream::start_differences(cubic, timing, n, narrow) == Status::kOk);
                CHECK(narrow.position() == reference_setpoint(b, p, n, n));
            } else {
                pathstream::WideDifferences wide{};
                REQUIRE(pathstream::start_differences(cubic, timing, n, wide) == Status::kOk);
                CHECK(wide.position() == reference_setpoint(b, p, n, n));
            }
        }
    }
}

// ---- Soundness of acceptance ------------------------------------------------------------

TEST_CASE("Every accepted span stays within the curve and difference bounds at every tick",
          "[rejection]") {
    const auto seed = pathstream::test::property_seed();
    INFO("seed " << seed);
    SpanGenerator gen(seed + 11);
    const std::uint64_t per_basis =
        std::max<std::uint64_t>(100, pathstream::test::g_spans_per_basis);
    for (Basis b : kAllBases) {
        std::uint64_t accepted = 0, rejected = 0, checked_core = 0;
        for (std::uint64_t i = 0; i < per_basis; ++i) {
            std::int32_t p[4];
            gen.control(b, p);
            // Bias toward short spans, where the difference bounds bite.
            const std::uint32_t n =
                i % 2 ? gen.ticks() : static_cast<std::uint32_t>(gen.uniform(1, 64));
            SpanTiming timing;
            TickCubic cubic;
            const Status s = build(b, p, n, timing, cubic);
            if (s != Status::kOk) {
                EXPECT(s == Status::kDifferenceOutOfRange || s == Status::kCurveOutOfRange,
                       describe(b, p, n) + ": " + name(s));
                ++rejected;
                continue;
            }
            ++accepted;
            const ExactSpan e(b, p, n);
            // The interpolation really is the reference's cubic.
            EXPECT(e.value(n) == reference_value(b, p, n, n).numerator, describe(b, p, n));
            // Candidate ticks: both ends, the curve's extremes (roots of N'), Delta1's vertex.
            // N'(k) = (f3/2) k^2 + (f2 - f3) k + (f1 - f2/2 + f3/3); Delta1'(k) = f3 k + f2 - f3/2.
            std::vector<std::int64_t> ticks{0, n};
            const auto f1 = static_cast<long double>(e.f1), f2 = static_cast<long double>(e.f2),
                       f3 = static_cast<long double>(e.f3);
            ticks_near_roots(f3 / 2, f2 - f3, f1 - f2 / 2 + f3 / 3, n, ticks);
            ticks_near_roots(0, f3, f2 - f3 / 2, n, ticks);
            const i128 curve_bound = i128{kMaxCurveLsb} * e.den;
            const i128 diff_bound = i128{kMaxDifferenceLsb} * e.den;
            EXPECT(abs128(e.delta3()) <= diff_bound,
                   describe(b, p, n) + " jerk " + str(e.delta3()));
            for (std::int64_t k : ticks) {
                EXPECT(abs128(e.value(k)) <= curve_bound,
                       describe(b, p, n) + " curve at tick " + std::to_string(k));
                EXPECT(abs128(e.delta1(k)) <= diff_bound,
                       describe(b, p, n) + " velocity at tick " + std::to_string(k));
                EXPECT(abs128(e.delta2(k)) <= diff_bound,
                       describe(b, p, n) + " acceleration at tick " + std::to_string(k));
            }
            // Every 8th accepted span: the core's own outputs at the tight ticks are exact
            // (an overflow in its setup or its quotients would show here).
            if (accepted % 8 == 0) {
                ++checked_core;
                for (std::int64_t k : ticks) {
                    Lsb v = 0;
                    const auto ku = static_cast<std::uint32_t>(k);
                    const Status es = pathstream::evaluate_at(cubic, timing, ku, v);
                    EXPECT(es == Status::kOk && v == reference_setpoint(b, p, n, k),
                           describe(b, p, n) + " evaluate_at " + std::to_string(k));
                }
                const auto k0 = static_cast<std::uint32_t>(ticks.back());
                const std::uint32_t steps = std::min<std::uint32_t>(3, n - k0);
                auto run = [&](auto state) {
                    const Status ss = pathstream::start_differences(cubic, timing, k0, state);
                    EXPECT(ss == Status::kOk, describe(b, p, n));
                    using Word = decltype(state.jerk_remainder);
                    const auto bias = static_cast<Word>(pathstream::difference_bias(timing));
                    for (std::uint32_t j = 0; j <= steps; ++j) {
                        EXPECT(state.position() == reference_setpoint(b, p, n, k0 + j),
                               describe(b, p, n) + " stepped tick " + std::to_string(k0 + j));
                        state.step(bias);
                    }
                };
                if (pathstream::is_narrow(timing)) {
                    run(pathstream::NarrowDifferences{});
                } else {
                    run(pathstream::WideDifferences{});
                }
            }
        }
        INFO("basis " << static_cast<int>(b) << ": accepted " << accepted << ", rejected "
                      << rejected << ", core checked " << checked_core);
        // Both outcomes occur, so the property is not vacuous.
        REQUIRE(accepted > per_basis / 4);
        REQUIRE(rejected > 0);
    }
}
