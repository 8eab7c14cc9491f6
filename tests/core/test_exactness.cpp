// Exactness: forward differencing == Horner == the independent __int128 reference, at every
// tick checked, for random spans of every basis. Size: --spans N per basis (default 100000).
#include <algorithm>
#include <catch2/catch.hpp>
#include <cstdio>

#include "core/property_settings.hpp"
#include "core/reference.hpp"
#include "pathstream/forward_difference.hpp"
#include "pathstream/tick_cubic.hpp"

using namespace pathstream;
using pathstream::test::reference_setpoint;
using pathstream::test::SpanGenerator;

namespace {

const char* basis_name(Basis b) {
    switch (b) {
        case Basis::kUniformBSpline:
            return "bspline";
        case Basis::kCatmullRom:
            return "catmull-rom";
        case Basis::kBezier:
            return "bezier";
        case Basis::kHermite:
            return "hermite";
    }
    return "?";
}

/// Worst case and totals of one run, printed so a large run reports what it covered.
struct Tally {
    std::uint64_t spans = 0, rejected = 0, ticks = 0, wide_spans = 0, mismatches = 0;
};

/// Walks forward differencing from k0 for `count` ticks, comparing every tick against Horner
/// and the reference. Returns the number of mismatching ticks (reported, then required 0).
template <typename Word>
std::uint64_t walk(Basis basis, const std::int32_t (&p)[4], const TickCubic& cubic,
                   const SpanTiming& timing, std::uint32_t k0, std::uint32_t count,
                   std::uint32_t horner_stride) {
    DifferenceState<Word> state{};
    REQUIRE(start_differences(cubic, timing, k0, state) == Status::kOk);
    const auto bias = static_cast<Word>(difference_bias(timing));
    std::uint64_t bad = 0;
    for (std::uint32_t i = 0; i < count; ++i) {
        const std::uint32_t k = k0 + i;
        const std::int64_t expected = reference_setpoint(basis, p, timing.ticks, k);
        bool ok = state.position() == expected;
        if (i % horner_stride == 0 || i + 1 == count) {
            Lsb horner = 0;
            REQUIRE(evaluate_at(cubic, timing, k, horner) == Status::kOk);
            ok = ok && horner == expected;
        }
        if (!ok && bad++ < 3) {
            UNSCOPED_INFO(basis_name(basis) << " n=" << timing.ticks << " k=" << k << " P={" << p[0]
                                            << "," << p[1] << "," << p[2] << "," << p[3] << "} fd="
                                            << state.position() << " expected=" << expected);
        }
        if (i + 1 < count) state.step(bias);
    }
    return bad;
}

std::uint64_t walk_any(Basis basis, const std::int32_t (&p)[4], const TickCubic& cubic,
                       const SpanTiming& timing, std::uint32_t k0, std::uint32_t count,
                       std::uint32_t horner_stride, Tally& tally) {
    tally.ticks += count;
    if (is_narrow(timing))
        return walk<std::uint32_t>(basis, p, cubic, timing, k0, count, horner_stride);
    ++tally.wide_spans;
    return walk<std::uint64_t>(basis, p, cubic, timing, k0, count, horner_stride);
}

void report(const char* what, Basis basis, std::uint64_t seed, const Tally& t) {
    std::printf(
        "%s %-11s seed=%llu spans=%llu rejected=%llu wide=%llu ticks=%llu mismatches=%llu\n", what,
        basis_name(basis), static_cast<unsigned long long>(seed),
        static_cast<unsigned long long>(t.spans), static_cast<unsigned long long>(t.rejected),
        static_cast<unsigned long long>(t.wide_spans), static_cast<unsigned long long>(t.ticks),
        static_cast<unsigned long long>(t.mismatches));
}

}  // namespace

TEST_CASE("forward differencing, Horner and the reference agree from any start tick",
          "[exactness]") {
    const std::uint64_t seed = pathstream::test::property_seed();
    const std::uint64_t spans = pathstream::test::g_spans_per_basis;
    INFO("seed " << seed << ", " << spans << " spans per basis");
    for (std::uint8_t b = 0; b < kBasisCount; ++b) {
        const auto basis = static_cast<Basis>(b);
        SpanGenerator gen(seed * 4 + b);
        Tally tally;
        while (tally.spans < spans) {
            std::int32_t p[4];
            gen.control(basis, p);
            SpanTiming timing;
            REQUIRE(make_span_timing(basis, gen.ticks(), timing) == Status::kOk);
            TickCubic cubic;
            if (make_tick_cubic(basis, p, timing, cubic) != Status::kOk) {
                ++tally.rejected;  // soundness of rejection is tested in [rejection]
                continue;
            }
            ++tally.spans;
            // A window of ticks from a random start (the end point, tick n, included when
            // the window reaches it), so initialisation at any tick is exercised too.
            const auto k0 = static_cast<std::uint32_t>(gen.uniform(0, timing.ticks));
            const std::uint32_t count = std::min<std::uint32_t>(timing.ticks - k0 + 1, 16);
            tally.mismatches += walk_any(basis, p, cubic, timing, k0, count, 1, tally);
        }
        report("window", basis, seed, tally);
        REQUIRE(tally.mismatches == 0);
        // The generator must reach both representations, or the run proves less than it says.
        REQUIRE(tally.wide_spans > 0);
        REQUIRE(tally.wide_spans < tally.spans);
    }
}

TEST_CASE("forward differencing stays exact over whole spans, end point included", "[exactness]") {
    const std::uint64_t seed = pathstream::test::property_seed();
    // Whole spans average ~6000 ticks: a hundredth of the window test's count keeps the
    // default run short while every span length from 1 to 65536 gets walked end to end.
    const std::uint64_t spans =
        std::max<std::uint64_t>(pathstream::test::g_spans_per_basis / 100, 8);
    INFO("seed " << seed);
    for (std::uint8_t b = 0; b < kBasisCount; ++b) {
        const auto basis = static_cast<Basis>(b);
        SpanGenerator gen(seed * 8 + b + 1);
        Tally tally;
        while (tally.spans < spans) {
            std::int32_t p[4];
            gen.control(basis, p);
            SpanTiming timing;
            // Every eighth span is the longest allowed, the worst case for word growth.
            const std::uint32_t n = tally.spans % 8 == 0 ? kMaxSpanTicks : gen.ticks();
            REQUIRE(make_span_timing(basis, n, timing) == Status::kOk);
            TickCubic cubic;
            if (make_tick_cubic(basis, p, timing, cubic) != Status::kOk) {
                ++tally.rejected;
                continue;
            }
            ++tally.spans;
            tally.mismatches += walk_any(basis, p, cubic, timing, 0, timing.ticks + 1, 997, tally);
        }
        report("whole ", basis, seed, tally);
        REQUIRE(tally.mismatches == 0);
    }
}

TEST_CASE("rounding is to nearest with halves toward +infinity", "[exactness]") {
    // A Bezier from 0 to 1 LSB over 2 ticks sits at exactly 1/2 in the middle; and from
    // 0 to -1 at -1/2. Both round up.
    SpanTiming timing;
    REQUIRE(make_span_timing(Basis::kBezier, 2, timing) == Status::kOk);
    TickCubic up, down;
    const std::int32_t rise[4] = {0, 0, 1, 1}, fall[4] = {0, 0, -1, -1};
    REQUIRE(make_tick_cubic(Basis::kBezier, rise, timing, up) == Status::kOk);
    REQUIRE(make_tick_cubic(Basis::kBezier, fall, timing, down) == Status::kOk);
    Lsb v = 7;
    REQUIRE(evaluate_at(up, timing, 1, v) == Status::kOk);
    CHECK(v == 1);
    REQUIRE(evaluate_at(down, timing, 1, v) == Status::kOk);
    CHECK(v == 0);
    NarrowDifferences fd{};
    REQUIRE(start_differences(down, timing, 0, fd) == Status::kOk);
    fd.step(static_cast<std::uint32_t>(difference_bias(timing)));
    CHECK(fd.position() == 0);
}
