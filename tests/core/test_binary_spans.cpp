// Spans whose denominator D = s n^3 is a power of two (Hermite and Bezier spans of 2^j ticks,
// Catmull-Rom spans of 2^j ticks; never a B-spline, s = 6) keep their remainders as binary
// fractions of the word, with K = 0, so that the word's carry needs no correction
// (docs/exact-math.md). Checked here: which spans are binary, the representation itself, and
// that such spans stay exact at every tick, both stepped from start_differences and played by
// SetpointStream, whose tick() gives them a path of their own.
#include <catch2/catch.hpp>
#include <cstdint>
#include <vector>

#include "core/reference.hpp"
#include "pathstream/forward_difference.hpp"
#include "pathstream/setpoint_stream.hpp"
#include "pathstream/tick_cubic.hpp"

using namespace pathstream;
using pathstream::test::reference_setpoint;
using pathstream::test::SpanGenerator;

namespace {

constexpr Basis kBases[] = {Basis::kUniformBSpline, Basis::kCatmullRom, Basis::kBezier,
                            Basis::kHermite};

bool power_of_two(std::uint64_t v) {
    return v != 0 && (v & (v - 1)) == 0;
}

/// Steps a span from k0 to its end; every remainder must be a multiple of 2^W / D, and every
/// setpoint the reference's. Returns the number of ticks checked.
template <typename Word>
std::uint64_t walk(Basis basis, const std::int32_t (&p)[4], const TickCubic& cubic,
                   const SpanTiming& timing, std::uint32_t k0) {
    DifferenceState<Word> s{};
    REQUIRE(start_differences(cubic, timing, k0, s) == Status::kOk);
    const auto bias = static_cast<Word>(difference_bias(timing));
    REQUIRE(bias == 0);
    // 2^W / D as a mask of the bits below it: a binary fraction has them all clear.
    const unsigned m = static_cast<unsigned>(__builtin_ctzll(timing.denominator));
    const unsigned word_bits = 8 * sizeof(Word);
    const Word low_bits =
        m == 0 ? static_cast<Word>(~Word{0}) : static_cast<Word>((Word{1} << (word_bits - m)) - 1);
    std::uint64_t checked = 0;
    for (std::uint32_t k = k0; k <= timing.ticks; ++k) {
        INFO("n=" << timing.ticks << " k=" << k << " P={" << p[0] << "," << p[1] << "," << p[2]
                  << "," << p[3] << "}");
        REQUIRE((s.jerk_remainder & low_bits) == 0);
        for (const Word r : s.remainder) REQUIRE((r & low_bits) == 0);
        REQUIRE(s.position() == reference_setpoint(basis, p, timing.ticks, k));
        ++checked;
        s.step(bias);
    }
    return checked;
}

}  // namespace

TEST_CASE("binary spans are exactly those whose D is a power of two, and their K is 0",
          "[exactness][binary]") {
    std::vector<std::uint32_t> lengths;
    for (std::uint32_t n = 1; n <= 130; ++n) lengths.push_back(n);
    for (unsigned j = 8; j <= 16; ++j) {
        const std::uint32_t n = std::uint32_t{1} << j;
        lengths.insert(lengths.end(), {n - 1, n, n + 1, n + n / 2});
    }
    for (const Basis basis : kBases) {
        for (const std::uint32_t n : lengths) {
            if (n > kMaxSpanTicks) continue;
            SpanTiming timing;
            REQUIRE(make_span_timing(basis, n, timing) == Status::kOk);
            const bool expected = basis != Basis::kUniformBSpline && power_of_two(n);
            INFO("basis " << static_cast<int>(basis) << " n=" << n);
            REQUIRE(is_binary(timing) == expected);
            REQUIRE(power_of_two(timing.denominator) == expected);
            const std::uint64_t general = is_narrow(timing)
                                              ? (std::uint64_t{1} << 32) - timing.denominator
                                              : 0 - timing.denominator;
            REQUIRE(difference_bias(timing) == (expected ? 0 : general));
        }
    }
}

TEST_CASE("binary spans keep binary-fraction remainders and stay exact at every tick",
          "[exactness][binary]") {
    SpanGenerator gen(0x5eed2b17);
    std::uint64_t spans = 0, ticks = 0, wide = 0;
    for (const Basis basis : {Basis::kCatmullRom, Basis::kBezier, Basis::kHermite}) {
        for (unsigned j = 0; j <= 16; ++j) {
            const std::uint32_t n = std::uint32_t{1} << j;
            SpanTiming timing;
            REQUIRE(make_span_timing(basis, n, timing) == Status::kOk);
            REQUIRE(is_binary(timing));
            for (int trial = 0; trial < 6; ++trial) {
                std::int32_t p[4];
                gen.control(basis, p);
                TickCubic cubic;
                if (make_tick_cubic(basis, p, timing, cubic) != Status::kOk) continue;
                // From tick 0 (what the stream prepares) and from a tick inside the span.
                const auto k0 = trial % 2 == 0 ? 0u : static_cast<std::uint32_t>(gen.uniform(0, n));
                if (is_narrow(timing)) {
                    ticks += walk<std::uint32_t>(basis, p, cubic, timing, k0);
                } else {
                    ticks += walk<std::uint64_t>(basis, p, cubic, timing, k0);
                    ++wide;
                }
                ++spans;
            }
        }
    }
    INFO(spans << " spans, " << wide << " wide, " << ticks << " ticks");
    REQUIRE(spans >= 200);
    REQUIRE(wide >= 20);
}

TEST_CASE("SetpointStream plays binary and other spans back to back, exactly",
          "[exactness][binary][stream]") {
    // A chain of Hermite spans (each starts at the previous one's end point P1), binary or
    // not, narrow and wide: the tick path switches between the general and the binary step,
    // and a binary span's first tick comes from the out-of-line start.
    constexpr unsigned kAxes = 2;
    const std::uint32_t lengths[] = {8, 7, 16, 1, 60, 2, 3, 4, 64, 2048, 1000, 8, 8, 5, 32, 1};
    SpanGenerator gen(0xb17a41);
    SetpointStream<kAxes, 4> stream;
    std::vector<Span<kAxes>> spans;
    Lsb at[kAxes] = {0, 0};
    for (const std::uint32_t n : lengths) {
        Span<kAxes> s;
        s.basis = Basis::kHermite;
        s.ticks = n;
        s.tag = static_cast<std::uint32_t>(spans.size() + 1);
        for (unsigned a = 0; a < kAxes; ++a) {
            s.control[a][0] = at[a];
            s.control[a][1] = static_cast<std::int32_t>(at[a] + gen.uniform(-20000, 20000));
            s.control[a][2] = static_cast<std::int32_t>(gen.uniform(-30000, 30000));
            s.control[a][3] = static_cast<std::int32_t>(gen.uniform(-30000, 30000));
            at[a] = s.control[a][1];
        }
        spans.push_back(s);
    }
    std::size_t next = 0;
    std::uint64_t checked = 0;
    for (const Span<kAxes>& s : spans) {
        for (std::uint32_t k = 0; k < s.ticks; ++k) {
            while (next < spans.size() && stream.free_slots() != 0) {
                REQUIRE(stream.push(spans[next]) == Status::kOk);
                ++next;
            }
            Lsb out[kAxes];
            REQUIRE(stream.tick(out) == TickState::kMoving);
            for (unsigned a = 0; a < kAxes; ++a) {
                INFO("span " << s.tag << " n=" << s.ticks << " k=" << k << " axis " << a);
                REQUIRE(out[a] == reference_setpoint(s.basis, s.control[a], s.ticks, k));
            }
            ++checked;
        }
        REQUIRE(stream.last_completed_tag() == s.tag);
    }
    Lsb out[kAxes];
    REQUIRE(stream.tick(out) == TickState::kIdle);
    for (unsigned a = 0; a < kAxes; ++a) REQUIRE(out[a] == at[a]);
    REQUIRE(stream.ticks_executed() == checked);
    REQUIRE(stream.spans_completed() == spans.size());
}
