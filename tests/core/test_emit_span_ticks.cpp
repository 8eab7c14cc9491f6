// Batch stepping: emit_span_ticks (state in registers for many ticks) against emit_and_step
// (the tick interrupt's one tick at a time), bit for bit in every setpoint and every field of
// the state; against start_differences at the tick reached (a state computed by division,
// not by stepping); and against the independent __int128 reference. SetpointStream::tick_many
// against as many tick() calls on a second stream fed the same spans at the same ticks.
// Size: --spans N (a two-hundredth of it per basis, at least 40).
#include <algorithm>
#include <catch2/catch.hpp>
#include <cstdint>
#include <memory>
#include <sstream>
#include <string>

#include "core/property_settings.hpp"
#include "core/reference.hpp"
#include "pathstream/forward_difference.hpp"
#include "pathstream/setpoint_stream.hpp"
#include "pathstream/span.hpp"
#include "pathstream/tick_cubic.hpp"

using namespace pathstream;
using pathstream::test::reference_setpoint;
using pathstream::test::SpanGenerator;

namespace {

constexpr unsigned kAxes = 3;  // odd on purpose: no pairing of axes can hide a slip
constexpr Lsb kSentinel = 0x5A5A5A5A;

template <typename Word>
bool same_state(const DifferenceState<Word>& a, const DifferenceState<Word>& b) {
    return a.jerk_remainder == b.jerk_remainder && a.jerk_quotient == b.jerk_quotient &&
           a.remainder[0] == b.remainder[0] && a.remainder[1] == b.remainder[1] &&
           a.remainder[2] == b.remainder[2] && a.quotient[0] == b.quotient[0] &&
           a.quotient[1] == b.quotient[1] && a.quotient[2] == b.quotient[2];
}

struct RandomSpan {
    Basis basis;
    std::int32_t control[kAxes][4];
    SpanTiming timing;
    TickCubic cubic[kAxes];
};

/// A span every axis of which the core accepts; tick counts as SpanGenerator draws them
/// (1..65536, log-uniform), so narrow and wide state both occur.
RandomSpan random_span(SpanGenerator& gen, Basis basis) {
    for (;;) {
        RandomSpan s{};
        s.basis = basis;
        REQUIRE(make_span_timing(basis, gen.ticks(), s.timing) == Status::kOk);
        bool ok = true;
        for (unsigned a = 0; a < kAxes && ok; ++a) {
            gen.control(basis, s.control[a]);
            ok = make_tick_cubic(basis, s.control[a], s.timing, s.cubic[a]) == Status::kOk;
        }
        if (ok) return s;
    }
}

/// Walks one span from a random tick to its end point twice: in random batches through
/// emit_span_ticks, and tick by tick through emit_and_step. Returns the number of failed
/// comparisons (a few are described with UNSCOPED_INFO).
template <typename Word>
std::uint64_t walk_span(const RandomSpan& s, SpanGenerator& gen) {
    const std::uint32_t n = s.timing.ticks;
    const auto bias = static_cast<Word>(difference_bias(s.timing));
    const auto k0 = static_cast<std::uint32_t>(gen.uniform(0, n));
    DifferenceState<Word> batch[kAxes], single[kAxes];
    for (unsigned a = 0; a < kAxes; ++a) {
        REQUIRE(start_differences(s.cubic[a], s.timing, k0, batch[a]) == Status::kOk);
        single[a] = batch[a];
    }
    // One row more than the longest batch: emit_span_ticks must not write past out[count).
    const std::uint32_t rows = n - k0 + 1;
    auto out = std::make_unique<Lsb[][kAxes]>(rows);
    // Long spans are checked against the reference at a stride (it costs ~100x a step).
    const std::uint32_t stride = n <= 4096 ? 1 : 61;
    std::uint64_t bad = 0;
    auto fail = [&](const std::string& what) {
        if (bad++ < 3)
            UNSCOPED_INFO("basis " << static_cast<int>(s.basis) << " n=" << n << " k0=" << k0
                                   << ": " << what);
    };
    for (std::uint32_t k = k0;;) {
        const std::uint32_t left = n - k;
        // Batch sizes: none, one, a few, a random share, everything left.
        std::uint32_t count = 0;
        switch (gen.uniform(0, 5)) {
            case 0:
                count = 0;
                break;
            case 1:
                count = std::min<std::uint32_t>(1, left);
                break;
            case 2:
                count =
                    static_cast<std::uint32_t>(gen.uniform(0, std::min<std::uint32_t>(left, 8)));
                break;
            case 3:
                count = static_cast<std::uint32_t>(gen.uniform(0, left));
                break;
            default:
                count = left;
                break;
        }
        for (std::uint32_t i = 0; i <= count; ++i) {
            for (unsigned a = 0; a < kAxes; ++a) out[i][a] = kSentinel;
        }
        emit_span_ticks(batch, out.get(), count, bias);
        for (std::uint32_t i = 0; i < count; ++i) {
            Lsb expected[kAxes];
            emit_and_step(single, expected, bias);
            for (unsigned a = 0; a < kAxes; ++a) {
                if (out[i][a] != expected[a]) {
                    fail("tick " + std::to_string(k + i) + " axis " + std::to_string(a) +
                         ": batch " + std::to_string(out[i][a]) + ", emit_and_step " +
                         std::to_string(expected[a]));
                }
                if ((k + i) % stride == 0 &&
                    out[i][a] != reference_setpoint(s.basis, s.control[a], n, k + i)) {
                    fail("tick " + std::to_string(k + i) + " axis " + std::to_string(a) +
                         " differs from the reference");
                }
            }
        }
        for (unsigned a = 0; a < kAxes; ++a) {
            if (out[count][a] != kSentinel)
                fail("wrote past out[count) at count " + std::to_string(count));
            if (!same_state(batch[a], single[a])) {
                fail("state after tick " + std::to_string(k + count) + " axis " +
                     std::to_string(a) + " differs from emit_and_step's");
            }
        }
        k += count;
        if (count == left) break;
    }
    // The end point's state, computed afresh: stepping must land on exactly these words.
    for (unsigned a = 0; a < kAxes; ++a) {
        DifferenceState<Word> fresh{};
        REQUIRE(start_differences(s.cubic[a], s.timing, n, fresh) == Status::kOk);
        if (!same_state(batch[a], fresh))
            fail("end state axis " + std::to_string(a) + " differs from start_differences(n)");
        if (batch[a].position() != reference_setpoint(s.basis, s.control[a], n, n))
            fail("end point differs from the reference");
    }
    return bad;
}

}  // namespace

TEST_CASE("emit_span_ticks equals emit_and_step tick for tick and lands on start_differences",
          "[exactness][batch]") {
    const std::uint64_t seed = pathstream::test::property_seed();
    const std::uint64_t spans =
        std::max<std::uint64_t>(pathstream::test::g_spans_per_basis / 200, 40);
    INFO("seed " << seed << ", " << spans << " spans per basis");
    for (std::uint8_t b = 0; b < kBasisCount; ++b) {
        const auto basis = static_cast<Basis>(b);
        SpanGenerator gen(seed * 16 + b + 3);
        std::uint64_t bad = 0, narrow = 0, wide = 0;
        for (std::uint64_t i = 0; i < spans; ++i) {
            const RandomSpan s = random_span(gen, basis);
            if (is_narrow(s.timing)) {
                ++narrow;
                bad += walk_span<std::uint32_t>(s, gen);
            } else {
                ++wide;
                bad += walk_span<std::uint64_t>(s, gen);
            }
        }
        INFO("basis " << static_cast<int>(b) << ": " << narrow << " narrow, " << wide
                      << " wide spans");
        REQUIRE(bad == 0);
        // Both representations must be reached, or the test proves less than it says.
        REQUIRE(narrow > 0);
        REQUIRE(wide > 0);
    }
}

namespace {

using Stream = SetpointStream<2, 8>;

/// A span from `from` that the core accepts: Hermite or Bezier (both start exactly at their
/// first point, so a chain is continuous by construction), 1..3000 ticks (wide state from
/// 1626), random outputs.
Span<2> chained_span(SpanGenerator& gen, const Lsb (&from)[2], std::uint32_t tag) {
    for (;;) {
        Span<2> span;
        span.basis = gen.uniform(0, 1) == 0 ? Basis::kHermite : Basis::kBezier;
        const auto pick = gen.uniform(0, 9);
        span.ticks =
            static_cast<std::uint32_t>(pick < 6 ? gen.uniform(1, 80) : gen.uniform(81, 3000));
        span.tag = tag;
        span.outputs = static_cast<std::uint8_t>(gen.uniform(0, 3));
        for (unsigned a = 0; a < 2; ++a) {
            const std::int64_t end = from[a] + gen.uniform(-200000, 200000);
            std::int32_t* c = span.control[a];
            c[0] = from[a];
            if (span.basis == Basis::kHermite) {
                c[1] = static_cast<std::int32_t>(end);
                c[2] = static_cast<std::int32_t>(gen.uniform(-300000, 300000));
                c[3] = static_cast<std::int32_t>(gen.uniform(-300000, 300000));
            } else {
                c[1] = static_cast<std::int32_t>(from[a] + gen.uniform(-100000, 100000));
                c[2] = static_cast<std::int32_t>(end + gen.uniform(-100000, 100000));
                c[3] = static_cast<std::int32_t>(end);
            }
        }
        PreparedSpan<2> scratch;
        if (prepare_span(span, scratch) == Status::kOk) return span;
    }
}

std::string counters(const Stream& s) {
    std::ostringstream os;
    os << "ticks " << s.ticks_executed() << ", spans " << s.spans_completed() << ", tag "
       << s.last_completed_tag() << ", outputs " << int{s.outputs()} << ", queued "
       << s.queued_spans() << ", between " << s.between_spans() << ", rest "
       << s.resting_position(0) << "/" << s.resting_position(1);
    return os.str();
}

}  // namespace

TEST_CASE("SetpointStream::tick_many equals as many tick() calls, idle stretches included",
          "[stream][batch]") {
    const std::uint64_t seed = pathstream::test::property_seed();
    INFO("seed " << seed);
    SpanGenerator gen(seed * 16 + 11);
    const Lsb start[2] = {1000, -2000};
    auto ticked = std::make_unique<Stream>(start);
    auto batched = std::make_unique<Stream>(start);
    auto out = std::make_unique<Lsb[][2]>(4001);
    Lsb end[2] = {start[0], start[1]};
    std::uint32_t tag = 0;
    std::uint64_t ticks = 0, idle_ticks = 0, wide_spans = 0, tick_calls_on_batched = 0;
    while (ticked->spans_completed() < 300) {
        // Producer: sometimes tops the queue up, sometimes lets it run dry (idle ticks).
        if (gen.uniform(0, 3) != 0) {
            while (ticked->free_slots() > 0 && gen.uniform(0, 4) != 0) {
                const Span<2> span = chained_span(gen, end, ++tag);
                wide_spans += span.ticks > 1625 ? 1u : 0u;
                REQUIRE(ticked->push(span) == Status::kOk);
                REQUIRE(batched->push(span) == Status::kOk);
                for (unsigned a = 0; a < 2; ++a)
                    end[a] = span.control[a][span.basis == Basis::kHermite ? 1 : 3];
            }
        }
        const auto count = static_cast<std::uint32_t>(gen.uniform(0, 9) < 3 ? gen.uniform(0, 3)
                                                                            : gen.uniform(0, 4000));
        for (std::uint32_t i = 0; i <= count; ++i) out[i][0] = out[i][1] = kSentinel;
        std::uint32_t batch_idle = 0;
        if (gen.uniform(0, 7) == 0) {
            // The same stream also ticked one tick at a time: the two calls must share state.
            for (std::uint32_t i = 0; i < count; ++i) {
                Lsb row[2];
                batch_idle += batched->tick(row) == TickState::kIdle ? 1u : 0u;
                out[i][0] = row[0];
                out[i][1] = row[1];
            }
            ++tick_calls_on_batched;
        } else {
            batch_idle = batched->tick_many(out.get(), count);
        }
        std::uint32_t single_idle = 0;
        for (std::uint32_t i = 0; i < count; ++i) {
            Lsb row[2];
            single_idle += ticked->tick(row) == TickState::kIdle ? 1u : 0u;
            if (row[0] != out[i][0] || row[1] != out[i][1]) {
                FAIL("tick " << ticks + i << ": tick() " << row[0] << "," << row[1]
                             << ", tick_many " << out[i][0] << "," << out[i][1]);
            }
        }
        REQUIRE(out[count][0] == kSentinel);
        REQUIRE(out[count][1] == kSentinel);
        REQUIRE(batch_idle == single_idle);
        REQUIRE(counters(*batched) == counters(*ticked));
        ticks += count;
        idle_ticks += single_idle;
    }
    INFO(ticks << " ticks, " << idle_ticks << " idle, " << wide_spans << " wide spans, "
               << tick_calls_on_batched << " batches by tick()");
    // The run must have gone through what it claims to test.
    REQUIRE(idle_ticks > 0);
    REQUIRE(wide_spans > 0);
    REQUIRE(tick_calls_on_batched > 0);
}
