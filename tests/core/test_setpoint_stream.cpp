// SetpointStream as its users drive it: push spans (task), tick (interrupt). Every emitted
// setpoint is compared with the independent exact reference; the counters, the idle hold and
// the queue-full behaviour are checked along the way, single-threaded and with a real
// producer thread.
//
// push() accepts only a continuous chain: a span's tick-0 value (the core's rounded value)
// must equal, on every axis, the previous pushed span's tick-n value (for the first span: the
// stream's start position). Random spans are made continuous by translation, which is exact
// in the core: the same integer offset is added to every position control value (Hermite:
// P0 and P1, not the tangents), and every setpoint moves by exactly that offset.
#include <algorithm>
#include <array>
#include <atomic>
#include <catch2/catch.hpp>
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
using pathstream::kMaxPositionLsb;
using pathstream::Lsb;
using pathstream::SetpointStream;
using pathstream::Span;
using pathstream::Status;
using pathstream::TickState;
using pathstream::test::reference_setpoint;
using pathstream::test::SpanGenerator;

namespace {

std::string name(Status s) {
    return pathstream::status_name(s);
}

#define EXPECT(cond, context)                                  \
    do {                                                       \
        if (!(cond)) FAIL(#cond << "  [" << (context) << "]"); \
    } while (0)

template <unsigned Axes>
std::string describe(const Span<Axes>& s) {
    std::ostringstream os;
    os << "span tag " << s.tag << " basis " << static_cast<int>(s.basis) << " n=" << s.ticks;
    for (unsigned a = 0; a < Axes; ++a) {
        os << " {" << s.control[a][0] << ", " << s.control[a][1] << ", " << s.control[a][2] << ", "
           << s.control[a][3] << "}";
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

/// The core's own tick-0 (`start`) and tick-n (`end`) values of a valid span, every axis
/// (make_span_timing, make_tick_cubic, evaluate_at: what push() compares).
template <unsigned Axes>
void core_ends(const Span<Axes>& span, Lsb (&start)[Axes], Lsb (&end)[Axes]) {
    pathstream::SpanTiming timing;
    const Status t = pathstream::make_span_timing(span.basis, span.ticks, timing);
    if (t != Status::kOk) FAIL("core_ends: " << describe(span) << ": " << name(t));
    for (unsigned a = 0; a < Axes; ++a) {
        pathstream::TickCubic cubic;
        const Status c = pathstream::make_tick_cubic(span.basis, span.control[a], timing, cubic);
        if (c != Status::kOk) FAIL("core_ends: " << describe(span) << ": " << name(c));
        const Status s0 = pathstream::evaluate_at(cubic, timing, 0, start[a]);
        const Status sn = pathstream::evaluate_at(cubic, timing, span.ticks, end[a]);
        if (s0 != Status::kOk || sn != Status::kOk) FAIL("core_ends: evaluate_at failed");
    }
}

/// Number of leading control values that are positions (Hermite: P0, P1; the tangents T0, T1
/// do not move with a translation).
int position_slots(Basis b) {
    return b == Basis::kHermite ? 2 : 4;
}

/// Adds `offset` to every position control value of axis `axis`; false (span unchanged) if a
/// value would leave +/-kMaxPositionLsb.
template <unsigned Axes>
bool translate_axis(Span<Axes>& span, unsigned axis, std::int64_t offset) {
    const int slots = position_slots(span.basis);
    for (int j = 0; j < slots; ++j) {
        const std::int64_t v = std::int64_t{span.control[axis][j]} + offset;
        if (v > kMaxPositionLsb || v < -kMaxPositionLsb) return false;
    }
    for (int j = 0; j < slots; ++j) {
        span.control[axis][j] = static_cast<std::int32_t>(span.control[axis][j] + offset);
    }
    return true;
}

/// Translates the valid `span` so that it starts exactly at `at` (the previous span's end
/// point, or the stream's start), and writes its new end point to `end` (which may be `at`).
/// Returns false, with `span` and `end` unchanged, if a control value would leave the position
/// range. Checks with the core that the translated span starts at `at` and that its end moved
/// by the same offset.
template <unsigned Axes>
bool chain_after(Span<Axes>& span, const Lsb (&at)[Axes], Lsb (&end)[Axes]) {
    Lsb target[Axes], start[Axes], old_end[Axes];
    for (unsigned a = 0; a < Axes; ++a) target[a] = at[a];
    core_ends(span, start, old_end);
    Span<Axes> moved = span;
    for (unsigned a = 0; a < Axes; ++a) {
        if (!translate_axis(moved, a, std::int64_t{target[a]} - start[a])) return false;
    }
    Lsb new_start[Axes];
    core_ends(moved, new_start, end);
    for (unsigned a = 0; a < Axes; ++a) {
        const std::int64_t offset = std::int64_t{target[a]} - start[a];
        EXPECT(new_start[a] == target[a] && std::int64_t{end[a]} == old_end[a] + offset,
               "translation of " + describe(span) + " axis " + std::to_string(a) + " by " +
                   std::to_string(offset));
    }
    span = moved;
    return true;
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

/// The next span of a continuous chain: random spans from `make` (each one the core accepts),
/// translated to start at `at`; a span that cannot be translated that far without leaving
/// the position range is replaced by another. `end` receives the new span's end point;
/// `redraws` counts the replaced spans.
template <unsigned Axes, typename Make>
Span<Axes> chained(Make&& make, const Lsb (&at)[Axes], Lsb (&end)[Axes], std::uint64_t& redraws) {
    for (;;) {
        Span<Axes> span = make();
        if (chain_after(span, at, end)) return span;
        ++redraws;
    }
}

template <unsigned Axes>
std::int64_t expected(const Span<Axes>& s, unsigned axis, std::uint32_t k) {
    return reference_setpoint(s.basis, s.control[axis], s.ticks, k);
}

/// The consumer side of a single-threaded test: ticks the stream and checks every setpoint
/// against the reference for the spans accepted so far, in push order (and, when idle, the
/// hold: the last accepted span's end point, or the start position).
template <unsigned Axes, std::uint32_t Capacity>
class Player {
public:
    Player(SetpointStream<Axes, Capacity>& stream, const Lsb (&start)[Axes]) : stream_(stream) {
        for (unsigned a = 0; a < Axes; ++a) hold_[a] = start[a];
    }
    /// Records a span push() accepted.
    void accepted(const Span<Axes>& span) { spans_.push_back(span); }
    std::size_t pending() const { return spans_.size() - played_; }
    std::size_t completed() const { return played_; }

    /// One tick, checked.
    void tick() {
        Lsb out[Axes];
        const TickState state = stream_.tick(out);
        if (played_ == spans_.size()) {
            EXPECT(state == TickState::kIdle, "tick with nothing queued");
            for (unsigned a = 0; a < Axes; ++a) EXPECT(out[a] == hold_[a], "idle hold");
            return;
        }
        const Span<Axes>& span = spans_[played_];
        EXPECT(state == TickState::kMoving, describe(span) + " tick " + std::to_string(k_));
        for (unsigned a = 0; a < Axes; ++a) {
            const auto want = expected(span, a, k_);
            EXPECT(out[a] == want, describe(span) + " axis " + std::to_string(a) + " tick " +
                                       std::to_string(k_) + " got " + std::to_string(out[a]) +
                                       " want " + std::to_string(want));
        }
        if (++k_ == span.ticks) {
            for (unsigned a = 0; a < Axes; ++a) hold_[a] = static_cast<Lsb>(expected(span, a, k_));
            k_ = 0;
            ++played_;
            EXPECT(stream_.last_completed_tag() == span.tag, describe(span));
        }
        EXPECT(stream_.spans_completed() == played_, describe(span));
    }
    /// Ticks until every accepted span has played, then once more (idle, on the hold).
    void drain() {
        while (played_ < spans_.size()) tick();
        tick();
    }

private:
    SetpointStream<Axes, Capacity>& stream_;
    std::vector<Span<Axes>> spans_;
    std::size_t played_ = 0;
    std::uint32_t k_ = 0;  // tick inside spans_[played_]
    Lsb hold_[Axes] = {};
};

/// A producer that retries: pushes `span`, ticking `player` while the queue is full. Only
/// kQueueFull is retried; any other status fails the test at once, and the retries are
/// bounded by the ticks still queued, so it cannot spin.
template <unsigned Axes, std::uint32_t Capacity>
void push_retrying(SetpointStream<Axes, Capacity>& stream, Player<Axes, Capacity>& player,
                   const Span<Axes>& span, std::uint64_t max_ticks) {
    for (std::uint64_t waited = 0;; ++waited) {
        const Status s = stream.push(span);
        if (s == Status::kOk) break;
        INFO(describe(span));
        REQUIRE(name(s) == name(Status::kQueueFull));
        REQUIRE(waited < max_ticks);
        player.tick();
    }
    player.accepted(span);
}

/// Snapshot of everything push() must leave unchanged when it refuses a span.
template <unsigned Axes, std::uint32_t Capacity>
struct StreamCounters {
    std::uint32_t queued, free;
    std::uint64_t ticks;
    std::uint32_t completed, tag;
    explicit StreamCounters(const SetpointStream<Axes, Capacity>& s)
        : queued(s.queued_spans()),
          free(s.free_slots()),
          ticks(s.ticks_executed()),
          completed(s.spans_completed()),
          tag(s.last_completed_tag()) {}
    bool operator==(const StreamCounters&) const = default;
};

constexpr Basis kAllBases[] = {Basis::kUniformBSpline, Basis::kCatmullRom, Basis::kBezier,
                               Basis::kHermite};

/// A fixed, gentle span shape of basis `b` (positions around `base`, small tangents).
template <unsigned Axes>
Span<Axes> shape(Basis b, std::uint32_t ticks, std::uint32_t tag, std::int32_t base) {
    Span<Axes> s;
    s.basis = b;
    s.ticks = ticks;
    s.tag = tag;
    for (unsigned a = 0; a < Axes; ++a) {
        const auto axis = static_cast<std::int32_t>(a);
        const std::int32_t p[4] = {base + 100 * axis, base + 3000 - 700 * axis,
                                   base - 2500 + 1100 * axis, base + 4000 + 13 * axis};
        for (int j = 0; j < 4; ++j) s.control[a][j] = p[j];
        if (b == Basis::kHermite) {
            s.control[a][2] = 9000 - 500 * axis;
            s.control[a][3] = -7000 + 333 * axis;
        }
    }
    return s;
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
    Lsb end[2] = {start[0], start[1]};
    for (std::uint32_t i = 0; i < 5; ++i) {
        Span<2> s;
        s.basis = static_cast<Basis>(i % 4);
        s.ticks = 3 + i;
        s.tag = 10 + i;
        for (int a = 0; a < 2; ++a) {
            for (int j = 0; j < 4; ++j) {
                s.control[a][j] =
                    static_cast<std::int32_t>(1000 * i + 100 * a + 37 * j * (j % 2 ? -1 : 1));
            }
        }
        const Lsb at[2] = {end[0], end[1]};
        REQUIRE(chain_after(s, at, end));  // a continuous chain from the start position
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
    for (unsigned a = 0; a < 2; ++a) CHECK(out[a] == end[a]);
}

TEST_CASE("A chain of random spans plays exactly the reference setpoints, tick by tick",
          "[stream]") {
    const auto seed = pathstream::test::property_seed();
    INFO("seed " << seed);
    SpanGenerator gen(seed + 21);
    constexpr unsigned kAxes = 3;
    const std::uint64_t chain_length =
        std::max<std::uint64_t>(40, pathstream::test::g_spans_per_basis / 100);
    const Lsb start[kAxes] = {1, 2, 3};
    // A continuous chain from the start position, with one span of the longest length in the
    // middle: the wide state and the counters at 2^16.
    std::vector<Span<kAxes>> spans;
    std::uint64_t redraws = 0;
    Lsb end[kAxes] = {start[0], start[1], start[2]};
    for (std::uint64_t i = 0; i < chain_length; ++i) {
        const Lsb at[kAxes] = {end[0], end[1], end[2]};
        const auto tag = static_cast<std::uint32_t>(i + 1);
        if (i == chain_length / 2) {
            spans.push_back(chained<kAxes>(
                [&] {
                    Span<kAxes> longest;
                    longest.basis = Basis::kUniformBSpline;
                    longest.ticks = pathstream::kMaxSpanTicks;
                    longest.tag = 0xFFFFFFFFu;
                    for (unsigned a = 0; a < kAxes; ++a)
                        gen.control(longest.basis, longest.control[a]);
                    REQUIRE(acceptable(longest));
                    return longest;
                },
                at, end, redraws));
            continue;
        }
        spans.push_back(
            chained<kAxes>([&] { return random_span<kAxes>(gen, tag); }, at, end, redraws));
    }
    INFO("spans redrawn because they could not be moved onto the chain: " << redraws);
    SetpointStream<kAxes, 8> stream(start);

    std::size_t pushed = 0, playing = 0;
    std::uint32_t k = 0;
    std::uint64_t ticks = 0, refused = 0;
    Lsb out[kAxes];
    while (playing < spans.size()) {
        // Producer: keep the queue topped up, with a refused push now and then in between:
        // an invalid span (its own status) or the next span off by 1 LSB on one axis
        // (discontinuous). Neither may change the stream.
        while (pushed < spans.size() && stream.free_slots() > 0) {
            if (gen.uniform(0, 9) == 0) {
                Span<kAxes> bad = spans[pushed];
                Status want = Status::kTickCountOutOfRange;
                if (gen.uniform(0, 1) == 0) {
                    bad.ticks = 0;
                } else {
                    const auto axis = static_cast<unsigned>(gen.uniform(0, kAxes - 1));
                    want = Status::kDiscontinuousSpan;
                    if (!translate_axis(bad, axis, 1)) REQUIRE(translate_axis(bad, axis, -1));
                }
                const StreamCounters<kAxes, 8> before(stream);
                const Status s = stream.push(bad);
                EXPECT(s == want, describe(bad) + ": " + name(s) + ", want " + name(want));
                EXPECT((StreamCounters<kAxes, 8>(stream) == before), describe(bad));
                ++refused;
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
    CHECK(refused > 0);
    // Dry: idle, holding the last span's tick-n value, counters frozen.
    const Span<kAxes>& last = spans.back();
    Lsb hold[kAxes];
    for (unsigned a = 0; a < kAxes; ++a) hold[a] = static_cast<Lsb>(expected(last, a, last.ticks));
    for (unsigned a = 0; a < kAxes; ++a) REQUIRE(hold[a] == end[a]);
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
    SetpointStream<1, 2> stream;  // starts at 0
    Lsb end[1] = {0};
    std::uint64_t redraws = 0;
    Lsb out[1];
    for (std::uint32_t i = 1; i <= 2000; ++i) {
        const Lsb at[1] = {end[0]};
        const Span<1> span = chained<1>(
            [&] {
                Span<1> s;
                s.ticks = 1;
                s.tag = i;
                do {
                    s.basis = gen.basis();
                    gen.control(s.basis, s.control[0]);
                } while (!acceptable(s));
                return s;
            },
            at, end, redraws);
        REQUIRE(stream.push(span) == Status::kOk);
        const TickState state = stream.tick(out);
        EXPECT(state == TickState::kMoving, describe(span));
        EXPECT(out[0] == expected(span, 0, 0), describe(span));
        EXPECT(out[0] == at[0], describe(span));
        EXPECT(stream.spans_completed() == i && stream.last_completed_tag() == i, describe(span));
        EXPECT(stream.ticks_executed() == i, describe(span));
        // Dry after every span: holds its end point.
        EXPECT(stream.tick(out) == TickState::kIdle, describe(span));
        EXPECT(out[0] == expected(span, 0, 1), describe(span));
        EXPECT(out[0] == end[0], describe(span));
    }
}

TEST_CASE("A producer thread and a ticking consumer thread agree with the reference",
          "[stream][threads]") {
    const auto seed = pathstream::test::property_seed();
    INFO("seed " << seed);
    SpanGenerator gen(seed + 23);
    constexpr unsigned kAxes = 2;
    constexpr std::uint32_t kSpans = 20000;
    // Short spans, so boundaries (and full/empty races) are frequent; a continuous chain from
    // the default start position, 0.
    std::vector<Span<kAxes>> spans;
    spans.reserve(kSpans);
    Lsb end[kAxes] = {0, 0};
    std::uint64_t redraws = 0;
    for (std::uint32_t i = 0; i < kSpans; ++i) {
        const Lsb at[kAxes] = {end[0], end[1]};
        spans.push_back(chained<kAxes>(
            [&] {
                Span<kAxes> span;
                span.tag = i + 1;
                do {
                    span.basis = gen.basis();
                    span.ticks = static_cast<std::uint32_t>(gen.uniform(1, 6));
                    for (unsigned a = 0; a < kAxes; ++a) gen.control(span.basis, span.control[a]);
                } while (!acceptable(span));
                return span;
            },
            at, end, redraws));
    }
    // Expected setpoints, computed up front so the consumer only compares.
    std::vector<Lsb> want;
    for (const auto& s : spans) {
        for (std::uint32_t k = 0; k < s.ticks; ++k) {
            for (unsigned a = 0; a < kAxes; ++a)
                want.push_back(static_cast<Lsb>(expected(s, a, k)));
        }
    }

    SetpointStream<kAxes, 4> stream;
    std::atomic<bool> stop{false};
    std::atomic<bool> producer_done{false};
    // The producer retries kQueueFull only; any other status stops it (no skipping, no
    // spinning) and is reported here, and the consumer then stops once the queue is empty.
    std::atomic<int> refused_status{static_cast<int>(Status::kOk)};
    std::atomic<std::uint32_t> refused_index{0};
    std::thread producer([&] {
        for (std::uint32_t i = 0; i < kSpans && !stop.load(std::memory_order_relaxed);) {
            const Status s = stream.push(spans[i]);
            if (s == Status::kQueueFull) {
                std::this_thread::yield();
                continue;
            }
            if (s != Status::kOk) {
                refused_index.store(i);
                refused_status.store(static_cast<int>(s));
                break;
            }
            ++i;
        }
        producer_done.store(true, std::memory_order_release);
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
            // Nothing queued and the producer has finished: no span will ever come.
            if (producer_done.load(std::memory_order_acquire) && stream.queued_spans() == 0) break;
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
                for (unsigned a = 0; a < kAxes; ++a)
                    last_end[a] = static_cast<Lsb>(expected(s, a, s.ticks));
            }
        }
        if (mismatches > 100) break;
    }
    stop.store(true);
    producer.join();
    INFO("first mismatch at setpoint " << first_mismatch << ", idle ticks " << idle_ticks);
    {
        const auto refused = static_cast<Status>(refused_status.load());
        INFO("push refused span " << refused_index.load() << ": "
                                  << (refused == Status::kOk
                                          ? std::string("-")
                                          : describe(spans[refused_index.load()])));
        REQUIRE(name(refused) == name(Status::kOk));
    }
    CHECK(mismatches == 0);
    CHECK(idle_wrong == 0);
    CHECK(index == want.size());
    CHECK(stream.ticks_executed() == want.size() / kAxes);
    CHECK(stream.last_completed_tag() == kSpans);
}

// ---- Continuity: push() refuses a span that does not start where the chain ends -----------

TEST_CASE(
    "A span off by 1 LSB on one axis is refused with kDiscontinuousSpan and changes "
    "nothing",
    "[stream]") {
    constexpr unsigned kAxes = 3;
    constexpr std::uint32_t kCapacity = 4;
    const Lsb start[kAxes] = {500, -700, 123456};
    SetpointStream<kAxes, kCapacity> stream(start);
    Player<kAxes, kCapacity> player(stream, start);
    Lsb end[kAxes] = {start[0], start[1], start[2]};
    std::uint32_t tag = 1;
    std::uint64_t refused = 0;
    // Rounds over every basis: the next span, chained; first each of its off-by-one copies
    // (+1 and -1 on each axis alone) is refused, then the span itself is accepted. Round 0
    // refuses with spans still queued, round 1 with a full queue (discontinuity is checked
    // before room), round 2 on a stream that has run dry.
    for (int round = 0; round < 3; ++round) {
        for (Basis b : kAllBases) {
            Span<kAxes> next =
                shape<kAxes>(b, 7 + 5 * tag, tag, 40000 * static_cast<std::int32_t>(tag));
            ++tag;
            Lsb next_end[kAxes];
            REQUIRE(chain_after(next, end, next_end));
            if (round == 1) {
                // Fill the queue first (push_retrying ticks only while it is full).
                while (stream.free_slots() > 0) {
                    Span<kAxes> filler = shape<kAxes>(Basis::kBezier, 3, 1000 + tag, -5000);
                    Lsb filler_end[kAxes];
                    REQUIRE(chain_after(filler, end, filler_end));
                    REQUIRE(name(stream.push(filler)) == name(Status::kOk));
                    player.accepted(filler);
                    for (unsigned a = 0; a < kAxes; ++a) end[a] = filler_end[a];
                }
                REQUIRE(chain_after(next, end, next_end));
                REQUIRE(stream.free_slots() == 0);
            }
            if (round == 2) {
                player.drain();
                REQUIRE(stream.queued_spans() == 0);
            }
            for (unsigned axis = 0; axis < kAxes; ++axis) {
                for (std::int64_t delta : {1, -1}) {
                    Span<kAxes> off = next;
                    REQUIRE(translate_axis(off, axis, delta));
                    // The premise, from the core itself: only this axis is off, by delta.
                    Lsb off_start[kAxes], off_end[kAxes];
                    core_ends(off, off_start, off_end);
                    for (unsigned a = 0; a < kAxes; ++a) {
                        REQUIRE(off_start[a] == end[a] + (a == axis ? delta : 0));
                    }
                    INFO(describe(off)
                         << " axis " << axis << " off by " << delta << ", round " << round);
                    const StreamCounters<kAxes, kCapacity> before(stream);
                    const Status s = stream.push(off);
                    REQUIRE(name(s) == name(Status::kDiscontinuousSpan));
                    REQUIRE(StreamCounters<kAxes, kCapacity>(stream) == before);
                    ++refused;
                    // Refused again after a tick: the refusal did not move the chain's end.
                    player.tick();
                    const Status again = stream.push(off);
                    REQUIRE(name(again) == name(Status::kDiscontinuousSpan));
                }
            }
            // The correct span is accepted (after room appears, when the queue is full) and
            // plays back exactly.
            push_retrying(stream, player, next, 100000);
            for (unsigned a = 0; a < kAxes; ++a) end[a] = next_end[a];
        }
    }
    player.drain();
    CHECK(refused == 3 * 4 * kAxes * 2);
    CHECK(stream.spans_completed() == player.completed());
    Lsb out[kAxes];
    REQUIRE(stream.tick(out) == TickState::kIdle);
    for (unsigned a = 0; a < kAxes; ++a) CHECK(out[a] == end[a]);
}

TEST_CASE(
    "The first span must start at the constructor's start position (the core's rounded "
    "tick-0 value)",
    "[stream]") {
    // A B-spline span whose exact start is not an integer: axis 0 starts at
    // (0 + 4 * 100 + 3) / 6 = 67.17, rounded to 67; axis 1 exactly at -1000.
    Span<2> span;
    span.basis = Basis::kUniformBSpline;
    span.ticks = 30;
    span.tag = 1;
    const std::int32_t p0[4] = {0, 100, 3, 50}, p1[4] = {-1003, -1000, -997, -990};
    for (int j = 0; j < 4; ++j) {
        span.control[0][j] = p0[j];
        span.control[1][j] = p1[j];
    }
    REQUIRE(expected(span, 0, 0) == 67);
    REQUIRE(expected(span, 1, 0) == -1000);

    for (const auto& wrong :
         {std::array<Lsb, 2>{68, -1000}, std::array<Lsb, 2>{66, -1000},
          std::array<Lsb, 2>{67, -999}, std::array<Lsb, 2>{67, -1001}, std::array<Lsb, 2>{0, 0}}) {
        INFO("start {" << wrong[0] << ", " << wrong[1] << "}");
        const Lsb start[2] = {wrong[0], wrong[1]};
        SetpointStream<2, 2> stream(start);
        const Status s = stream.push(span);
        REQUIRE(name(s) == name(Status::kDiscontinuousSpan));
        CHECK(stream.queued_spans() == 0);
        CHECK(stream.free_slots() == 2);
        Lsb out[2];
        REQUIRE(stream.tick(out) == TickState::kIdle);  // still holding its start
        CHECK(out[0] == start[0]);
        CHECK(out[1] == start[1]);
    }
    {
        const Lsb start[2] = {67, -1000};
        SetpointStream<2, 2> stream(start);
        Player<2, 2> player(stream, start);
        REQUIRE(name(stream.push(span)) == name(Status::kOk));
        player.accepted(span);
        Lsb out[2];
        // Peek at tick 0 through a second, identical stream: the start position itself.
        SetpointStream<2, 2> twin(start);
        REQUIRE(twin.push(span) == Status::kOk);
        REQUIRE(twin.tick(out) == TickState::kMoving);
        CHECK(out[0] == 67);
        CHECK(out[1] == -1000);
        player.drain();
    }
    // The default constructor starts at 0: the same span is refused, the span moved onto 0 is
    // accepted.
    {
        SetpointStream<2, 2> stream;
        REQUIRE(name(stream.push(span)) == name(Status::kDiscontinuousSpan));
        Span<2> at_zero = span;
        const Lsb zero[2] = {0, 0};
        Lsb end[2];
        REQUIRE(chain_after(at_zero, zero, end));
        Player<2, 2> player(stream, zero);
        REQUIRE(name(stream.push(at_zero)) == name(Status::kOk));
        player.accepted(at_zero);
        player.drain();
    }
    // Halves round toward +infinity: an exact start of +1/2 is 1, of -1/2 is 0.
    {
        Span<1> half_up, half_down;
        half_up.basis = half_down.basis = Basis::kUniformBSpline;
        half_up.ticks = half_down.ticks = 10;
        const std::int32_t up[4] = {1, 0, 2, 7}, down[4] = {-1, 0, -2, 7};
        for (int j = 0; j < 4; ++j) {
            half_up.control[0][j] = up[j];
            half_down.control[0][j] = down[j];
        }
        REQUIRE(expected(half_up, 0, 0) == 1);
        REQUIRE(expected(half_down, 0, 0) == 0);
        SetpointStream<1, 2> zero;
        CHECK(name(zero.push(half_up)) == name(Status::kDiscontinuousSpan));
        CHECK(name(zero.push(half_down)) == name(Status::kOk));
        const Lsb one[1] = {1};
        SetpointStream<1, 2> at_one(one);
        CHECK(name(at_one.push(half_down)) == name(Status::kDiscontinuousSpan));
        CHECK(name(at_one.push(half_up)) == name(Status::kOk));
    }
}

TEST_CASE(
    "A full queue: an invalid span gets its validation error, a valid continuous one "
    "kQueueFull until a tick frees a slot",
    "[stream]") {
    constexpr unsigned kAxes = 2;
    constexpr std::uint32_t kCapacity = 2;
    const auto m = static_cast<std::int32_t>(kMaxPositionLsb);
    const Lsb start[kAxes] = {-250, 9000};
    SetpointStream<kAxes, kCapacity> stream(start);
    Player<kAxes, kCapacity> player(stream, start);
    Lsb end[kAxes] = {start[0], start[1]};
    std::vector<Span<kAxes>> chain;
    for (std::uint32_t i = 0; i < 4; ++i) {
        Span<kAxes> s =
            shape<kAxes>(kAllBases[i], 5 + i, i + 1, 1000 * static_cast<std::int32_t>(i));
        const Lsb at[kAxes] = {end[0], end[1]};
        REQUIRE(chain_after(s, at, end));
        chain.push_back(s);
    }
    for (std::uint32_t i = 0; i < kCapacity; ++i) {
        REQUIRE(name(stream.push(chain[i])) == name(Status::kOk));
        player.accepted(chain[i]);
    }
    REQUIRE(stream.free_slots() == 0);

    // Refused spans derived from the next span of the chain (chain[2]).
    struct Bad {
        const char* what;
        Span<kAxes> span;
        Status want;
    };
    std::vector<Bad> bad;
    auto variant = [&](const char* what, Status want, auto&& change) {
        Span<kAxes> s = chain[2];
        s.tag = 99;
        change(s);
        bad.push_back(Bad{what, s, want});
    };
    variant("zero ticks", Status::kTickCountOutOfRange, [](Span<kAxes>& s) { s.ticks = 0; });
    variant("too many ticks", Status::kTickCountOutOfRange,
            [](Span<kAxes>& s) { s.ticks = pathstream::kMaxSpanTicks + 1; });
    variant("unknown basis", Status::kUnknownBasis,
            [](Span<kAxes>& s) { s.basis = static_cast<Basis>(7); });
    variant("control value out of range", Status::kControlValueOutOfRange,
            [&](Span<kAxes>& s) { s.control[1][3] = m + 1; });
    variant("too steep", Status::kDifferenceOutOfRange, [&](Span<kAxes>& s) {
        s.basis = Basis::kBezier;
        s.ticks = 1;
        for (int j = 0; j < 4; ++j) s.control[0][j] = j % 2 ? m : -m;
    });
    variant("invalid and off by one", Status::kTickCountOutOfRange, [](Span<kAxes>& s) {
        REQUIRE(translate_axis(s, 0, 1));
        s.ticks = 0;
    });
    variant("valid but off by one", Status::kDiscontinuousSpan,
            [](Span<kAxes>& s) { REQUIRE(translate_axis(s, 1, -1)); });

    auto refuse_all = [&](const char* when) {
        for (const Bad& b : bad) {
            INFO(b.what << " " << when << ": " << describe(b.span));
            const StreamCounters<kAxes, kCapacity> before(stream);
            const Status s = stream.push(b.span);
            if (b.want == Status::kDifferenceOutOfRange) {
                CHECK((name(s) == name(Status::kDifferenceOutOfRange) ||
                       name(s) == name(Status::kCurveOutOfRange)));
            } else {
                CHECK(name(s) == name(b.want));
            }
            CHECK(StreamCounters<kAxes, kCapacity>(stream) == before);
        }
    };
    refuse_all("into a full queue");
    // The valid continuous span: kQueueFull, with nothing changed, until the active span's
    // last tick has been played.
    for (std::uint32_t k = 0; k < chain[0].ticks; ++k) {
        const StreamCounters<kAxes, kCapacity> before(stream);
        const Status s = stream.push(chain[2]);
        REQUIRE(name(s) == name(Status::kQueueFull));
        REQUIRE(StreamCounters<kAxes, kCapacity>(stream) == before);
        refuse_all("into a full queue, mid-span");
        player.tick();
    }
    REQUIRE(stream.free_slots() == 1);
    refuse_all("with a free slot");
    REQUIRE(name(stream.push(chain[2])) == name(Status::kOk));
    player.accepted(chain[2]);
    // And again through a producer that retries only on kQueueFull.
    push_retrying(stream, player, chain[3], chain[1].ticks + 1);
    player.drain();
    CHECK(stream.spans_completed() == 4);
    CHECK(stream.last_completed_tag() == chain[3].tag);
    Lsb out[kAxes];
    REQUIRE(stream.tick(out) == TickState::kIdle);
    for (unsigned a = 0; a < kAxes; ++a) CHECK(out[a] == end[a]);
}
