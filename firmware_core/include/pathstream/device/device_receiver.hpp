// The device's task side: batches in (decode, core validation, exact limit check, continuity
// at every join, sequence numbers, job ends), commands and configuration out to the tick
// through the mailbox, status in from the tick through the status board. Runs in one task
// (the bus server); never in the tick interrupt. Shares nothing with the tick side but the
// DeviceChannel.
#pragma once

#include <cstddef>
#include <cstdint>

#include "pathstream/device/batch_crc.hpp"
#include "pathstream/device/device_channel.hpp"
#include "pathstream/device/device_state.hpp"
#include "pathstream/device/motion_limits.hpp"
#include "pathstream/device/wire_span.hpp"
#include "pathstream/span.hpp"
#include "pathstream/status.hpp"

namespace pathstream::device {

/// The default interleaving hook of DeviceReceiver::accept_batch: nothing.
struct NoInterleave {
    void operator()() const {}
};

/// Task side of a device of `Axes` axes with a span queue `Capacity` deep. Every member runs
/// in one task context (the bus server) unless it says otherwise. Storage inline.
template <unsigned Axes, std::uint32_t Capacity>
class DeviceReceiver {
public:
    /// Init context. `channel` must outlive the receiver.
    explicit DeviceReceiver(DeviceChannel<Axes, Capacity>& channel) : channel_(channel) {
        const DeviceStatus<Axes> s = channel.board.read();
        producer_epoch_ = s.epoch;
        for (unsigned a = 0; a < Axes; ++a) chain_.start[a] = s.origin[a];
    }

    /// Sets the tick rate, limits and pen-down delay. Allowed only idle with nothing queued
    /// (queued spans were checked against the old limits): kWrongState otherwise; kBadLimits
    /// for zero or out-of-range values. The tick reads the limits only after a later start.
    [[nodiscard]] Status configure(const MotionLimits<Axes>& limits) {
        if (Status s = check_limits(limits); s != Status::kOk) return s;
        if (status().device_state() != DeviceState::kIdle || channel_.queue.queued_spans() != 0) {
            return Status::kWrongState;
        }
        channel_.mailbox.limits = limits;
        limits_ = limits;
        configured_ = true;
        return Status::kOk;
    }
    bool configured() const { return configured_; }
    const MotionLimits<Axes>& limits() const { return limits_; }

    /// Whether accept_batch refuses spans that could leave an axis's travel (on by default).
    /// Homing turns it off while it searches for a switch the soft limits know nothing of
    /// (the coordinates are not yet defined); it turns it on again when it ends.
    void enforce_travel(bool on) { enforce_travel_ = on; }
    bool travel_enforced() const { return enforce_travel_; }

    /// Accepts a batch of `count` wire spans (payload[0..length)) whose first span has sequence
    /// number `first_sequence`. All or nothing: every span is decoded, validated by the core,
    /// checked against the limits, for continuity of position and velocity at every join
    /// (the first span of a job, and the first after a queue drop, start from rest) and for a
    /// job end at rest, before any is queued; on an error nothing changes. Each queued span is
    /// stamped with the current epoch, its job (the sequence number of the job's first span)
    /// and its end tangent. A resend of the last accepted batch (a retry after a lost reply:
    /// the same first sequence, count, length and CRC-32 of the payload) is acknowledged with
    /// kOk and not queued again (duplicates() counts it); other bytes under those numbers are
    /// a master out of step: kBadSequence, whatever the transport.
    /// Errors: kNotConfigured; kWrongState (fault, e-stop, stopping, or a queue drop by the
    /// tick while the batch was being queued: its spans are then never executed);
    /// kBadSequence (a gap, a partial overlap, an older batch, or the last batch's numbers
    /// with other bytes); kBadBatch (count 0 or > kMaxBatchSpans,
    /// length mismatch, bad flags, an output bit outside kOutputKnownMask); a span's own Status
    /// (its validation, kVelocityLimit, kAccelerationLimit, kOutsideTravel, kVelocityStep,
    /// kJobEndMoving, kPauseMoving, and under a jerk limit kJerkLimit and kAccelerationStep: the
    /// acceleration at every join, a job's first span, after a pause and at a job end or pause too,
    /// where the other side is rest); and only for a batch that is otherwise acceptable, kQueueFull
    /// (not enough free slots: retry later). `between` is called before each span is queued: a test
    /// hook that runs the tick there (the interrupt could); the default does nothing. Cost: two
    /// decodes and one validation per span, the push's own validation (~5,000 instructions per axis
    /// on M4), and one CRC-32 of the payload (~8 steps per byte) for an accepted batch or a resend.
    template <typename Between = NoInterleave>
    [[nodiscard]] Status accept_batch(std::uint32_t first_sequence, std::uint16_t count,
                                      const std::uint8_t* payload, std::size_t length,
                                      Between&& between = Between{}) {
        if (!configured_) return Status::kNotConfigured;
        const DeviceStatus<Axes> s = status();
        const DeviceState state = s.device_state();
        if (state == DeviceState::kFault || state == DeviceState::kEstop ||
            state == DeviceState::kStopping) {
            return Status::kWrongState;
        }
        if (count == 0 || count > kMaxBatchSpans) return Status::kBadBatch;
        sync_epoch(s);
        if (last_batch_.count != 0 && first_sequence == last_batch_.first &&
            count == last_batch_.count && first_sequence + count == next_sequence_) {
            // The core compares the bytes itself: every transport gets the same answer.
            if (length != last_batch_.length || batch_crc32(payload, length) != last_batch_.crc)
                return Status::kBadSequence;
            ++duplicates_;
            return Status::kOk;
        }
        if (first_sequence != next_sequence_) return Status::kBadSequence;
        Chain chain = chain_;
        if (Status st = walk_batch(payload, length, count, chain, false, between);
            st != Status::kOk)
            return st;
        // Room is checked after validity, as SetpointStream::push does: a master retrying on
        // kQueueFull never retries a batch that can never go in.
        if (channel_.queue.free_slots() < count) return Status::kQueueFull;
        chain = chain_;
        // Cannot fail: the first walk proved every span, the room only grows.
        if (Status st = walk_batch(payload, length, count, chain, true, between); st != Status::kOk)
            return st;
        // The tick may have dropped the queue while the spans went in: those pushed after the
        // drop carry the old epoch and will be discarded unplayed, so the batch is refused
        // (the next batch starts at the rest point the drop published).
        if (status().epoch != producer_epoch_) return Status::kWrongState;
        chain_ = chain;
        next_sequence_ += count;
        last_batch_ = {first_sequence, count, length, batch_crc32(payload, length)};
        return Status::kOk;
    }

    /// Requests a command; the next tick applies it (a second request before that tick
    /// replaces the first, except a stop, which stays: later requests but reset are then
    /// kWrongState, a second stop kOk). Every value is checked here: kUnknownCommand for a
    /// value that is no Command; kWrongState when the state does not allow it (start: idle;
    /// hold: running; resume: holding; stop: running, holding, idle (drops what is queued);
    /// reset: fault, or e-stop with the input released); kNotConfigured (start before
    /// configure); kNothingToResume (start with nothing queued, or resume after an underrun
    /// with nothing queued: nothing would move). Repeating a command already in effect is kOk
    /// and posts nothing, when no request is pending; with one pending (the state it was
    /// judged in is about to change), it is posted and replaces that one. Cost: one status
    /// read.
    [[nodiscard]] Status command(Command c) { return post_command(c, 0); }

    /// A start that keeps the operator's pen (set_pen) down: the device's own jog, whose
    /// spans carry that pen. Otherwise as command(Command::kStart).
    [[nodiscard]] Status start_keeping_pen() {
        return post_command(Command::kStart, kMailboxKeepPen);
    }

    /// The operator's pen: lowered (`down`) or raised at rest. Idle with nothing queued only
    /// (kWrongState otherwise). The tick keeps it until a plain start, a stop, a fault or the
    /// e-stop raises it; it shows in the outputs while idle. Posted like a command (a command
    /// before the next tick replaces it). Cost: one status read.
    [[nodiscard]] Status set_pen(bool down) {
        if (status().device_state() != DeviceState::kIdle || channel_.queue.queued_spans() != 0) {
            return Status::kWrongState;
        }
        post(down ? kMailboxPenDown : kMailboxPenUp);
        return Status::kOk;
    }

    /// True from a command() that posted a request until the tick that takes it.
    bool command_pending() const {
        return channel_.mailbox.command.load(std::memory_order_relaxed) != status().command_applied;
    }

private:
    Status post_command(Command c, std::uint32_t modifier) {
        const std::uint32_t value = static_cast<std::uint32_t>(c);
        if (!is_command(value)) return Status::kUnknownCommand;
        const DeviceStatus<Axes> s = status();
        const DeviceState state = s.device_state();
        const bool queued = channel_.queue.queued_spans() != 0;
        // "Already in effect" is judged from the published state, which a request the tick has
        // not taken yet is about to change: with one pending, this request is posted and
        // replaces it (a hold after a resume not yet taken must not leave the resume to run).
        const std::uint32_t pending = channel_.mailbox.command.load(std::memory_order_relaxed);
        const bool settled = pending == s.command_applied;
        // A stop not yet taken is not undone by a later request: the device is stopping.
        if (!settled &&
            (pending & kMailboxValueMask) == static_cast<std::uint32_t>(Command::kStop) &&
            c != Command::kReset) {
            return c == Command::kStop ? Status::kOk : Status::kWrongState;
        }
        switch (c) {
            case Command::kStart:
                if (!configured_) return Status::kNotConfigured;
                if (state == DeviceState::kRunning && settled) return Status::kOk;
                if (state != DeviceState::kIdle && state != DeviceState::kRunning)
                    return Status::kWrongState;
                if (state == DeviceState::kIdle && !queued) return Status::kNothingToResume;
                break;
            case Command::kHold:
                if (state == DeviceState::kHolding && settled) return Status::kOk;
                if (state != DeviceState::kRunning && state != DeviceState::kHolding)
                    return Status::kWrongState;
                break;
            case Command::kResume:
                if (state == DeviceState::kRunning && settled) return Status::kOk;
                if (state != DeviceState::kHolding && state != DeviceState::kRunning)
                    return Status::kWrongState;
                if (state == DeviceState::kHolding && s.held_by_underrun() && !queued) {
                    return Status::kNothingToResume;
                }
                break;
            case Command::kStop:
                if (state == DeviceState::kStopping && settled) return Status::kOk;
                if (state != DeviceState::kRunning && state != DeviceState::kHolding &&
                    state != DeviceState::kIdle && state != DeviceState::kStopping) {
                    return Status::kWrongState;
                }
                break;
            case Command::kReset:
                if (state == DeviceState::kIdle) return Status::kOk;  // nothing to reset
                if (state != DeviceState::kFault && state != DeviceState::kEstop)
                    return Status::kWrongState;
                if (state == DeviceState::kEstop &&
                    channel_.mailbox.estop.load(std::memory_order_relaxed) != 0) {
                    return Status::kWrongState;
                }
                break;
            case Command::kJog:
            case Command::kSetPosition:
            case Command::kHome:
            case Command::kPen:
                return Status::kUnknownCommand;  // operator commands carry arguments
        }
        post(value | modifier);
        return Status::kOk;
    }

    // One store carries the request number and the value: the tick can never pair a new
    // number with an old value.
    void post(std::uint32_t value) {
        request_number_ = (request_number_ + 1u) & 0xFFFFFFu;
        channel_.mailbox.command.store((request_number_ << 8) | value, std::memory_order_release);
    }

public:
    /// Any context (a GPIO edge interrupt too): raises a fault; the next tick freezes every
    /// axis where it is, drops the queue and enters kFault. The first fault's code is kept
    /// (loads and stores only: two raisers in the same instant may keep either code, never
    /// none). `code` must not be kNone.
    void raise_fault(FaultCode code) {
        if (channel_.mailbox.fault.load(std::memory_order_acquire) == 0) {
            channel_.mailbox.fault.store(static_cast<std::uint32_t>(code),
                                         std::memory_order_release);
        }
    }

    /// Any context: the e-stop input's level. Active: the next tick freezes every axis, drops
    /// the queue and enters kEstop; kReset is refused until the input is released.
    void set_estop_input(bool active) {
        channel_.mailbox.estop.store(active ? 1u : 0u, std::memory_order_release);
    }

    /// Redefines where the axes are (homing's "set zero"): the next tick makes `position` the
    /// rest point and the last setpoint, without moving, and starts a new epoch there (the
    /// next batch starts at `position`; sequence numbers continue). Idle only, with nothing
    /// queued and no earlier set_position still pending (position_pending()): kWrongState
    /// otherwise.
    [[nodiscard]] Status set_position(const Lsb (&position)[Axes]) {
        const DeviceStatus<Axes> s = status();
        if (s.device_state() != DeviceState::kIdle || channel_.queue.queued_spans() != 0 ||
            position_posted_ != s.position_applied) {
            return Status::kWrongState;
        }
        for (unsigned a = 0; a < Axes; ++a) channel_.mailbox.position[a] = position[a];
        ++position_posted_;
        channel_.mailbox.position_request.store(position_posted_, std::memory_order_release);
        return Status::kOk;
    }
    /// True from set_position() until the tick that applies it.
    bool position_pending() const { return position_posted_ != status().position_applied; }

    /// The tick's status, whole (one tick's values, never a mix of two).
    DeviceStatus<Axes> status() const { return channel_.board.read(); }
    /// Sequence number of the last span accepted (0 before the first; the first is 1).
    std::uint32_t last_accepted_sequence() const { return next_sequence_ - 1u; }
    /// Batches acknowledged as retries.
    std::uint32_t duplicates() const { return duplicates_; }
    /// The epoch the chain of accepted spans belongs to (the task side takes a new epoch from
    /// the status at its next batch).
    std::uint32_t producer_epoch() const { return producer_epoch_; }
    /// Free queue slots (a lower bound: the tick only frees more). Either context.
    std::uint32_t free_slots() const { return channel_.queue.free_slots(); }
    /// Spans queued, the one in progress included. Either context.
    std::uint32_t queued_spans() const { return channel_.queue.queued_spans(); }

private:
    // Where the next span must start: position, end tangent, end acceleration and length of
    // the last span accepted (tangent and acceleration 0: at rest, as after a job end or a
    // pause), and the job the next span belongs to.
    struct Chain {
        Lsb start[Axes] = {};
        std::int32_t tangent[Axes] = {};
        TickAcceleration acceleration[Axes] = {};
        std::uint32_t ticks = 1;
        std::uint32_t job = 1;
    };

    // The last batch queued, as much of it as a resend is compared with (count 0: none yet).
    struct LastBatch {
        std::uint32_t first = 0;
        std::uint16_t count = 0;
        std::size_t length = 0;
        std::uint32_t crc = 0;
    };

    // A new epoch (the tick dropped the queue): the next span starts at rest at its origin,
    // and begins a new job.
    void sync_epoch(const DeviceStatus<Axes>& s) {
        if (s.epoch == producer_epoch_) return;
        producer_epoch_ = s.epoch;
        channel_.queue.restart_producer_at(s.origin);
        chain_ = Chain{};
        for (unsigned a = 0; a < Axes; ++a) chain_.start[a] = s.origin[a];
        chain_.job = next_sequence_;
    }

    // Decodes `count` spans, validating each (push = false) or queueing each with its stamp
    // (push = true). `chain` carries position, tangent and job from span to span.
    template <typename Between>
    Status walk_batch(const std::uint8_t* payload, std::size_t length, std::uint16_t count,
                      Chain& chain, bool push, Between& between) {
        std::size_t offset = 0;
        for (std::uint16_t i = 0; i < count; ++i) {
            WireSpan w;
            std::size_t used = 0;
            if (Status st = decode_wire_span(payload + offset, length - offset, Axes, w, used);
                st != Status::kOk) {
                return st;
            }
            offset += used;
            if ((w.flags & kWireContinueTangent) != 0) {
                for (unsigned a = 0; a < Axes; ++a) w.start_tangent[a] = chain.tangent[a];
            }
            const bool job_end = (w.flags & kWireJobEnd) != 0;
            const bool pause = (w.flags & kWirePause) != 0;
            const std::uint32_t sequence = next_sequence_ + i;
            const Span<Axes> span = to_core_span<Axes>(w, chain.start, sequence);
            if (!push) {
                if (Status st = check_span(span, w, chain, job_end, pause); st != Status::kOk) {
                    return st;
                }
            } else {
                SpanStamp<Axes> stamp;
                stamp.epoch = producer_epoch_;
                stamp.job = chain.job;
                stamp.job_end = job_end;
                stamp.pause_after = pause;
                for (unsigned a = 0; a < Axes; ++a) {
                    stamp.end_tangent[a] = w.end_tangent[a];
                    stamp.start_tangent[a] = w.start_tangent[a];
                    stamp.chord[a] = w.end[a] - chain.start[a];  // both within +-2^27
                }
                between();
                if (Status st = channel_.queue.push(span, stamp); st != Status::kOk) return st;
            }
            for (unsigned a = 0; a < Axes; ++a) {
                // A job end or a pause is followed by rest: the next span starts from there.
                chain.acceleration[a] =
                    job_end || pause
                        ? TickAcceleration{}
                        : hermite_end_acceleration(w.end[a] - chain.start[a], w.start_tangent[a],
                                                   w.end_tangent[a], w.ticks);
                chain.start[a] = w.end[a];
                chain.tangent[a] = w.end_tangent[a];
            }
            chain.ticks = w.ticks;
            if (job_end) chain.job = sequence + 1u;
        }
        return offset == length ? Status::kOk : Status::kBadBatch;
    }

    // The core's validation, the exact limit checks (velocity, acceleration, jerk, travel), the
    // join with the previous span (velocity, and acceleration under a jerk limit), and a job
    // end or a pause at rest (velocity, and acceleration under a jerk limit).
    Status check_span(const Span<Axes>& span, const WireSpan& w, const Chain& chain, bool job_end,
                      bool pause) const {
        ValidatedSpan<Axes> v;
        if (Status st = validate_span(span, v); st != Status::kOk) return st;
        for (unsigned a = 0; a < Axes; ++a) {
            if (Status st =
                    check_axis_limits(v.cubic[a], v.timing, limits_.axis[a], limits_.tick_hz);
                st != Status::kOk) {
                return st;
            }
            if (enforce_travel_) {
                if (Status st = check_axis_travel(v.cubic[a], v.timing, limits_.axis[a]);
                    st != Status::kOk) {
                    return st;
                }
            }
            if (Status st = check_axis_jerk(v.cubic[a], v.timing, limits_.axis[a], limits_.tick_hz);
                st != Status::kOk) {
                return st;
            }
        }
        for (unsigned a = 0; a < Axes; ++a) {
            if (Status st = check_join(w.start_tangent[a], w.ticks, chain.tangent[a], chain.ticks,
                                       limits_.axis[a], limits_.tick_hz);
                st != Status::kOk) {
                return st;
            }
            if (Status st = check_acceleration_step(start_acceleration(v.cubic[a], v.timing),
                                                    chain.acceleration[a], limits_.axis[a],
                                                    limits_.tick_hz);
                st != Status::kOk) {
                return st;
            }
        }
        for (unsigned a = 0; a < Axes; ++a) {
            if (w.end_tangent[a] == 0) continue;
            if (job_end) return Status::kJobEndMoving;
            if (pause) return Status::kPauseMoving;
        }
        if (job_end || pause) {
            for (unsigned a = 0; a < Axes; ++a) {
                if (Status st = check_end_at_rest(end_acceleration(v.cubic[a], v.timing),
                                                  limits_.axis[a], limits_.tick_hz);
                    st != Status::kOk) {
                    return st;
                }
            }
        }
        return Status::kOk;
    }

    DeviceChannel<Axes, Capacity>& channel_;
    MotionLimits<Axes> limits_;
    bool configured_ = false;
    bool enforce_travel_ = true;
    std::uint32_t next_sequence_ = 1;
    LastBatch last_batch_;
    std::uint32_t duplicates_ = 0;
    std::uint32_t producer_epoch_ = 0;
    std::uint32_t request_number_ = 0;
    std::uint32_t position_posted_ = 0;
    Chain chain_;
};

}  // namespace pathstream::device
