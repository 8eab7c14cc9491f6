// The span queue plus the per-tick consumer: spans in (task), one setpoint per axis per
// tick out (timer interrupt).
#pragma once

#include <cstdint>
#include <type_traits>

#include "pathstream/narrow_tick.hpp"
#include "pathstream/span.hpp"
#include "pathstream/span_queue.hpp"
#include "pathstream/status.hpp"
#include "pathstream/units.hpp"

namespace pathstream {

namespace detail {
// Ticks the span in progress has supplied: its countdown at the start less the one counted
// down, in either encoding (the other countdown is 0). A free function, so that an explicit
// instantiation of the stream (the size probe, docs/cortex-m.md) emits no copy of it.
template <unsigned Axes>
inline std::uint32_t ticks_supplied(const PreparedSpan<Axes>& span, const NarrowTick<Axes>& narrow,
                                    std::uint32_t wide_left) {
    return span.countdown - narrow.countdown - wide_left;
}
}  // namespace detail

/// What tick() produced.
enum class TickState : std::uint8_t {
    kMoving = 0,  ///< a span supplied this tick's setpoints
    kIdle = 1,    ///< no span queued: setpoints hold the last end point (or the start)
};

/// Spans of `Axes` axes queued `Capacity` deep, consumed one tick at a time by forward
/// differencing. Consecutive spans join without a gap or a repeated tick: a span of n ticks
/// supplies its ticks 0..n-1, and its end point (tick n) is the next span's tick 0.
/// Storage is inline (about Capacity * (16 + 40 * Axes) bytes); no allocation ever.
template <unsigned Axes, std::uint32_t Capacity>
class SetpointStream {
public:
    /// Starts idle, holding `start` (LSB per axis); the first span must begin there.
    /// Init context. The default constructor starts at 0 on every axis.
    explicit SetpointStream(const Lsb (&start)[Axes]) {
        for (unsigned a = 0; a < Axes; ++a) hold_[a] = pushed_end_[a] = start[a];
    }
    SetpointStream() = default;

    /// Producer (task): validates `span`, checks that it starts exactly where the previously
    /// pushed span ends (or at the start position, for the first), and prepares it straight
    /// into a free queue slot. Errors, in this order, each leaving queue and stream unchanged:
    /// the span's own validation error; kDiscontinuousSpan (a jump no axis could execute);
    /// kQueueFull (retry later: the span itself is fine). Cost: validation, one Horner end
    /// point per axis, preparation. Never call from the tick interrupt.
    [[nodiscard]] Status push(const Span<Axes>& span) { return push(span, SpanStamp<Axes>{}); }

    /// push() that also stores `stamp` in the queue entry before publishing it, so the consumer
    /// sees the stamp whenever it sees the span (next_span()). Same errors and cost. Producer.
    [[nodiscard]] Status push(const Span<Axes>& span, const SpanStamp<Axes>& stamp) {
        ValidatedSpan<Axes> v;
        if (Status s = validate_span(span, v); s != Status::kOk) return s;
        Lsb end[Axes];
        for (unsigned a = 0; a < Axes; ++a) {
            Lsb start = 0;
            if (evaluate_at(v.cubic[a], v.timing, 0, start) != Status::kOk ||
                evaluate_at(v.cubic[a], v.timing, v.timing.ticks, end[a]) != Status::kOk) {
                return Status::kTickOutsideSpan;  // unreachable: ticks 0 and n are in the span
            }
            if (start != pushed_end_[a]) return Status::kDiscontinuousSpan;
        }
        PreparedSpan<Axes>* slot = queue_.claim();
        if (slot == nullptr) return Status::kQueueFull;
        prepare_validated(v, *slot);
        slot->stamp = stamp;
        queue_.publish();
        for (unsigned a = 0; a < Axes; ++a) pushed_end_[a] = end[a];
        return Status::kOk;
    }

    /// Consumer (tick interrupt): writes this tick's setpoint for every axis to `out`.
    /// Every tick of a narrow span is played by narrow_tick_fast on the stream's own copy of
    /// the span's state (first in the object, so that no pointer is loaded): one test of the
    /// countdown, one forward-differencing step per axis, and finish_span() after the last.
    /// Everything else (starting a span, a wide span, an empty queue) is out of line, in
    /// tick_slow(). Always inlined, so that the interrupt handler holds the fast path itself.
    [[gnu::always_inline]] TickState tick(Lsb (&out)[Axes]) {
        static_assert(std::is_standard_layout_v<SetpointStream>, "narrow_ at offset 0");
        NarrowTick<Axes>* state = &narrow_;
        Lsb* o = out;
        for (;;) {
            const FastTick fast = narrow_tick_fast<kCompactTick>(state, o);
            if (fast == FastTick::kPlayed) [[likely]]
                return TickState::kMoving;
            // `this` and `out` as they came (narrow_tick_fast), taken from the registers it
            // left them in: copies kept for these paths would cost the fast one a move each.
            SetpointStream* const self = reinterpret_cast<SetpointStream*>(state);
            if (fast == FastTick::kLastPlayed) {
                self->finish_span();
                return TickState::kMoving;
            }
            const Slow slow = self->tick_slow(*reinterpret_cast<Lsb(*)[Axes]>(o));
            if (slow != Slow::kStarted) return static_cast<TickState>(slow);
            // A narrow span started: its first tick is narrow_tick_fast's.
            state = &self->narrow_;
            o = self->started_out_;
        }
    }

    /// Consumer, for code that wants many ticks at once (a host simulator, a batch fill; the
    /// tick interrupt calls tick()): writes out[0..count) exactly as `count` calls of tick()
    /// would, with the same counters, outputs() and state afterwards, and returns how many of
    /// those ticks were kIdle. A span's ticks come from emit_span_ticks, the state in
    /// registers rather than loaded and stored every tick. Cost: O(count * Axes) plus O(Axes)
    /// per span started or finished. Consumer context.
    std::uint32_t tick_many(Lsb (*out)[Axes], std::uint32_t count) {
        std::uint32_t idle = 0;
        for (std::uint32_t done = 0; done < count;) {
            if (active_ == nullptr) {
                // Starts the next span as tick_slow() does; the queue is looked at every idle
                // tick, as tick() would, so a span pushed meanwhile starts at the same tick.
                active_ = queue_.front();
                if (active_ == nullptr) {
                    for (unsigned a = 0; a < Axes; ++a) out[done][a] = hold_[a];
                    ++idle;
                    ++done;
                    continue;
                }
                start_span();
            }
            const std::uint32_t left =
                active_->ticks - detail::ticks_supplied(*active_, narrow_, wide_left_);
            const std::uint32_t k = left < count - done ? left : count - done;
            if (active_->wide) {
                emit_span_ticks(active_->wide_state, out + done, k, active_->bias);
                wide_left_ = left - k;
            } else {
                emit_span_ticks(narrow_.axis, out + done, k, narrow_.bias);
                narrow_.countdown -= k;  // either encoding; finish_span() clears it at 0
            }
            done += k;
            if (left == k) finish_span();
        }
        return idle;
    }

    /// Spans queued, the active one included. Either context.
    std::uint32_t queued_spans() const { return queue_.size(); }
    /// Free queue slots as seen by the producer.
    std::uint32_t free_slots() const { return queue_.free_slots(); }
    static constexpr std::uint32_t capacity() { return Capacity; }
    /// Ticks supplied by spans since construction (idle ticks excluded). Consumer context.
    std::uint64_t ticks_executed() const { return completed_ticks_ + ticks_into_span(); }
    /// Tag of the last span whose every tick was supplied; 0 before the first. Consumer.
    std::uint32_t last_completed_tag() const { return last_completed_tag_; }
    /// Discrete outputs (Span::outputs) in force: those of the span that supplied the last
    /// tick, kept while idle. Consumer context; read it right after tick().
    std::uint8_t outputs() const { return outputs_; }
    /// Spans completed since construction. Consumer context.
    std::uint32_t spans_completed() const { return spans_completed_; }
    /// True when no span is in progress: the next tick() starts the next queued span (or
    /// holds). A device decides stops here, where the last span's end velocity is known.
    /// Consumer context.
    bool between_spans() const { return active_ == nullptr; }
    /// The span in progress (its stamp included), or nullptr between spans. Consumer context.
    const PreparedSpan<Axes>* span_in_progress() const { return active_; }
    /// Ticks the span in progress has supplied (1 .. its ticks - 1; 0 between spans): the
    /// next tick() supplies its tick k = ticks_into_span(). Consumer context.
    std::uint32_t ticks_into_span() const {
        return active_ != nullptr ? detail::ticks_supplied(*active_, narrow_, wide_left_) : 0u;
    }
    /// The setpoint the next tick() supplies for `axis` from the span in progress (the exact
    /// curve at its tick k, rounded once), without supplying it. Precondition: a span is in
    /// progress. O(1). Consumer context.
    Lsb next_setpoint(unsigned axis) const {
        return active_->wide ? active_->wide_state[axis].position() : narrow_.axis[axis].position();
    }
    /// Where the axes rest between spans (the last span's end point, or the start). Consumer.
    Lsb resting_position(unsigned axis) const { return hold_[axis]; }
    /// End point of the last pushed span (or the start): where the next push must begin.
    /// Producer context.
    Lsb pushed_end(unsigned axis) const { return pushed_end_[axis]; }

    /// Consumer: drops the span in progress and every queued span, and holds `position`
    /// from the next tick on. The producer must then call restart_producer_at() with the
    /// same position before its next push (devices hand it over with an epoch counter).
    /// O(queued spans). Consumer context.
    void discard_all(const Lsb (&position)[Axes]) {
        if (active_ != nullptr) {
            completed_ticks_ += ticks_into_span();  // the ticks it did supply
            narrow_.countdown = wide_left_ = 0;
            active_ = nullptr;
            queue_.release();
        }
        while (queue_.front() != nullptr) queue_.release();
        for (unsigned a = 0; a < Axes; ++a) hold_[a] = position[a];
    }
    /// Consumer, between spans: the span the next tick() starts (its stamp included), or
    /// nullptr when none is queued. A span seen here stays the next one until the consumer
    /// ticks or drops it. O(1). Consumer context.
    const PreparedSpan<Axes>* next_span() { return between_spans() ? queue_.front() : nullptr; }
    /// Consumer, between spans: releases the span next_span() returned without playing it (no
    /// ticks counted, the rest point unchanged). Precondition: next_span() != nullptr. O(1).
    void drop_next() { queue_.release(); }
    /// Producer: the next pushed span must start at `position`. O(Axes). Producer context.
    void restart_producer_at(const Lsb (&position)[Axes]) {
        for (unsigned a = 0; a < Axes; ++a) pushed_end_[a] = position[a];
    }

private:
    // tick() repeats its per-axis code up to 4 axes and loops beyond, which costs 2
    // instructions per axis and keeps the core within 8 KiB at 8 axes (docs/cortex-m.md).
    static constexpr bool kCompactTick = Axes > 4;

    // What tick_slow() did: TickState's values, or kStarted (a narrow span, not yet played).
    enum class Slow : std::uint8_t {
        kMoving = static_cast<std::uint8_t>(TickState::kMoving),
        kIdle = static_cast<std::uint8_t>(TickState::kIdle),
        kStarted,
    };

    // Everything tick() does not: taking the next span from the queue, every tick of a wide
    // span (D >= 2^32: long spans) and holding when the queue is empty.
    [[gnu::noinline]] Slow tick_slow(Lsb (&out)[Axes]) {
        if (active_ == nullptr) {
            active_ = queue_.front();
            if (active_ == nullptr) {
                for (unsigned a = 0; a < Axes; ++a) out[a] = hold_[a];
                return Slow::kIdle;
            }
            if (start_span()) {
                started_out_ = out;
                return Slow::kStarted;
            }
        }
        emit_and_step(active_->wide_state, out, active_->bias);
        if (--wide_left_ == 0) finish_span();
        return Slow::kMoving;
    }

    // Makes the queue's front span (active_) the one in progress: a narrow one's K, countdown
    // and states are copied to narrow_, where the tick steps them; a wide one's countdown to
    // wide_left_. True when it is narrow. Out of line: tick_slow() and tick_many() share it.
    [[gnu::noinline]] bool start_span() {
        outputs_ = active_->outputs;
        if (active_->wide) {
            wide_left_ = active_->countdown;
            return false;
        }
        narrow_.bias = active_->narrow_bias;
        narrow_.countdown = active_->countdown;
        for (unsigned a = 0; a < Axes; ++a) narrow_.axis[a] = active_->narrow[a];
        return true;
    }

    [[gnu::noinline]] void finish_span() {
        // The state has stepped once past the last tick: it now holds the end point.
        for (unsigned a = 0; a < Axes; ++a) {
            hold_[a] =
                active_->wide ? active_->wide_state[a].position() : narrow_.axis[a].position();
        }
        narrow_.countdown = 0;
        last_completed_tag_ = active_->tag;
        completed_ticks_ += active_->ticks;
        ++spans_completed_;
        active_ = nullptr;
        queue_.release();
    }

    // First: tick() addresses it as `this` (narrow_tick_fast). Consumer side only.
    NarrowTick<Axes> narrow_;  // the narrow span in progress (countdown 0: none)
    // The small fields before the queue, so that Thumb code reaches each with one offset load.
    std::uint32_t wide_left_ = 0;           // ticks the wide span in progress has to supply
    Lsb* started_out_ = nullptr;            // tick_slow()'s `out` when it started a narrow span
    PreparedSpan<Axes>* active_ = nullptr;  // span being played, narrow or wide
    std::uint64_t completed_ticks_ = 0;
    std::uint32_t last_completed_tag_ = 0;
    std::uint32_t spans_completed_ = 0;
    std::uint8_t outputs_ = 0;
    Lsb hold_[Axes] = {};        // consumer side: where the axes rest when idle
    Lsb pushed_end_[Axes] = {};  // producer side: end point of the last pushed span
    SpanQueue<PreparedSpan<Axes>, Capacity> queue_;
};

}  // namespace pathstream
