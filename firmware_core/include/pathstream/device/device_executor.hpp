// The device's tick side: consumes the span queue one tick at a time, applies the task side's
// requests from the mailbox, owns the one motion-stop path (hold, stop, underrun, job end,
// fault, e-stop; a hold or stop from the tick that takes it, inside a span too) and the
// re-entry, drives the discrete outputs, and publishes the status.
// Runs in the tick interrupt only. Shares nothing with the task side but the DeviceChannel.
#pragma once

#include <atomic>
#include <cstdint>

#include "pathstream/device/device_channel.hpp"
#include "pathstream/device/device_state.hpp"
#include "pathstream/device/jerk_moves.hpp"
#include "pathstream/device/motion_limits.hpp"
#include "pathstream/device/stop_spans.hpp"
#include "pathstream/setpoint_stream.hpp"
#include "pathstream/span.hpp"
#include "pathstream/status.hpp"

namespace pathstream::device {

/// Tick side of a device of `Axes` axes with a span queue `Capacity` deep. tick() runs in the
/// tick interrupt; nothing else of this class runs anywhere else. Storage inline.
template <unsigned Axes, std::uint32_t Capacity>
class DeviceExecutor {
public:
    /// Idle at `start` (the channel's start). Init context. `channel` must outlive it.
    DeviceExecutor(DeviceChannel<Axes, Capacity>& channel, const Lsb (&start)[Axes])
        : channel_(channel) {
        for (unsigned a = 0; a < Axes; ++a) {
            position_[a] = rest_[a] = start[a];
            status_.origin[a] = status_.position[a] = start[a];
        }
    }

    /// One tick: applies the mailbox's requests, then writes every axis's setpoint to `out`
    /// and publishes the status. Only a span stamped with the current epoch is ever played:
    /// older ones are dropped unplayed whenever the queue is between spans. Steady state
    /// costs SetpointStream::tick plus the request loads and the status publication; a
    /// controlled stop or re-entry is planned in this call, at a span boundary or in the tick
    /// that takes a hold or stop (a one-off of a few thousand instructions per axis). Tick
    /// interrupt context.
    void tick(Lsb (&out)[Axes]) {
        SetpointStream<Axes, Capacity>& queue = channel_.queue;
        // In the middle of a span, with no request taken, a tick changes only the status's hot
        // words (position, counters): it publishes only those.
        const bool mid_span = motion_ == Motion::kStream && !queue.between_spans();
        const bool took_request = apply_requests();
        // A generated move whose last tick was output ends here, so the tick that outputs its
        // end point already carries the state it leads to (idle only once at rest).
        if (motion_ == Motion::kGenerated && generated_.between_spans() &&
            generated_.queued_spans() == 0) {
            finish_generated();
        }
        bool play = !queue.between_spans();
        if (!play) {
            drop_stale();
            if (state_ == DeviceState::kRunning && motion_ == Motion::kStream) play = at_boundary();
        }
        bool path = false;
        switch (motion_) {
            case Motion::kStream:
                if (play) {
                    (void)queue.tick(out);
                    outputs_ = queue.outputs();
                    path = true;
                } else {
                    for (unsigned a = 0; a < Axes; ++a) out[a] = queue.resting_position(a);
                    outputs_ = held_machine_outputs();
                }
                break;
            case Motion::kGenerated:
                (void)generated_.tick(out);
                ++generated_ticks_;
                // Only the pen, and only for the last pen-down delay of a re-entry onto a
                // pen-down span: it lands as the axes reach the boundary.
                outputs_ = static_cast<std::uint8_t>(
                    held_machine_outputs() |
                    (generated_kind_ == Generated::kReentry && generated_left_ <= pen_lead_ticks_
                         ? pen_lead_outputs_
                         : std::uint8_t{0}));
                --generated_left_;
                break;
            case Motion::kRest:
            default:
                for (unsigned a = 0; a < Axes; ++a) out[a] = rest_[a];
                outputs_ = state_ == DeviceState::kIdle ? manual_pen_ : held_machine_outputs();
                break;
        }
        for (unsigned a = 0; a < Axes; ++a) position_[a] = out[a];
        publish(path, !mid_span || took_request);
    }

private:
    enum class Motion : std::uint8_t { kRest, kStream, kGenerated };
    enum class Generated : std::uint8_t { kNone, kHoldStop, kStopStop, kReentry };

    // The stamp of the span in progress, or of the last one played (tick side's copy: the
    // queue slot is reused once the span is done). Default: at rest.
    struct Current {
        std::int32_t tangent[Axes] = {};
        std::int32_t start_tangent[Axes] = {};  // with the chord: the end acceleration, for a stop
        std::int32_t chord[Axes] = {};
        std::uint32_t ticks = 1;
        bool job_end = false;
        bool pause_after = false;
    };

    const MotionLimits<Axes>& limits() const { return channel_.mailbox.limits; }

    // Off the path, a job keeps the machine functions (spindle, coolant) of the span it last
    // played while it runs, holds or stops (the stream keeps that span's outputs); idle, in a
    // fault and in the e-stop there are none.
    std::uint8_t held_machine_outputs() const {
        const bool job = state_ == DeviceState::kRunning || state_ == DeviceState::kHolding ||
                         state_ == DeviceState::kStopping;
        return job ? static_cast<std::uint8_t>(channel_.queue.outputs() & kOutputMachineMask)
                   : std::uint8_t{0};
    }

    void set_state(DeviceState s) {
        state_ = s;
        status_.state = static_cast<std::uint32_t>(s);
    }
    // The own-move flag changes with the motion, never on a tick in the middle of a move.
    void set_motion(Motion m) {
        motion_ = m;
        status_.flags = m == Motion::kGenerated ? (status_.flags | kStatusOwnMove)
                                                : (status_.flags & ~kStatusOwnMove);
    }
    void set_paused(bool paused) {
        status_.flags = paused ? (status_.flags | kStatusPaused) : (status_.flags & ~kStatusPaused);
    }
    void set_held_by_underrun(bool held) {
        status_.flags = held ? (status_.flags | kStatusHeldByUnderrun)
                             : (status_.flags & ~kStatusHeldByUnderrun);
    }

    // `all`: this tick may have changed words after the hot ones.
    void publish(bool path, bool all) {
        status_.tick_count = status_.tick_count + 1u;
        status_.tick_check = status_.tick_count;
        for (unsigned a = 0; a < Axes; ++a) status_.position[a] = position_[a];
        status_.outputs = outputs_;
        status_.flags =
            path ? (status_.flags | kStatusPathTick) : (status_.flags & ~kStatusPathTick);
        const std::uint64_t executed = channel_.queue.ticks_executed();
        status_.ticks_executed_low = static_cast<std::uint32_t>(executed);
        status_.ticks_executed_high = static_cast<std::uint32_t>(executed >> 32);
        status_.generated_ticks_low = static_cast<std::uint32_t>(generated_ticks_);
        status_.generated_ticks_high = static_cast<std::uint32_t>(generated_ticks_ >> 32);
        status_.last_completed_sequence = channel_.queue.last_completed_tag();
        channel_.board.publish(status_, all);
    }

    // Takes the mailbox's new requests; true when it took one (the status then changed beyond
    // its hot words). Most ticks find none: four relaxed loads decide that without a barrier;
    // take_requests() loads again with acquire before it reads what a request carries.
    bool apply_requests() {
        const DeviceMailbox<Axes>& m = channel_.mailbox;
        const std::uint32_t command = m.command.load(std::memory_order_relaxed);
        const std::uint32_t estop = m.estop.load(std::memory_order_relaxed);
        const std::uint32_t fault = m.fault.load(std::memory_order_relaxed);
        const std::uint32_t position = m.position_request.load(std::memory_order_relaxed);
        if (command == status_.command_applied && position == status_.position_applied &&
            (estop | fault) == 0) {
            return false;
        }
        return take_requests();
    }

    bool take_requests() {
        DeviceMailbox<Axes>& m = channel_.mailbox;
        // The command word first: its acquire makes everything the task side wrote before
        // posting it (configuration, spans) visible to the rest of this tick.
        const std::uint32_t command = m.command.load(std::memory_order_acquire);
        const bool estop = m.estop.load(std::memory_order_acquire) != 0;
        const std::uint32_t fault = m.fault.load(std::memory_order_acquire);
        const DeviceState s = state_;
        if (estop && s != DeviceState::kEstop) {
            stop_at_once();
            set_state(DeviceState::kEstop);
            return true;
        }
        if (fault != 0 && s != DeviceState::kFault && s != DeviceState::kEstop) {
            stop_at_once();
            status_.fault_code = fault;
            set_state(DeviceState::kFault);
            return true;
        }
        const bool position = apply_position_request(s);
        if (command == status_.command_applied) return position;
        status_.command_applied = command;
        const std::uint32_t value = command & kMailboxValueMask;
        if (value == kMailboxPenUp || value == kMailboxPenDown) {
            if (s == DeviceState::kIdle && motion_ == Motion::kRest) {
                manual_pen_ = value == kMailboxPenDown ? kOutputPenDown : std::uint8_t{0};
            }
            return true;
        }
        switch (static_cast<Command>(value)) {
            case Command::kStart:
                // Only the device's own jog keeps the operator's pen: a job's pen is its spans'.
                if ((command & kMailboxKeepPen) == 0) manual_pen_ = 0;
                // Starting with nothing (current) queued does nothing.
                drop_stale();
                if (s == DeviceState::kIdle && channel_.queue.next_span() != nullptr) {
                    set_motion(Motion::kStream);
                    set_state(DeviceState::kRunning);
                }
                break;
            case Command::kHold:
                // Inside a span: the stop starts in this tick. Between spans (and during a
                // re-entry, until it reaches the path): at the boundary.
                if (s == DeviceState::kRunning && !stop_within_span(false)) hold_requested_ = true;
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
                manual_pen_ = 0;
                if (s == DeviceState::kRunning) {
                    if (!stop_within_span(true)) stop_requested_ = true;
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
                    m.fault.store(0, std::memory_order_release);
                    status_.fault_code = static_cast<std::uint32_t>(FaultCode::kNone);
                    drop_queue();
                    set_state(DeviceState::kIdle);
                }
                break;
            default:
                break;  // the task side refuses every other value before posting
        }
        return true;
    }

    // set_position: taken only while idle at rest (a start in the same tick comes after it);
    // in any other state it is dropped (the task sees it applied either way).
    // True when it took a request.
    bool apply_position_request(DeviceState s) {
        DeviceMailbox<Axes>& m = channel_.mailbox;
        const std::uint32_t request = m.position_request.load(std::memory_order_acquire);
        if (request == status_.position_applied) return false;
        if (s == DeviceState::kIdle && motion_ == Motion::kRest) {
            for (unsigned a = 0; a < Axes; ++a) position_[a] = rest_[a] = m.position[a];
            drop_queue();
        }
        status_.position_applied = request;
        return true;
    }

    // Every queue drop: the queue emptied, a new epoch whose chain starts at the rest point.
    // Spans the task side still pushes with the old stamp are dropped by drop_stale().
    void drop_queue() {
        channel_.queue.discard_all(rest_);
        status_.epoch = status_.epoch + 1u;
        for (unsigned a = 0; a < Axes; ++a) status_.origin[a] = rest_[a];
        current_ = Current{};
        set_held_by_underrun(false);
        set_paused(false);
    }

    // Between spans: spans of an older epoch at the head of the queue are never played.
    void drop_stale() {
        SetpointStream<Axes, Capacity>& queue = channel_.queue;
        for (const PreparedSpan<Axes>* next = queue.next_span();
             next != nullptr && next->stamp.epoch != status_.epoch; next = queue.next_span()) {
            queue.drop_next();
        }
    }

    // E-stop and faults: the axes stay at the last output; everything queued is dropped.
    void stop_at_once() {
        manual_pen_ = 0;
        for (unsigned a = 0; a < Axes; ++a) rest_[a] = position_[a];
        set_motion(Motion::kRest);
        generated_kind_ = Generated::kNone;
        hold_requested_ = stop_requested_ = resume_pending_ = false;
        drop_queue();
    }

    void fault(FaultCode code) {
        stop_at_once();
        status_.fault_code = static_cast<std::uint32_t>(code);
        set_state(DeviceState::kFault);
    }

    // The next span becomes the one in progress: its stamp is copied here, where the tick
    // can keep it after the slot is reused.
    void adopt(const PreparedSpan<Axes>& next) {
        for (unsigned a = 0; a < Axes; ++a) {
            current_.tangent[a] = next.stamp.end_tangent[a];
            current_.start_tangent[a] = next.stamp.start_tangent[a];
            current_.chord[a] = next.stamp.chord[a];
        }
        current_.ticks = next.ticks;
        current_.job_end = next.stamp.job_end;
        current_.pause_after = next.stamp.pause_after;
        if (next.stamp.job != status_.job) {
            status_.job = next.stamp.job;
            job_start_ticks_ = channel_.queue.ticks_executed();
        }
        status_.span_epoch = next.stamp.epoch;
    }

    // The last span of a job ended (at rest): report it, and idle there.
    void finish_job() {
        SetpointStream<Axes, Capacity>& queue = channel_.queue;
        status_.finished_job = status_.job;
        status_.finished_job_ticks =
            static_cast<std::uint32_t>(queue.ticks_executed() - job_start_ticks_);
        for (unsigned a = 0; a < Axes; ++a) rest_[a] = queue.resting_position(a);
        set_motion(Motion::kRest);
        current_ = Current{};
        hold_requested_ = false;
        set_state(DeviceState::kIdle);
        if (stop_requested_) {
            stop_requested_ = false;
            drop_queue();
        }
    }

    // Running, between two spans: the job ends, the next span starts, or a controlled stop
    // begins (stop, hold, underrun). True when the stream plays the next span this tick.
    bool at_boundary() {
        SetpointStream<Axes, Capacity>& queue = channel_.queue;
        if (current_.job_end) {
            finish_job();
            return false;
        }
        if (current_.pause_after) {
            // The span ended at rest (the receiver checked): hold here like a hold command.
            current_.pause_after = false;
            hold_requested_ = true;
            set_paused(true);
        }
        const PreparedSpan<Axes>* next = queue.next_span();
        bool moving = false;
        for (unsigned a = 0; a < Axes; ++a) moving = moving || current_.tangent[a] != 0;
        const bool underrun = next == nullptr && moving && !stop_requested_ && !hold_requested_;
        if (!stop_requested_ && !hold_requested_ && !underrun) {
            if (next == nullptr) return false;  // at rest with nothing queued: wait there
            adopt(*next);
            return true;
        }
        for (unsigned a = 0; a < Axes; ++a) {
            boundary_[a] = rest_[a] = queue.resting_position(a);
            boundary_tangent_[a] = current_.tangent[a];
        }
        boundary_ticks_ = current_.ticks;
        const bool stopping = stop_requested_;
        set_held_by_underrun(underrun);
        if (underrun) status_.underruns = status_.underruns + 1u;
        hold_requested_ = stop_requested_ = false;
        // The stop is planned on the base an in-span stop at the span's last tick would get
        // (velocity_within_span at k = n, where the chord and T0 drop out: the velocity is
        // T1/n): the span's own length n, exactly T1, for spans of up to kMinInSpanStopBase
        // ticks or when the stop needs n ticks or more; else the ticks the stop needs, so a
        // long span's stop (an underrun after it) is not stretched to the span's length.
        for (unsigned a = 0; a < Axes; ++a) boundary_acceleration_[a] = TickAcceleration{};
        if (moving) {
            const std::int32_t none[Axes] = {};
            if (velocity_within_span(none, none, current_.tangent, current_.ticks, current_.ticks,
                                     limits(), boundary_tangent_, boundary_ticks_) != Status::kOk) {
                fault(FaultCode::kStopFailed);
                return false;
            }
            for (unsigned a = 0; a < Axes; ++a) {
                boundary_acceleration_[a] =
                    hermite_end_acceleration(current_.chord[a], current_.start_tangent[a],
                                             current_.tangent[a], current_.ticks);
            }
        }
        begin_stop(stopping, moving);
        return false;
    }

    // From boundary_ with boundary_tangent_ over boundary_ticks_: at rest, hold or end the
    // job (a stop drops the queue); moving, the controlled stop of plan_stop.
    void begin_stop(bool stopping, bool moving) {
        if (!moving) {
            set_motion(Motion::kRest);
            if (stopping) {
                drop_queue();
                set_state(DeviceState::kIdle);
            } else {
                set_state(DeviceState::kHolding);
            }
            return;
        }
        // Under a jerk limit the two or three spans of plan_jerk_stop; where none fit, the one
        // span of plan_stop (stopping matters more than the jerk limit).
        JerkMove<Axes> jerk_stop;
        const bool smooth =
            has_jerk_limit(limits()) &&
            plan_jerk_stop(boundary_, boundary_tangent_, boundary_ticks_, boundary_acceleration_,
                           limits(), jerk_stop) == Status::kOk;
        if (!smooth) {
            jerk_stop.count = 1;
            if (plan_stop(boundary_, boundary_tangent_, boundary_ticks_, limits(),
                          jerk_stop.span[0]) != Status::kOk) {
                fault(FaultCode::kStopFailed);
                return;
            }
        }
        if (!start_generated(jerk_stop)) {
            fault(FaultCode::kStopFailed);
            return;
        }
        generated_kind_ = stopping ? Generated::kStopStop : Generated::kHoldStop;
        set_state(stopping ? DeviceState::kStopping : DeviceState::kHolding);
    }

    // A hold (`stopping` false) or stop taken inside a span: a controlled stop planned like
    // one at a boundary (plan_stop), from the setpoint the span would supply in this tick and
    // the span's velocity there (velocity_within_span); that setpoint becomes the boundary a
    // resume re-enters at, and the rest of the span plays after the re-entry. False, and
    // nothing done, between spans and during the device's own moves.
    bool stop_within_span(bool stopping) {
        SetpointStream<Axes, Capacity>& queue = channel_.queue;
        const PreparedSpan<Axes>* span = queue.span_in_progress();
        if (motion_ != Motion::kStream || span == nullptr) return false;
        for (unsigned a = 0; a < Axes; ++a) boundary_[a] = rest_[a] = queue.next_setpoint(a);
        hold_requested_ = stop_requested_ = false;
        set_held_by_underrun(false);
        if (velocity_within_span(span->stamp.chord, span->stamp.start_tangent,
                                 span->stamp.end_tangent, span->ticks, queue.ticks_into_span(),
                                 limits(), boundary_tangent_, boundary_ticks_) != Status::kOk) {
            fault(FaultCode::kStopFailed);
            return true;
        }
        for (unsigned a = 0; a < Axes; ++a) {
            boundary_acceleration_[a] = acceleration_within_span(
                span->stamp.chord[a], span->stamp.start_tangent[a], span->stamp.end_tangent[a],
                span->ticks, queue.ticks_into_span(), boundary_ticks_);
        }
        bool moving = false;
        for (unsigned a = 0; a < Axes; ++a) moving = moving || boundary_tangent_[a] != 0;
        begin_stop(stopping, moving);
        return true;
    }

    void begin_reentry() {
        bool at_boundary = true;
        bool moving = false;
        for (unsigned a = 0; a < Axes; ++a) {
            at_boundary = at_boundary && rest_[a] == boundary_[a];
            moving = moving || boundary_tangent_[a] != 0;
        }
        set_held_by_underrun(false);
        set_paused(false);
        if (at_boundary && !moving) {
            set_motion(Motion::kStream);
            set_state(DeviceState::kRunning);
            return;
        }
        // Under a jerk limit the three or four spans of plan_jerk_reentry, arriving with the
        // acceleration the path has there: the span a stop inside a span left (its value at the
        // stop), else the next span's start.
        JerkMove<Axes> reentry;
        Status planned = Status::kOk;
        if (has_jerk_limit(limits())) {
            TickAcceleration arrival[Axes];
            const PreparedSpan<Axes>* into = channel_.queue.next_span();
            for (unsigned a = 0; a < Axes; ++a) {
                arrival[a] = channel_.queue.span_in_progress() != nullptr || into == nullptr
                                 ? boundary_acceleration_[a]
                                 : start_acceleration_of(into->stamp, into->ticks, a);
            }
            planned = plan_jerk_reentry(rest_, boundary_, boundary_tangent_, boundary_ticks_,
                                        arrival, limits(), reentry);
        } else {
            reentry.count = 1;
            planned = plan_reentry(rest_, boundary_, boundary_tangent_, boundary_ticks_, limits(),
                                   reentry.span[0]);
        }
        if (planned != Status::kOk || !start_generated(reentry)) {
            // No move back onto the path fits: a fault the master sees (rather than a hold
            // that silently never resumes); reset, then restart the job.
            fault(FaultCode::kReentryFailed);
            return;
        }
        generated_kind_ = Generated::kReentry;
        drop_stale();
        // The span the re-entry leads into: the one a stop inside a span left, else the next.
        const PreparedSpan<Axes>* next = channel_.queue.span_in_progress();
        if (next == nullptr) next = channel_.queue.next_span();
        pen_lead_outputs_ = next != nullptr
                                ? static_cast<std::uint8_t>(next->outputs & kOutputPenDown)
                                : std::uint8_t{0};
        pen_lead_ticks_ = limits().pen_down_ticks;
        set_state(DeviceState::kRunning);
    }

    // The acceleration at the start of a queued Hermite span (its stamp): (6C - 4T0 - 2T1) / n^2.
    static TickAcceleration start_acceleration_of(const SpanStamp<Axes>& stamp, std::uint32_t n,
                                                  unsigned a) {
        const std::int64_t c = stamp.chord[a], t0 = stamp.start_tangent[a],
                           t1 = stamp.end_tangent[a];
        return TickAcceleration{6 * c - 4 * t0 - 2 * t1, static_cast<std::uint64_t>(n) * n};
    }

    bool start_generated(const JerkMove<Axes>& move) {
        Lsb from[Axes];
        for (unsigned a = 0; a < Axes; ++a) from[a] = move.span[0].control[a][0];
        generated_.discard_all(from);
        generated_.restart_producer_at(from);
        generated_left_ = 0;
        for (unsigned i = 0; i < move.count; ++i) {
            if (generated_.push(move.span[i]) != Status::kOk) return false;
            generated_left_ += move.span[i].ticks;
        }
        set_motion(Motion::kGenerated);
        return true;
    }

    void finish_generated() {
        const Generated kind = generated_kind_;
        generated_kind_ = Generated::kNone;
        for (unsigned a = 0; a < Axes; ++a) rest_[a] = generated_.resting_position(a);
        set_motion(Motion::kRest);
        if (kind == Generated::kReentry) {
            // The stream resumes where it left the path; a stop or hold requested meanwhile
            // is taken there: at once inside a span, else at the boundary (at_boundary).
            set_motion(Motion::kStream);
            if (stop_requested_ || hold_requested_) (void)stop_within_span(stop_requested_);
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

    // The per-tick fields first, at small offsets (ARMv6-M loads and stores reach 124 bytes).
    DeviceChannel<Axes, Capacity>& channel_;
    DeviceStatus<Axes> status_;  // published by every tick
    DeviceState state_ = DeviceState::kIdle;
    Motion motion_ = Motion::kRest;
    Generated generated_kind_ = Generated::kNone;
    bool hold_requested_ = false;
    bool stop_requested_ = false;
    bool resume_pending_ = false;
    std::uint8_t outputs_ = 0;
    std::uint8_t manual_pen_ = 0;  // the operator's pen at rest while idle (set_pen)
    std::uint8_t pen_lead_outputs_ = 0;
    std::uint32_t pen_lead_ticks_ = 0;
    std::uint32_t generated_left_ = 0;  // ticks of the generated spans still to output
    std::uint64_t generated_ticks_ = 0;
    std::uint64_t job_start_ticks_ = 0;  // path ticks executed when the current job began
    Current current_;
    Lsb position_[Axes] = {};
    Lsb rest_[Axes] = {};
    Lsb boundary_[Axes] = {};
    std::int32_t boundary_tangent_[Axes] = {};
    std::uint32_t boundary_ticks_ = 1;
    TickAcceleration boundary_acceleration_[Axes] = {};  // the path's acceleration at boundary_
    SetpointStream<Axes, 4> generated_;                  // the device's own stop and re-entry spans
};

}  // namespace pathstream::device
