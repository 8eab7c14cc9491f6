// SetpointStream as its users drive it: push spans (task), tick (interrupt). Every emitted
// setpoint is compared with the independent exact reference; the counters, the idle hold and
// the queue-full behaviour are checked along the way, single-threaded and with a real
// producer thread.
#include <catch2/catch.hpp>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "core/property_settings.hpp"
#include "core/reference.hpp"
#include "pathstream/setpoint_stream.hpp"
#include "pathstream/span.hpp"
#include "pathstream/tick_cubic.hpp"

using pathstream::Basis;
using pathstream::Lsb;
using pathstream::SetpointStream;
using pathstream::Span;
using pathstream::Status;
using pathstream::TickState;
using pathstream::test::reference_setpoint;
using pathstream::test::SpanGenerator;

namespace {

std::string name(Status s) { return pathstream::status_name(s); }

#define EXPECT(cond, context)                                          \
    do {                                                               \
        if (!(cond)) FAIL(#cond << "  [" << (context) << "]");         \
    } while (0)

template <unsigned Axes>
std::string describe(const Span<Axes>& s) {
    std::ostringstream os;
    os << "span tag " << s.tag << " basis " << static_cast<int>(s.basis) << " n=" << s.ticks;
    for (unsigned a = 0; a < Axes; ++a) {
        os << " {" << s.control[a][0] << ", " << s.control[a][1] << ", " << s.control[a][2]
           << ", " << s.control[a][3] << "}";
    }
    return os.str();
}

/// True when the core accepts `span` (checked on a scratch stream, so the one under test is
/// not involved).
template <unsigned Axes>
bool acceptable(const Span<Axes>& span) {
    pathstream::PreparedSpan<Axes> scratch;
    return pathstream::prepare_span(span, scratch) == Status::kOk;
}

/// A random span the core accepts: mixed bases, tick counts mostly short with some past the
/// narrow limit (wide state) and, rarely, very long.
template <unsigned Axes>
Span<Axes> random_span(SpanGenerator& gen, std::uint32_t tag) {
    Span<Axes> span;
    span.tag = tag;
    for (;;) {
        span.basis = gen.basis();
        const auto pick = gen.uniform(0, 99);
        span.ticks = static_cast<std::uint32_t>(pick < 70   ? gen.uniform(1, 64)
                                                : pick < 95 ? gen.uniform(65, 2000)
                                                            : gen.uniform(2001, 8000));
        for (unsigned a = 0; a < Axes; ++a) gen.control(span.basis, span.control[a]);
        if (acceptable(span)) return span;
    }
}

template <unsigned Axes>
std::int64_t expected(const Span<Axes>& s, unsigned axis, std::uint32_t k) {
    return reference_setpoint(s.basis, s.control[axis], s.ticks, k);
}

}  // namespace

TEST_CASE("An idle stream holds its start position", "[stream]") {
    const Lsb start[3] = {123, -456, 134217728};
    SetpointStream<3, 4> stream(start);
    CHECK(stream.queued_spans() == 0);
    CHECK(stream.free_slots() == 4);
    CHECK(stream.capacity() == 4);
    for (int i = 0; i < 10; ++i) {
        Lsb out[3] = {-1, -1, -1};
        CHECK(stream.tick(out) == TickState::kIdle);
        CHECK(out[0] == 123);
        CHECK(out[1] == -456);
        CHECK(out[2] == 134217728);
    }
    CHECK(stream.ticks_executed() == 0);
    CHECK(stream.spans_completed() == 0);
    CHECK(stream.last_completed_tag() == 0);

    SetpointStream<2, 2> zero;  // default: holds 0
    Lsb out[2] = {7, 7};
    CHECK(zero.tick(out) == TickState::kIdle);
    CHECK(out[0] == 0);
    CHECK(out[1] == 0);
}

TEST_CASE("push returns kQueueFull when full and changes nothing", "[stream]") {
    const Lsb start[2] = {0, 0};
    SetpointStream<2, 4> stream(start);
    std::vector<Span<2>> spans;
    for (std::uint32_t i = 0; i < 5; ++i) {
        Span<2> s;
        s.basis = static_cast<Basis>(i % 4);
        s.ticks = 3 + i;
        s.tag = 10 + i;
        for (int a = 0; a < 2; ++a) {
            for (int j = 0; j < 4; ++j) {
                s.control[a][j] = static_cast<std::int32_t>(1000 * i + 100 * a + 37 * j * (j % 2 ? -1 : 1));
            }
        }
        spans.push_back(s);
    }
    for (int i = 0; i < 4; ++i) {
        const Status s = stream.push(spans[static_cast<std::size_t>(i)]);
        REQUIRE(name(s) == name(Status::kOk));
        CHECK(stream.queued_spans() == static_cast<std::uint32_t>(i + 1));
        CHECK(stream.free_slots() == static_cast<std::uint32_t>(3 - i));
    }
    for (int attempt = 0; attempt < 3; ++attempt) {
        const Status s = stream.push(spans[4]);
        CHECK(name(s) == name(Status::kQueueFull));
        CHECK(stream.queued_spans() == 4);
        CHECK(stream.free_slots() == 0);
    }
    Lsb out[2];
    // The active span still occupies its slot: full until its last tick has been played.
    for (std::uint32_t k = 0; k < spans[0].ticks; ++k) {
        const Status s = stream.push(spans[4]);
        CHECK(name(s) == name(Status::kQueueFull));
        REQUIRE(stream.tick(out) == TickState::kMoving);
        for (unsigned a = 0; a < 2; ++a) CHECK(out[a] == expected(spans[0], a, k));
    }
    CHECK(stream.free_slots() == 1);
    CHECK(stream.last_completed_tag() == 10);
    // Spans 1..3 play untouched by the refused pushes; then the one pushed late.
    const Status late = stream.push(spans[4]);
    REQUIRE(name(late) == name(Status::kOk));
    for (std::size_t i = 1; i < 5; ++i) {
        for (std::uint32_t k = 0; k < spans[i].ticks; ++k) {
            REQUIRE(stream.tick(out) == TickState::kMoving);
            for (unsigned a = 0; a < 2; ++a) {
                CHECK(out[a] == expected(spans[i], a, k));
            }
        }
        CHECK(stream.last_completed_tag() == spans[i].tag);
        CHECK(stream.spans_completed() == i + 1);
    }
    CHECK(stream.tick(out) == TickState::kIdle);
    for (unsigned a = 0; a < 2; ++a) CHECK(out[a] == expected(spans[4], a, spans[4].ticks));
}

TEST_CASE("A chain of random spans plays exactly the reference setpoints, tick by tick",
          "[stream]") {
    const auto seed = pathstream::test::property_seed();
    INFO("seed " << seed);
    SpanGenerator gen(seed + 21);
    constexpr unsigned kAxes = 3;
    const std::uint64_t chain_length =
        std::max<std::uint64_t>(40, pathstream::test::g_spans_per_basis / 100);
    std::vector<Span<kAxes>> spans;
    for (std::uint64_t i = 0; i < chain_length; ++i) {
        spans.push_back(random_span<kAxes>(gen, static_cast<std::uint32_t>(i + 1)));
    }
    // One span of the longest length, in the middle: the wide state and the counters at 2^16.
    {
        Span<kAxes> longest;
        longest.basis = Basis::kUniformBSpline;
        longest.ticks = pathstream::kMaxSpanTicks;
        longest.tag = 0xFFFFFFFFu;
        for (unsigned a = 0; a < kAxes; ++a) gen.control(longest.basis, longest.control[a]);
        REQUIRE(acceptable(longest));
        spans.insert(spans.begin() + static_cast<std::ptrdiff_t>(spans.size() / 2), longest);
    }
    const Lsb start[kAxes] = {1, 2, 3};
    SetpointStream<kAxes, 8> stream(start);

    std::size_t pushed = 0, playing = 0;
    std::uint32_t k = 0;
    std::uint64_t ticks = 0;
    Lsb out[kAxes];
    while (playing < spans.size()) {
        // Producer: keep the queue topped up, with a rejected push now and then in between.
        while (pushed < spans.size() && stream.free_slots() > 0) {
            if (gen.uniform(0, 9) == 0) {
                Span<kAxes> bad = spans[pushed];
                bad.ticks = 0;
                const std::uint32_t before = stream.queued_spans();
                const Status s = stream.push(bad);
                EXPECT(s == Status::kTickCountOutOfRange, name(s));
                EXPECT(stream.queued_spans() == before, describe(bad));
            }
            const Status s = stream.push(spans[pushed]);
            EXPECT(s == Status::kOk, describe(spans[pushed]) + ": " + name(s));
            ++pushed;
        }
        const Span<kAxes>& span = spans[playing];
        const TickState state = stream.tick(out);
        EXPECT(state == TickState::kMoving, describe(span) + " tick " + std::to_string(k));
        for (unsigned a = 0; a < kAxes; ++a) {
            const auto want = expected(span, a, k);
            EXPECT(out[a] == want, describe(span) + " axis " + std::to_string(a) + " tick " +
                                       std::to_string(k) + " got " + std::to_string(out[a]) +
                                       " want " + std::to_string(want));
        }
        ++ticks;
        EXPECT(stream.ticks_executed() == ticks, ticks);
        if (++k == span.ticks) {
            k = 0;
            ++playing;
            EXPECT(stream.spans_completed() == playing, describe(span));
            EXPECT(stream.last_completed_tag() == span.tag, describe(span));
        } else {
            EXPECT(stream.spans_completed() == playing, describe(span));
            EXPECT(stream.last_completed_tag() == (playing == 0 ? 0u : spans[playing - 1].tag),
                   describe(span));
        }
    }
    // Dry: idle, holding the last span's tick-n value, counters frozen.
    const Span<kAxes>& last = spans.back();
    Lsb hold[kAxes];
    for (unsigned a = 0; a < kAxes; ++a) hold[a] = static_cast<Lsb>(expected(last, a, last.ticks));
    for (int i = 0; i < 5; ++i) {
        REQUIRE(stream.tick(out) == TickState::kIdle);
        for (unsigned a = 0; a < kAxes; ++a) REQUIRE(out[a] == hold[a]);
    }
    CHECK(stream.ticks_executed() == ticks);
    CHECK(stream.spans_completed() == spans.size());
    CHECK(stream.last_completed_tag() == last.tag);
    CHECK(stream.queued_spans() == 0);
    CHECK(stream.free_slots() == 8);

    // A span pushed after running dry continues from the hold point: a Hermite span that
    // starts there (P0 = hold) plays its tick 0 at the hold, then moves on.
    Span<kAxes> resume;
    resume.basis = Basis::kHermite;
    resume.ticks = 50;
    resume.tag = 4242;
    for (unsigned a = 0; a < kAxes; ++a) {
        resume.control[a][0] = hold[a];
        resume.control[a][1] = hold[a] + (hold[a] > 0 ? -5000 : 5000);
        resume.control[a][2] = 0;
        resume.control[a][3] = 0;
    }
    REQUIRE(stream.push(resume) == Status::kOk);
    for (std::uint32_t t = 0; t < resume.ticks; ++t) {
        REQUIRE(stream.tick(out) == TickState::kMoving);
        for (unsigned a = 0; a < kAxes; ++a) {
            REQUIRE(out[a] == expected(resume, a, t));
            if (t == 0) REQUIRE(out[a] == hold[a]);
        }
        REQUIRE(stream.ticks_executed() == ticks + t + 1);
    }
    CHECK(stream.spans_completed() == spans.size() + 1);
    CHECK(stream.last_completed_tag() == 4242);
    REQUIRE(stream.tick(out) == TickState::kIdle);
    for (unsigned a = 0; a < kAxes; ++a) CHECK(out[a] == resume.control[a][1]);
}

TEST_CASE("Spans of one tick: every tick is a boundary", "[stream]") {
    const auto seed = pathstream::test::property_seed();
    INFO("seed " << seed);
    SpanGenerator gen(seed + 22);
    SetpointStream<1, 2> stream;
    Lsb out[1];
    for (std::uint32_t i = 1; i <= 2000; ++i) {
        Span<1> span;
        span.ticks = 1;
        span.tag = i;
        do {
            span.basis = gen.basis();
            gen.control(span.basis, span.control[0]);
        } while (!acceptable(span));
        REQUIRE(stream.push(span) == Status::kOk);
        const TickState state = stream.tick(out);
        EXPECT(state == TickState::kMoving, describe(span));
        EXPECT(out[0] == expected(span, 0, 0), describe(span));
        EXPECT(stream.spans_completed() == i && stream.last_completed_tag() == i, describe(span));
        EXPECT(stream.ticks_executed() == i, describe(span));
        // Dry after every span: holds its end point.
        EXPECT(stream.tick(out) == TickState::kIdle, describe(span));
        EXPECT(out[0] == expected(span, 0, 1), describe(span));
    }
}

TEST_CASE("A producer thread and a ticking consumer thread agree with the reference",
          "[stream]") {
    const auto seed = pathstream::test::property_seed();
    INFO("seed " << seed);
    SpanGenerator gen(seed + 23);
    constexpr unsigned kAxes = 2;
    constexpr std::uint32_t kSpans = 20000;
    // Short spans, so boundaries (and full/empty races) are frequent.
    std::vector<Span<kAxes>> spans;
    spans.reserve(kSpans);
    for (std::uint32_t i = 0; i < kSpans; ++i) {
        Span<kAxes> span;
        span.tag = i + 1;
        do {
            span.basis = gen.basis();
            span.ticks = static_cast<std::uint32_t>(gen.uniform(1, 6));
            for (unsigned a = 0; a < kAxes; ++a) gen.control(span.basis, span.control[a]);
        } while (!acceptable(span));
        spans.push_back(span);
    }
    // Expected setpoints, computed up front so the consumer only compares.
    std::vector<Lsb> want;
    for (const auto& s : spans) {
        for (std::uint32_t k = 0; k < s.ticks; ++k) {
            for (unsigned a = 0; a < kAxes; ++a) want.push_back(static_cast<Lsb>(expected(s, a, k)));
        }
    }

    SetpointStream<kAxes, 4> stream;
    std::atomic<bool> stop{false};
    std::atomic<std::uint32_t> push_errors{0};
    std::thread producer([&] {
        for (std::uint32_t i = 0; i < kSpans && !stop.load(std::memory_order_relaxed);) {
            const Status s = stream.push(spans[i]);
            if (s == Status::kQueueFull) {
                std::this_thread::yield();
                continue;
            }
            if (s != Status::kOk) push_errors.fetch_add(1);
            ++i;
        }
    });

    std::size_t index = 0;
    std::uint64_t mismatches = 0, idle_wrong = 0, idle_ticks = 0;
    std::size_t first_mismatch = 0;
    Lsb last_end[kAxes] = {0, 0};
    std::uint32_t completed = 0;
    while (stream.spans_completed() < kSpans) {
        Lsb out[kAxes];
        if (stream.tick(out) == TickState::kIdle) {
            ++idle_ticks;
            for (unsigned a = 0; a < kAxes; ++a) {
                if (out[a] != last_end[a]) ++idle_wrong;
            }
            std::this_thread::yield();
            continue;
        }
        for (unsigned a = 0; a < kAxes; ++a) {
            if (index >= want.size() || out[a] != want[index]) {
                if (mismatches++ == 0) first_mismatch = index;
            }
            ++index;
        }
        if (stream.spans_completed() != completed) {
            completed = stream.spans_completed();
            if (completed <= kSpans) {
                const auto& s = spans[completed - 1];
                for (unsigned a = 0; a < kAxes; ++a) last_end[a] = static_cast<Lsb>(expected(s, a, s.ticks));
            }
        }
        if (mismatches > 100) break;
    }
    stop.store(true);
    producer.join();
    INFO("first mismatch at setpoint " << first_mismatch << ", idle ticks " << idle_ticks);
    CHECK(push_errors.load() == 0);
    CHECK(mismatches == 0);
    CHECK(idle_wrong == 0);
    CHECK(index == want.size());
    CHECK(stream.ticks_executed() == want.size() / kAxes);
    CHECK(stream.last_completed_tag() == kSpans);
}
