// The device: a SetpointStream behind a state machine that accepts sequenced batches of wire
// spans, checks them against the axis limits, and owns the one motion-stop path (hold, stop,
// underrun, fault, e-stop). Every bus protocol (Modbus, CAN) and the GPIO logic drive this.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>

#include "pathstream/device/motion_limits.hpp"
#include "pathstream/device/stop_spans.hpp"
#include "pathstream/device/wire_span.hpp"
#include "pathstream/setpoint_stream.hpp"
#include "pathstream/status.hpp"

namespace pathstream::device {

/// Device state; values are the Modbus status register's (docs/modbus.md).
enum class DeviceState : std::uint8_t {
    kIdle = 0,      ///< not moving; spans may be queued; start begins execution
    kRunning = 1,   ///< executing spans (at rest when the queue is dry at a stop point)
    kHolding = 2,   ///< decelerating to, or resting at, a hold (command or underrun)
    kStopping = 3,  ///< decelerating; then the queue is dropped and the state becomes idle
    kFault = 4,     ///< stopped at once by a fault; reset_fault leaves it
    kEstop = 5,     ///< stopped at once by the e-stop; reset (input released) leaves it
};

/// Commands, as written to the command register.
enum class Command : std::uint16_t {
    kStart = 1,
    kHold = 2,
    kResume = 3,
    kStop = 4,
    kReset = 5,  ///< leaves fault or e-stop for idle
};

/// Fault codes (the status block's fault register). 0x01xx: axis limit switch, low byte =
/// axis * 2 + side (0 negative, 1 positive); reported by the GPIO layer.
enum class FaultCode : std::uint16_t {
    kNone = 0,
    kExternal = 1,      ///< raised by the integration (e.g. a drive fault input)
    kStopFailed = 2,    ///< no controlled stop fits in one span: stopped at once
    kReentryFailed = 3, ///< resume: no move back onto the path fits in one span
    kLimitSwitchBase = 0x100,
};

/// Maximum spans in one batch (bounded so validation needs no storage per span).
inline constexpr std::uint16_t kMaxBatchSpans = 64;

/// A device of `Axes` axes with a span queue `Capacity` deep.
///
/// Contexts: tick() runs in the tick interrupt; every other member runs in one task (the bus
/// server). Commands and faults are requests that the next tick() applies, so motion reacts
/// within one tick and the interrupt never waits on the task. Storage inline, no allocation.
template <unsigned Axes, std::uint32_t Capacity>
class MotionDevice {
public:
    /// Idle at `start` (LSB per axis), unconfigured. Init context.
    explicit MotionDevice(const Lsb (&start)[Axes]) : stream_(start) {
        for (unsigned a = 0; a < Axes; ++a) position_[a] = rest_[a] = start[a];
    }

    // ---- task side --------------------------------------------------------------------

    /// Sets the tick rate and limits. Allowed only idle with nothing queued (queued spans were
    /// checked against the old limits): kWrongState otherwise; kBadLimits for zero or
    /// out-of-range values. Task context.
    [[nodiscard]] Status configure(const MotionLimits<Axes>& limits) {
        if (Status s = check_limits(limits); s != Status::kOk) return s;
        if (state() != DeviceState::kIdle || stream_.queued_spans() != 0) {
            return Status::kWrongState;
        }
        limits_ = limits;
        configured_ = true;
        return Status::kOk;
    }
    bool configured() const { return configured_; }
    const MotionLimits<Axes>& limits() const { return limits_; }

    /// Accepts a batch of `count` wire spans (payload[0..length)) whose first span has sequence
    /// number `first_sequence`. All or nothing: every span is decoded, validated by the core,
    /// checked against the limits and for continuity before any is queued; on an error nothing
    /// changes. A batch that was already accepted entirely (a retry after a lost reply) is
    /// acknowledged with kOk and not queued again (duplicates() counts it).
    /// Errors: kNotConfigured; kWrongState (fault, e-stop, stopping); kBadSequence (a gap or a
    /// partial overlap); kBadBatch (count 0 or > kMaxBatchSpans, length mismatch, bad flags);
    /// a span's own Status (its validation, kVelocityLimit, kAccelerationLimit); and only for
    /// a batch that is otherwise acceptable, kQueueFull (not enough free slots: retry later).
    /// Cost: two decodes and one validation per span (~5,000 instructions per axis on M4).
    /// Task context.
    [[nodiscard]] Status accept_batch(std::uint32_t first_sequence, std::uint16_t count,
                                      const std::uint8_t* payload, std::size_t length) {
        if (!configured_) return Status::kNotConfigured;
        const DeviceState s = state();
        if (s == DeviceState::kFault || s == DeviceState::kEstop || s == DeviceState::kStopping) {
            return Status::kWrongState;
        }
        if (count == 0 || count > kMaxBatchSpans) return Status::kBadBatch;
        sync_producer();
        const std::uint32_t last = first_sequence + count - 1u;
        if (first_sequence == next_sequence_ - count && last == next_sequence_ - 1u &&
            count <= accepted_spans_) {
            ++duplicates_;
            return Status::kOk;
        }
        if (first_sequence != next_sequence_) return Status::kBadSequence;
        // Pass 1: decode and check everything, chaining start points and tangents.
        Lsb start[Axes];
        std::int32_t tangent[Axes];
        for (unsigned a = 0; a < Axes; ++a) {
            start[a] = stream_.pushed_end(a);
            tangent[a] = last_tangent_[a];
        }
        if (Status st = walk_batch(payload, length, count, start, tangent, nullptr); st != Status::kOk) {
            return st;
        }
        // Room is checked after validity, as SetpointStream::push does: a master retrying on
        // kQueueFull never retries a batch that can never go in.
        if (stream_.free_slots() < count) return Status::kQueueFull;
        // Pass 2: the same walk, pushing. Cannot fail: pass 1 proved every span and the room.
        for (unsigned a = 0; a < Axes; ++a) {
            start[a] = stream_.pushed_end(a);
            tangent[a] = last_tangent_[a];
        }
        if (Status st = walk_batch(payload, length, count, start, tangent, &stream_); st != Status::kOk) {
            return st;  // unreachable
        }
        for (unsigned a = 0; a < Axes; ++a) last_tangent_[a] = tangent[a];
        next_sequence_ += count;
        accepted_spans_ += count;
        return Status::kOk;
    }

    /// Requests a command; the next tick applies it (a second request before that tick
    /// replaces the first). Errors (nothing requested): kWrongState
    /// when the state does not allow it (start: idle only and configured; hold: running;
    /// resume: holding; stop: running, holding or idle; reset: fault, or e-stop with the input
    /// released), kNotConfigured, kNothingToResume (a hold after an underrun with nothing
    /// queued). Repeating a command already in effect is kOk. Task context.
    [[nodiscard]] Status command(Command c) {
        const DeviceState s = state();
        switch (c) {
            case Command::kStart:
                if (!configured_) return Status::kNotConfigured;
                if (s == DeviceState::kRunning) return Status::kOk;
                if (s != DeviceState::kIdle) return Status::kWrongState;
                break;
            case Command::kHold:
                if (s == DeviceState::kHolding) return Status::kOk;
                if (s != DeviceState::kRunning) return Status::kWrongState;
                break;
            case Command::kResume:
                if (s == DeviceState::kRunning) return Status::kOk;
                if (s != DeviceState::kHolding) return Status::kWrongState;
                if (held_by_underrun_ && stream_.queued_spans() == 0) return Status::kNothingToResume;
                break;
            case Command::kStop:
                if (s == DeviceState::kIdle || s == DeviceState::kStopping) return Status::kOk;
                if (s != DeviceState::kRunning && s != DeviceState::kHolding) return Status::kWrongState;
                break;
            case Command::kReset:
                if (s == DeviceState::kIdle) return Status::kOk;
                if (s != DeviceState::kFault && s != DeviceState::kEstop) return Status::kWrongState;
                if (s == DeviceState::kEstop && estop_input_.load(std::memory_order_relaxed)) {
                    return Status::kWrongState;
                }
                break;
        }
        // Value first, then the sequence that publishes it; the tick compares sequences, so no
        // read-modify-write is needed (ARMv6-M has none) and a request is never lost.
        request_value_.store(static_cast<std::uint16_t>(c), std::memory_order_relaxed);
        request_sequence_.store(request_sequence_.load(std::memory_order_relaxed) + 1, std::memory_order_release);
        return Status::kOk;
    }

    /// Any context (a GPIO edge interrupt too): raises a fault; the next tick freezes every
    /// axis where it is, drops the queue and enters kFault. The first fault's code is kept.
    void raise_fault(FaultCode code) {
        // Loads and stores only (ARMv6-M has no atomic read-modify-write): two raisers racing
        // in the same instant may keep either code, never none.
        if (fault_request_.load(std::memory_order_acquire) == 0) {
            fault_request_.store(static_cast<std::uint16_t>(code), std::memory_order_release);
        }
    }
    /// Redefines where the axes are (homing's "set zero"): the next tick makes `position` the
    /// rest point and the last setpoint, without moving, and hands it to the producer side (the
    /// next batch starts there; sequence numbers continue). Idle only, with nothing queued and
    /// no earlier set_position still pending (position_pending()): kWrongState otherwise.
    /// Task context.
    [[nodiscard]] Status set_position(const Lsb (&position)[Axes]) {
        sync_producer();
        if (state() != DeviceState::kIdle || stream_.queued_spans() != 0 || position_pending()) {
            return Status::kWrongState;
        }
        // The array is written before the sequence store (release) that publishes it; the tick
        // reads it only after seeing the new sequence (acquire), and no second request can
        // overwrite it before the tick has copied it (position_pending()).
        for (unsigned a = 0; a < Axes; ++a) requested_position_[a] = position[a];
        position_request_.store(position_request_.load(std::memory_order_relaxed) + 1, std::memory_order_release);
        return Status::kOk;
    }
    /// True from set_position() until the tick that applies it. Task context.
    bool position_pending() const {
        return position_request_.load(std::memory_order_relaxed) != position_applied_.load(std::memory_order_acquire);
    }

    /// Any context: the e-stop input's level. Active: the next tick freezes every axis, drops
    /// the queue and enters kEstop; kReset is refused until the input is released.
    void set_estop_input(bool active) { estop_input_.store(active, std::memory_order_release); }

    // ---- status (task side reads; values written by tick) ------------------------------
    DeviceState state() const { return static_cast<DeviceState>(state_.load(std::memory_order_acquire)); }
    FaultCode fault_code() const { return fault_code_; }
    std::uint32_t free_slots() const { return stream_.free_slots(); }
    static constexpr std::uint32_t capacity() { return Capacity; }
    /// Sequence number of the last span accepted (0 before the first). Task context.
    std::uint32_t last_accepted_sequence() const { return next_sequence_ - 1u; }
    /// Sequence number (= tag) of the last span executed to its end.
    std::uint32_t last_completed_sequence() const { return stream_.last_completed_tag(); }
    /// Path ticks executed (ticks supplied by accepted spans; stop and re-entry moves excluded).
    std::uint64_t ticks_executed() const { return stream_.ticks_executed(); }
    /// Ticks of stop and re-entry moves the device generated itself.
    std::uint64_t generated_ticks() const { return generated_ticks_; }
    /// Setpoint output by the last tick, per axis.
    Lsb position(unsigned axis) const { return position_[axis]; }
    std::uint8_t outputs() const { return outputs_; }
    std::uint32_t underruns() const { return underruns_; }
    std::uint32_t duplicates() const { return duplicates_; }
    std::uint32_t queued_spans() const { return stream_.queued_spans(); }
    /// True while holding because the queue ran dry (not because of a hold command).
    bool held_by_underrun() const { return held_by_underrun_; }

    // ---- tick interrupt ----------------------------------------------------------------

    /// One tick: applies a pending request, then writes every axis's setpoint to `out`.
    /// Steady state costs SetpointStream::tick plus a few loads; a controlled stop or
    /// re-entry is planned in this call at a span boundary (a one-off of a few thousand
    /// instructions per axis). Tick interrupt context.
    void tick(Lsb (&out)[Axes]) {
        apply_requests();
        const DeviceState s = state();
        if (s == DeviceState::kRunning && motion_ == Motion::kStream && stream_.between_spans()) {
            decide_at_boundary();
        }
        switch (motion_) {
            case Motion::kStream:
                stream_.tick(out);
                outputs_ = stream_.outputs();
                break;
            case Motion::kGenerated:
                generated_.tick(out);
                ++generated_ticks_;
                if (generated_.between_spans() && generated_.queued_spans() == 0) finish_generated();
                break;
            case Motion::kRest:
            default:
                for (unsigned a = 0; a < Axes; ++a) out[a] = rest_[a];
                break;
        }
        for (unsigned a = 0; a < Axes; ++a) position_[a] = out[a];
    }

private:
    enum class Motion : std::uint8_t { kRest, kStream, kGenerated };
    enum class Generated : std::uint8_t { kNone, kHoldStop, kStopStop, kReentry };

    // Decodes `count` spans, validating each (and pushing it when `target` is set). `start`
    // and `tangent` carry the chain from span to span.
    Status walk_batch(const std::uint8_t* payload, std::size_t length, std::uint16_t count, Lsb (&start)[Axes],
                      std::int32_t (&tangent)[Axes], SetpointStream<Axes, Capacity>* target) {
        std::size_t offset = 0;
        for (std::uint16_t i = 0; i < count; ++i) {
            WireSpan w;
            std::size_t used = 0;
            if (Status st = decode_wire_span(payload + offset, length - offset, Axes, w, used); st != Status::kOk) {
                return st;
            }
            offset += used;
            if ((w.flags & kWireContinueTangent) != 0) {
                for (unsigned a = 0; a < Axes; ++a) w.start_tangent[a] = tangent[a];
            }
            const std::uint32_t sequence = next_sequence_ + i;
            const Span<Axes> span = to_core_span<Axes>(w, start, sequence);
            if (target == nullptr) {
                ValidatedSpan<Axes> v;
                if (Status st = validate_span(span, v); st != Status::kOk) return st;
                for (unsigned a = 0; a < Axes; ++a) {
                    if (Status st = check_axis_limits(v.cubic[a], v.timing, limits_.axis[a], limits_.tick_hz);
                        st != Status::kOk) {
                        return st;
                    }
                }
            } else {
                if (Status st = target->push(span); st != Status::kOk) return st;
                EndVelocity& e = ends_[sequence % kEndRing];
                e.ticks = w.ticks;
                for (unsigned a = 0; a < Axes; ++a) e.tangent[a] = w.end_tangent[a];
            }
            for (unsigned a = 0; a < Axes; ++a) {
                start[a] = w.end[a];
                tangent[a] = w.end_tangent[a];
            }
        }
        return offset == length ? Status::kOk : Status::kBadBatch;
    }

    // After the consumer dropped the queue, the producer restarts its chain at the rest point.
    void sync_producer() {
        const std::uint32_t epoch = drop_epoch_.load(std::memory_order_acquire);
        if (epoch == producer_epoch_) return;
        producer_epoch_ = epoch;
        stream_.restart_producer_at(dropped_at_);
        for (unsigned a = 0; a < Axes; ++a) last_tangent_[a] = 0;
    }

    void set_state(DeviceState s) { state_.store(static_cast<std::uint8_t>(s), std::memory_order_release); }

    void rest_here() {
        for (unsigned a = 0; a < Axes; ++a) rest_[a] = position_[a];
        motion_ = Motion::kRest;
    }

    // Consumer: drops everything queued and hands the rest point to the producer.
    void drop_queue() {
        for (unsigned a = 0; a < Axes; ++a) dropped_at_[a] = rest_[a];
        stream_.discard_all(rest_);
        drop_epoch_.store(drop_epoch_.load(std::memory_order_relaxed) + 1, std::memory_order_release);
        held_by_underrun_ = false;
    }

    void apply_requests() {
        const std::uint16_t fault = fault_request_.load(std::memory_order_acquire);
        const bool estop = estop_input_.load(std::memory_order_acquire);
        const DeviceState s = state();
        if (estop && s != DeviceState::kEstop) {
            stop_at_once();
            set_state(DeviceState::kEstop);
            return;
        }
        if (fault != 0 && s != DeviceState::kFault && s != DeviceState::kEstop) {
            fault_code_ = static_cast<FaultCode>(fault);
            stop_at_once();
            set_state(DeviceState::kFault);
            return;
        }
        apply_position_request(s);
        const std::uint32_t sequence = request_sequence_.load(std::memory_order_acquire);
        if (sequence == applied_sequence_) return;
        applied_sequence_ = sequence;
        const std::uint16_t r = request_value_.load(std::memory_order_relaxed);
        switch (static_cast<Command>(r)) {
            case Command::kStart:
                if (s == DeviceState::kIdle) {
                    motion_ = Motion::kStream;
                    set_state(DeviceState::kRunning);
                }
                break;
            case Command::kHold:
                if (s == DeviceState::kRunning) hold_requested_ = true;
                break;
            case Command::kResume:
                if (s == DeviceState::kHolding) {
                    if (motion_ == Motion::kRest) {
                        begin_reentry();
                    } else {
                        resume_pending_ = true;  // still decelerating: resume once at rest
                    }
                }
                break;
            case Command::kStop:
                if (s == DeviceState::kRunning) {
                    stop_requested_ = true;
                } else if (s == DeviceState::kHolding) {
                    if (motion_ == Motion::kRest) {
                        drop_queue();
                        set_state(DeviceState::kIdle);
                    } else {
                        stop_requested_ = true;  // finish_generated completes it
                    }
                } else if (s == DeviceState::kIdle) {
                    drop_queue();
                }
                break;
            case Command::kReset:
                if ((s == DeviceState::kFault || s == DeviceState::kEstop) && !estop) {
                    fault_request_.store(0, std::memory_order_release);
                    fault_code_ = FaultCode::kNone;
                    set_state(DeviceState::kIdle);
                }
                break;
        }
    }

    // set_position: taken only while idle at rest (a start in the same tick comes after it);
    // in any other state it is dropped (the task sees position_pending() clear either way).
    void apply_position_request(DeviceState s) {
        const std::uint32_t request = position_request_.load(std::memory_order_acquire);
        if (request == position_applied_.load(std::memory_order_relaxed)) return;
        if (s == DeviceState::kIdle && motion_ == Motion::kRest) {
            for (unsigned a = 0; a < Axes; ++a) position_[a] = rest_[a] = requested_position_[a];
            drop_queue();
        }
        position_applied_.store(request, std::memory_order_release);
    }

    // E-stop and faults: the axes stay where this tick's setpoint would have been computed
    // from, i.e. at the last output; everything queued is dropped.
    void stop_at_once() {
        rest_here();
        generated_kind_ = Generated::kNone;
        hold_requested_ = stop_requested_ = resume_pending_ = false;
        drop_queue();
    }

    // Running, between two spans: continue, or begin a controlled stop (stop, hold, underrun).
    void decide_at_boundary() {
        const bool dry = stream_.queued_spans() == 0;
        const std::uint32_t tag = stream_.last_completed_tag();
        const EndVelocity* end = tag != 0 ? &ends_[tag % kEndRing] : nullptr;
        bool moving = false;
        if (end != nullptr) {
            for (unsigned a = 0; a < Axes; ++a) moving = moving || end->tangent[a] != 0;
        }
        const bool underrun = dry && moving && !stop_requested_ && !hold_requested_;
        if (!stop_requested_ && !hold_requested_ && !underrun) return;
        for (unsigned a = 0; a < Axes; ++a) {
            boundary_[a] = stream_.resting_position(a);
            rest_[a] = boundary_[a];
            boundary_tangent_[a] = moving ? end->tangent[a] : 0;
        }
        boundary_ticks_ = moving ? end->ticks : 1;
        const bool stopping = stop_requested_;
        held_by_underrun_ = underrun;
        if (underrun) ++underruns_;
        hold_requested_ = stop_requested_ = false;
        if (!moving) {
            motion_ = Motion::kRest;
            if (stopping) {
                drop_queue();
                set_state(DeviceState::kIdle);
            } else {
                set_state(DeviceState::kHolding);
            }
            return;
        }
        Span<Axes> stop;
        if (plan_stop(boundary_, boundary_tangent_, boundary_ticks_, limits_, stop) != Status::kOk ||
            !start_generated(stop)) {
            fault_code_ = FaultCode::kStopFailed;
            stop_at_once();
            set_state(DeviceState::kFault);
            return;
        }
        generated_kind_ = stopping ? Generated::kStopStop : Generated::kHoldStop;
        set_state(stopping ? DeviceState::kStopping : DeviceState::kHolding);
    }

    void begin_reentry() {
        bool at_boundary = true;
        bool moving = false;
        for (unsigned a = 0; a < Axes; ++a) {
            at_boundary = at_boundary && rest_[a] == boundary_[a];
            moving = moving || boundary_tangent_[a] != 0;
        }
        held_by_underrun_ = false;
        if (at_boundary && !moving) {
            motion_ = Motion::kStream;
            set_state(DeviceState::kRunning);
            return;
        }
        Span<Axes> reentry;
        if (plan_reentry(rest_, boundary_, boundary_tangent_, boundary_ticks_, limits_, reentry) != Status::kOk ||
            !start_generated(reentry)) {
            // No move back onto the path fits in one span: a fault the master sees (rather
            // than a hold that silently never resumes); reset, then restart the job.
            fault_code_ = FaultCode::kReentryFailed;
            stop_at_once();
            set_state(DeviceState::kFault);
            return;
        }
        generated_kind_ = Generated::kReentry;
        set_state(DeviceState::kRunning);
    }

    bool start_generated(const Span<Axes>& span) {
        Lsb from[Axes];
        for (unsigned a = 0; a < Axes; ++a) from[a] = span.control[a][0];
        generated_.discard_all(from);
        generated_.restart_producer_at(from);
        if (generated_.push(span) != Status::kOk) return false;
        motion_ = Motion::kGenerated;
        return true;
    }

    void finish_generated() {
        const Generated kind = generated_kind_;
        generated_kind_ = Generated::kNone;
        for (unsigned a = 0; a < Axes; ++a) rest_[a] = generated_.resting_position(a);
        motion_ = Motion::kRest;
        if (kind == Generated::kReentry) {
            // The stream resumes at the boundary it left; a stop or hold requested meanwhile
            // is taken at the next boundary.
            motion_ = Motion::kStream;
            return;
        }
        if (kind == Generated::kStopStop || stop_requested_) {
            stop_requested_ = resume_pending_ = false;
            drop_queue();
            set_state(DeviceState::kIdle);
            return;
        }
        if (resume_pending_) {
            resume_pending_ = false;
            begin_reentry();
        }
    }

    struct EndVelocity {
        std::uint32_t ticks = 1;
        std::int32_t tangent[Axes] = {};
    };
    static constexpr std::uint32_t kEndRing = 2 * Capacity;  // a completed span's entry outlives Capacity pushes

    SetpointStream<Axes, Capacity> stream_;
    SetpointStream<Axes, 2> generated_;  // the device's own stop and re-entry spans
    MotionLimits<Axes> limits_;
    bool configured_ = false;

    // producer (task) side
    std::uint32_t next_sequence_ = 1;
    std::uint32_t accepted_spans_ = 0;
    std::uint32_t duplicates_ = 0;
    std::uint32_t producer_epoch_ = 0;
    std::int32_t last_tangent_[Axes] = {};
    EndVelocity ends_[kEndRing];

    // requests (any context -> tick)
    std::atomic<std::uint16_t> request_value_{0};
    std::atomic<std::uint32_t> request_sequence_{0};  // written by the task only
    std::atomic<std::uint16_t> fault_request_{0};
    std::atomic<bool> estop_input_{false};
    std::atomic<std::uint32_t> position_request_{0};  // written by the task only
    std::atomic<std::uint32_t> position_applied_{0};  // written by the tick only
    Lsb requested_position_[Axes] = {};

    // consumer (tick) side
    std::atomic<std::uint8_t> state_{static_cast<std::uint8_t>(DeviceState::kIdle)};
    std::atomic<std::uint32_t> drop_epoch_{0};
    std::uint32_t applied_sequence_ = 0;
    Motion motion_ = Motion::kRest;
    Generated generated_kind_ = Generated::kNone;
    FaultCode fault_code_ = FaultCode::kNone;
    bool hold_requested_ = false;
    bool stop_requested_ = false;
    bool resume_pending_ = false;
    bool held_by_underrun_ = false;
    std::uint8_t outputs_ = 0;
    std::uint32_t underruns_ = 0;
    std::uint64_t generated_ticks_ = 0;
    Lsb position_[Axes] = {};
    Lsb rest_[Axes] = {};
    Lsb dropped_at_[Axes] = {};
    Lsb boundary_[Axes] = {};
    std::int32_t boundary_tangent_[Axes] = {};
    std::uint32_t boundary_ticks_ = 1;
};

}  // namespace pathstream::device
