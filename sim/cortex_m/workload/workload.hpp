// A fixed, deterministic workload for the core, compiled unchanged for the host and for the
// bare-metal Cortex-M images (freestanding: no heap, no I/O, no float, no OS headers).
//
// It pushes pseudo-random spans of all four bases through pathstream::SetpointStream for
// several axis counts and queue depths: narrow spans (8..300 ticks), wide spans (1700..8000
// ticks, always D >= 2^32, and once the longest span, 65536 ticks) and invalid spans (their
// status codes are checked). Every setpoint of every tick, every TickState, every status and
// every Horner value (pathstream::evaluate_at at pseudo-random ticks of each span) is folded
// into a 64-bit FNV-1a checksum. The checksum must be identical on every target.
//
// push() accepts only a continuous chain (a span's tick-0 value must equal the previous
// span's tick-n value, or the stream's start position), so every drawn span is moved onto the
// chain by translation, which is exact in the core: the same integer offset on every position
// control value of an axis (Hermite: P0 and P1, not the tangents). Once per section a copy of
// the next span, 1 LSB off on one axis, is pushed first and must be refused with
// kDiscontinuousSpan.
//
// It also checks itself: the stream's setpoint at two pseudo-random ticks of each span, and
// the held end point when the queue runs dry, must equal evaluate_at computed independently
// (make_span_timing + make_tick_cubic + Horner); differences are counted as mismatches.
#pragma once

#include <cstdint>

#include "pathstream/basis.hpp"
#include "pathstream/setpoint_stream.hpp"
#include "pathstream/span.hpp"
#include "pathstream/status.hpp"
#include "pathstream/tick_cubic.hpp"
#include "pathstream/units.hpp"

namespace pathstream::workload {

/// 64-bit FNV-1a over little-endian bytes.
class Fnv1a64 {
public:
    void byte(std::uint8_t b) {
        hash_ ^= b;
        hash_ *= 0x100000001b3u;
    }
    void u32(std::uint32_t v) {
        for (int i = 0; i < 4; ++i) byte(static_cast<std::uint8_t>(v >> (8 * i)));
    }
    void u64(std::uint64_t v) {
        u32(static_cast<std::uint32_t>(v));
        u32(static_cast<std::uint32_t>(v >> 32));
    }
    void lsb(Lsb v) { u32(static_cast<std::uint32_t>(v)); }
    std::uint64_t value() const { return hash_; }

private:
    std::uint64_t hash_ = 0xcbf29ce484222325u;
};

/// SplitMix64: small, fast, and identical on every platform (unsigned arithmetic only).
class SplitMix64 {
public:
    explicit SplitMix64(std::uint64_t seed) : state_(seed) {}
    std::uint64_t next() {
        std::uint64_t z = (state_ += 0x9e3779b97f4a7c15u);
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9u;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebu;
        return z ^ (z >> 31);
    }
    /// Uniform enough in [0, bound) for a workload (bound > 0).
    std::uint32_t below(std::uint32_t bound) {
        return static_cast<std::uint32_t>(next() >> 32) % bound;
    }
    /// In [lo, hi], both within int32 and hi - lo < 2^32 - 1.
    std::int32_t between(std::int64_t lo, std::int64_t hi) {
        const auto span = static_cast<std::uint32_t>(hi - lo + 1);
        return static_cast<std::int32_t>(lo + below(span));
    }

private:
    std::uint64_t state_;
};

/// What the workload did; printed by both mains next to the checksum.
struct Summary {
    std::uint64_t checksum = 0;
    std::uint32_t ticks = 0;               ///< tick() calls, idle ones included
    std::uint32_t spans_accepted = 0;      ///< push() == kOk
    std::uint32_t spans_rejected = 0;      ///< push() refused: validation error or discontinuity
    std::uint32_t horner_evaluations = 0;  ///< evaluate_at() calls
    std::uint32_t mismatches = 0;          ///< self-check failures; must be 0
};

/// Which tick counts a section draws.
enum class Width : std::uint8_t { kNarrow, kWide, kMixed };

struct Context {
    SplitMix64 rng{0x5eed'0f'9a75'57e4u};
    Fnv1a64 hash;
    Summary summary;
};

inline std::uint32_t draw_ticks(SplitMix64& rng, Width width) {
    const bool wide = width == Width::kWide || (width == Width::kMixed && rng.below(8) == 0);
    return wide ? 1700 + rng.below(6301)  // D >= 2^32 for every basis from n = 1626 on
                : 8 + rng.below(293);     // 8..300: the narrow, streaming case
}

/// Control values in range for the basis, in one of four styles (anywhere, at the limits,
/// tiny, gentle around an offset).
inline void draw_control(SplitMix64& rng, Basis basis, std::int32_t (&p)[4]) {
    const std::uint32_t style = rng.below(4);
    const std::int32_t center = rng.between(-kMaxPositionLsb / 2, kMaxPositionLsb / 2);
    for (int i = 0; i < 4; ++i) {
        const bool tangent = basis == Basis::kHermite && i >= 2;
        const std::int64_t limit = tangent ? kMaxTangentLsb : kMaxPositionLsb;
        std::int64_t v = 0;
        switch (style) {
            case 0:
                v = rng.between(-limit, limit);
                break;
            case 1:
                v = (rng.below(2) != 0 ? limit : -limit) - rng.between(-3, 3);
                break;
            case 2:
                v = rng.between(-1000, 1000);
                break;
            default:
                v = tangent ? rng.between(-200000, 200000) : center + rng.between(-50000, 50000);
        }
        if (v > limit) v = limit;
        if (v < -limit) v = -limit;
        p[i] = static_cast<std::int32_t>(v);
    }
}

/// The core's tick-0 value of `span` on every axis (make_span_timing, make_tick_cubic,
/// evaluate_at): where the chain must stand for push() to accept it. Returns the span's
/// validation error, if any (`start` is then unspecified). Axes evaluate_at calls.
template <unsigned Axes>
Status span_start(const Span<Axes>& span, Lsb (&start)[Axes]) {
    SpanTiming timing;
    if (Status s = make_span_timing(span.basis, span.ticks, timing); s != Status::kOk) return s;
    for (unsigned a = 0; a < Axes; ++a) {
        TickCubic cubic;
        if (Status s = make_tick_cubic(span.basis, span.control[a], timing, cubic);
            s != Status::kOk) {
            return s;
        }
        if (Status s = evaluate_at(cubic, timing, 0, start[a]); s != Status::kOk) return s;
    }
    return Status::kOk;
}

/// Translates one axis whose tick-0 value is `start` so that it starts at `at`: adds
/// at - start to each position control value (Hermite: P0, P1; not the tangents). Returns
/// false, leaving `control` unchanged, if a value would leave +/-kMaxPositionLsb.
inline bool translate_axis(Basis basis, std::int32_t (&control)[4], Lsb start, Lsb at) {
    const int positions = basis == Basis::kHermite ? 2 : 4;
    const std::int64_t offset = std::int64_t{at} - start;
    for (int j = 0; j < positions; ++j) {
        const std::int64_t v = control[j] + offset;
        if (v > kMaxPositionLsb || v < -kMaxPositionLsb) return false;
    }
    for (int j = 0; j < positions; ++j) control[j] = static_cast<std::int32_t>(control[j] + offset);
    return true;
}

/// Translates `span`, whose tick-0 values are `start`, so that it starts at `at` on every
/// axis (translate_axis). Returns false, leaving `span` unchanged, if any axis cannot move.
template <unsigned Axes>
bool translate(Span<Axes>& span, const Lsb (&start)[Axes], const Lsb (&at)[Axes]) {
    Span<Axes> moved = span;
    for (unsigned a = 0; a < Axes; ++a) {
        if (!translate_axis(moved.basis, moved.control[a], start[a], at[a])) return false;
    }
    span = moved;
    return true;
}

/// Draws the next span of a chain that stands at `at`: basis and tick count as drawn, then per
/// axis control values as drawn, translated to start at `at[axis]`. An axis the core rejects
/// (too steep) is left as drawn, so push() refuses the span with that error. An axis that
/// cannot be moved that far within the position range is drawn again, up to 16 times; then
/// it is flat at `at[axis]`. `longest`: the span lasts kMaxSpanTicks ticks.
template <unsigned Axes>
void draw_span(Context& ctx, Width width, bool longest, std::uint32_t tag, const Lsb (&at)[Axes],
               Span<Axes>& span) {
    SplitMix64& rng = ctx.rng;
    span.tag = tag;
    span.basis = static_cast<Basis>(rng.below(kBasisCount));
    span.ticks = longest ? kMaxSpanTicks : draw_ticks(rng, width);
    SpanTiming timing;
    if (make_span_timing(span.basis, span.ticks, timing) != Status::kOk) {
        ++ctx.summary.mismatches;  // every basis and tick count drawn here is valid
        return;
    }
    for (unsigned a = 0; a < Axes; ++a) {
        bool placed = false;
        for (int attempt = 0; attempt < 16 && !placed; ++attempt) {
            draw_control(rng, span.basis, span.control[a]);
            TickCubic cubic;
            Lsb start = 0;
            const Status s = make_tick_cubic(span.basis, span.control[a], timing, cubic);
            ctx.hash.byte(static_cast<std::uint8_t>(s));
            if (s != Status::kOk) return;  // rejected by the core anyway: left as drawn
            if (evaluate_at(cubic, timing, 0, start) != Status::kOk) ++ctx.summary.mismatches;
            ++ctx.summary.horner_evaluations;
            placed = translate_axis(span.basis, span.control[a], start, at[a]);
        }
        if (!placed) {
            for (int j = 0; j < 4; ++j) {
                span.control[a][j] = span.basis == Basis::kHermite && j >= 2 ? 0 : at[a];
            }
        }
    }
}

/// Makes every fourth-teenth span invalid in one of four ways; returns true if it did.
template <unsigned Axes>
bool maybe_break(SplitMix64& rng, Span<Axes>& span) {
    if (rng.below(14) != 0) return false;
    switch (rng.below(4)) {
        case 0:
            span.ticks = 0;
            break;
        case 1:
            span.ticks = kMaxSpanTicks + 1;
            break;
        case 2:
            span.basis = static_cast<Basis>(4 + rng.below(250));
            break;
        default:
            span.control[rng.below(Axes)][rng.below(2)] =
                static_cast<std::int32_t>(kMaxTangentLsb + 1 + rng.below(1000));
            break;
    }
    return true;
}

/// The independent expectation for one accepted span: Horner values at its start, at two
/// ticks inside it and at its end point.
template <unsigned Axes>
struct Expectation {
    std::uint32_t ticks = 0;
    std::uint32_t sample[2] = {0, 0};
    Lsb at_sample[2][Axes] = {};
    Lsb start[Axes] = {};
    Lsb end[Axes] = {};
};

/// Validates `span` independently of the stream and fills `e`; returns the first error.
template <unsigned Axes>
Status expect(Context& ctx, const Span<Axes>& span, Expectation<Axes>& e) {
    SpanTiming timing;
    if (Status s = make_span_timing(span.basis, span.ticks, timing); s != Status::kOk) return s;
    TickCubic cubic[Axes];
    for (unsigned a = 0; a < Axes; ++a) {
        if (Status s = make_tick_cubic(span.basis, span.control[a], timing, cubic[a]);
            s != Status::kOk) {
            return s;
        }
    }
    e.ticks = span.ticks;
    e.sample[0] = ctx.rng.below(span.ticks);
    e.sample[1] = ctx.rng.below(span.ticks);
    for (unsigned a = 0; a < Axes; ++a) {
        for (int j = 0; j < 2; ++j) {
            const Status s = evaluate_at(cubic[a], timing, e.sample[j], e.at_sample[j][a]);
            ctx.hash.byte(static_cast<std::uint8_t>(s));
            ctx.hash.lsb(e.at_sample[j][a]);
        }
        const Status s0 = evaluate_at(cubic[a], timing, 0, e.start[a]);
        ctx.hash.byte(static_cast<std::uint8_t>(s0));
        ctx.hash.lsb(e.start[a]);
        const Status s = evaluate_at(cubic[a], timing, span.ticks, e.end[a]);
        ctx.hash.byte(static_cast<std::uint8_t>(s));
        ctx.hash.lsb(e.end[a]);
        ctx.summary.horner_evaluations += 4;
    }
    // One evaluation past the end must be refused.
    Lsb ignored = 0;
    const Status past = evaluate_at(cubic[0], timing, span.ticks + 1, ignored);
    if (past != Status::kTickOutsideSpan) ++ctx.summary.mismatches;
    return Status::kOk;
}

/// True when `a` and `b` agree on every axis.
template <unsigned Axes>
bool same_point(const Lsb (&a)[Axes], const Lsb (&b)[Axes]) {
    for (unsigned i = 0; i < Axes; ++i) {
        if (a[i] != b[i]) return false;
    }
    return true;
}

/// Pushes a copy of the valid span `span` (which continues the chain), 1 LSB off on one
/// pseudo-random axis: push() must refuse it with kDiscontinuousSpan and change nothing.
/// Returns false (nothing pushed) if that copy would leave the position range.
template <unsigned Axes, std::uint32_t Capacity>
bool push_discontinuous(Context& ctx, SetpointStream<Axes, Capacity>& stream,
                        const Span<Axes>& span) {
    const unsigned axis = ctx.rng.below(Axes);
    Span<Axes> off = span;
    Lsb start[Axes], at[Axes];
    if (span_start(span, start) != Status::kOk) return false;
    ctx.summary.horner_evaluations += Axes;
    for (unsigned a = 0; a < Axes; ++a) at[a] = start[a];
    at[axis] = start[axis] + (start[axis] < 0 ? 1 : -1);
    if (!translate(off, start, at)) return false;
    const std::uint32_t queued = stream.queued_spans();
    const Status got = stream.push(off);
    ctx.hash.byte(static_cast<std::uint8_t>(got));
    if (got != Status::kDiscontinuousSpan || stream.queued_spans() != queued) {
        ++ctx.summary.mismatches;
    }
    ++ctx.summary.spans_rejected;
    return true;
}

/// One section: `attempts` pushes (valid and invalid) into a fresh stream of Axes axes and
/// Capacity slots, ticked until every accepted span has been consumed. The producer pushes at
/// pseudo-random moments, so the queue sometimes runs dry and the stream idles. The spans
/// form a continuous chain from the stream's start position; once, half-way, a span 1 LSB
/// off the chain is refused first. `longest_first`: the first span lasts kMaxSpanTicks ticks.
template <unsigned Axes, std::uint32_t Capacity>
void run_section(Context& ctx, Width width, std::uint32_t attempts, bool longest_first) {
    SplitMix64& rng = ctx.rng;
    Lsb hold[Axes];
    for (unsigned a = 0; a < Axes; ++a) hold[a] = rng.between(-5000, 5000);
    SetpointStream<Axes, Capacity> stream(hold);
    Lsb chain_end[Axes];  // producer side: where the next span must start
    for (unsigned a = 0; a < Axes; ++a) chain_end[a] = hold[a];
    bool discontinuity_checked = false;

    Expectation<Axes> mirror[Capacity];
    std::uint32_t head = 0, tail = 0;  // free-running indices into mirror
    std::uint32_t k = 0;               // tick inside the front span
    std::uint32_t made = 0;
    std::uint32_t last_tag = 0;
    std::uint64_t moving_ticks = 0;

    while (made < attempts || head != tail) {
        // Producer: when there is room, push now or later (never later when idle for long).
        if (made < attempts && head - tail < Capacity && rng.below(4) != 0) {
            Span<Axes> span;
            draw_span(ctx, width, longest_first && made == 0, made + 1, chain_end, span);
            if (!discontinuity_checked && made >= attempts / 2) {
                discontinuity_checked = push_discontinuous(ctx, stream, span);
            }
            const bool broken = maybe_break(rng, span);
            ++made;

            Expectation<Axes>& e = mirror[head % Capacity];
            Status expected = expect(ctx, span, e);
            if (expected == Status::kOk && !same_point(e.start, chain_end)) {
                expected = Status::kDiscontinuousSpan;
                ++ctx.summary.mismatches;  // draw_span put a valid span off the chain
            }
            const Status got = stream.push(span);
            ctx.hash.byte(static_cast<std::uint8_t>(got));
            if (got != expected || (broken && got == Status::kOk)) ++ctx.summary.mismatches;
            if (got == Status::kOk) {
                ++head;
                ++ctx.summary.spans_accepted;
                last_tag = span.tag;
                for (unsigned a = 0; a < Axes; ++a) chain_end[a] = e.end[a];
            } else {
                ++ctx.summary.spans_rejected;
            }
        }

        // Consumer: one tick.
        Lsb out[Axes];
        const TickState state = stream.tick(out);
        ++ctx.summary.ticks;
        ctx.hash.byte(static_cast<std::uint8_t>(state));
        for (unsigned a = 0; a < Axes; ++a) ctx.hash.lsb(out[a]);

        if (state == TickState::kMoving) {
            ++moving_ticks;
            if (head == tail) {
                ++ctx.summary.mismatches;  // moving without an accepted span
                break;
            }
            const Expectation<Axes>& e = mirror[tail % Capacity];
            for (int j = 0; j < 2; ++j) {
                if (k != e.sample[j]) continue;
                for (unsigned a = 0; a < Axes; ++a) {
                    if (out[a] != e.at_sample[j][a]) ++ctx.summary.mismatches;
                }
            }
            if (++k == e.ticks) {
                for (unsigned a = 0; a < Axes; ++a) hold[a] = e.end[a];
                ++tail;
                k = 0;
            }
        } else {
            if (head != tail) {
                ++ctx.summary.mismatches;  // idle although a span is queued
                break;
            }
            for (unsigned a = 0; a < Axes; ++a) {
                if (out[a] != hold[a]) ++ctx.summary.mismatches;
            }
        }
    }

    // Drained: one more tick must idle on the last end point; the counters must agree.
    Lsb out[Axes];
    if (stream.tick(out) != TickState::kIdle) ++ctx.summary.mismatches;
    for (unsigned a = 0; a < Axes; ++a) {
        if (out[a] != hold[a]) ++ctx.summary.mismatches;
        ctx.hash.lsb(out[a]);
    }
    if (stream.ticks_executed() != moving_ticks) ++ctx.summary.mismatches;
    if (stream.last_completed_tag() != last_tag) ++ctx.summary.mismatches;
    if (stream.queued_spans() != 0) ++ctx.summary.mismatches;
    if (!same_point(chain_end, hold)) ++ctx.summary.mismatches;
    if (!discontinuity_checked) ++ctx.summary.mismatches;  // the refusal was never exercised
    ctx.hash.u64(stream.ticks_executed());
    ctx.hash.u32(stream.spans_completed());
    ctx.hash.u32(stream.last_completed_tag());
}

}  // namespace pathstream::workload

#include "device_workload.hpp"

namespace pathstream::workload {

/// The whole workload: about 200k ticks over six sections, 1 to 8 axes, then the device
/// (state machine and Modbus register map) at 1, 2 and 4 axes.
inline Summary run() {
    Context ctx;
    run_section<1, 4>(ctx, Width::kNarrow, 48, false);
    run_section<2, 8>(ctx, Width::kMixed, 40, false);
    run_section<3, 16>(ctx, Width::kNarrow, 64, false);
    run_section<3, 16>(ctx, Width::kWide, 6, true);
    run_section<4, 8>(ctx, Width::kMixed, 40, false);
    run_section<8, 2>(ctx, Width::kMixed, 16, false);
    DeviceWorkload<1>(ctx).run();
    DeviceWorkload<2>(ctx).run();
    DeviceWorkload<4>(ctx).run();
    ctx.summary.checksum = ctx.hash.value();
    return ctx.summary;
}

}  // namespace pathstream::workload
