// The streaming loop shared by the Modbus and CAN clients (docs/modbus.md, docs/can.md).
#include "span_streamer.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "pathstream/device/motion_device.hpp"

namespace pathstream::host {

using device::DeviceState;

SpanStreamer::SpanStreamer(SpanSupply& supply, const MachineProfile& profile, BusSession& bus,
                           const StreamSettings& settings)
    : feed_(supply), profile_(profile), bus_(bus), settings_(settings) {}

std::vector<Lsb> SpanStreamer::rest_position() {
    bus_.mark_alive();
    axes_ = static_cast<unsigned>(profile_.axes.size());
    const DeviceSnapshot s = bus_.read_status();
    check_identity(s, false, DeviceState::kIdle);
    return std::vector<Lsb>(s.position, s.position + axes_);
}

StreamOutcome SpanStreamer::run(const SupplyProgress& progress) {
    const auto wall_start = Clock::now();
    bus_.mark_alive();
    // The job's first span (planning may still run): where the device must rest.
    feed_.wait_first();
    axes_ = feed_.axes();
    std::copy(feed_.start(), feed_.start() + axes_, start_);
    DeviceSnapshot s = bus_.read_status();
    std::size_t next = 0;
    if (settings_.held != nullptr) {
        next = continue_held(s);
    } else {
        check_identity(s, true, DeviceState::kIdle);
        configure();
        base_ = s.last_accepted + 1;
        acknowledged_ = s.last_accepted;
    }
    free_slots_ = s.free_slots;
    // The queue epoch the job lives in: a change that this stream did not ask for is a stop,
    // fault or e-stop from elsewhere.
    job_epoch_ = s.epoch;
    underruns_at_start_ = s.underruns;
    // A held job goes on with a resume (the device's own re-entry) instead of a start.
    const device::Command go =
        settings_.held != nullptr ? device::Command::kResume : device::Command::kStart;
    rate_ = profile_.tick_hz;
    const auto lead_target =
        static_cast<std::uint64_t>(std::ceil(settings_.lead_seconds * profile_.tick_hz));
    const auto poll = std::chrono::milliseconds(settings_.poll_interval_ms);
    bool started = false;
    StreamInterrupt interrupt(*settings_.interrupt);
    PauseWatch pauses(*settings_.interrupt, feed_.pauses());
    while (true) {
        if (feed_.error()) interrupt.force_hold();
        const StreamInterrupt::Action action = interrupt.next_action(started);
        if (action == StreamInterrupt::Action::kHold) command(device::Command::kHold, true);
        if (action == StreamInterrupt::Action::kStop) command(device::Command::kStop, true);
        const std::uint64_t lead = queued_ticks(s, next);
        const bool can_send = free_slots_ > 0 && s.state != DeviceState::kStopping;
        std::optional<DeviceSnapshot> fresh;
        if (interrupt.active()) {
            std::this_thread::sleep_for(poll);
            fresh = bus_.read_status();
        } else if (can_send && (lead < lead_target || !started) && feed_.sendable(next)) {
            fresh = send_batch(next);
        } else {
            bool predicted = false;
            std::this_thread::sleep_for(poll_wait(lead, lead_target, started, predicted));
            // Woken when the lead should have drained to the target: send the next batch at
            // once when its answer is the status anyway (instead of polling first). The free
            // slots known are a lower bound (slots only free up), so the batch fits.
            if (predicted && bus_.batch_answers_with_status() && can_send && feed_.sendable(next)) {
                fresh = send_batch(next);
            } else {
                fresh = bus_.read_status();
            }
        }
        if (fresh) {
            s = *fresh;
            free_slots_ = s.free_slots;
            observe(s, interrupt);
            observe_rate(s, started);
            if (!interrupt.stop_sent() && s.epoch != job_epoch_ && s.state == DeviceState::kIdle &&
                !job_finished(s)) {
                outcome_.interrupted = 2;  // dropped by another client's stop: report a stop
                outcome_.stopped_elsewhere = true;
                break;
            }
            check_running(s, started && !interrupt.stop_sent());
        }
        // Start once the lead is queued, or everything is, or the device's queue is full
        // (a lead longer than the queue holds would otherwise never start).
        if (!started && !interrupt.active() &&
            (queued_ticks(s, next) >= lead_target || all_sent(next) || free_slots_ == 0)) {
            command(go, false);
            started = true;
            started_at_ = Clock::now();
        }
        if (!interrupt.active() && s.state == DeviceState::kHolding && s.held_by_underrun() &&
            s.queued > 0) {
            command(device::Command::kResume, true);
        }
        if (pauses.observe(s, s.ticks_executed - start_ticks_) && !interrupt.active()) {
            command(device::Command::kResume, true);
        }
        if (progress) {
            progress(static_cast<std::uint32_t>(s.ticks_executed - start_ticks_),
                     feed_.total_ticks(),
                     static_cast<double>(queued_ticks(s, next)) / profile_.tick_hz);
        }
        // The job (its last span marks the end) is done when the device reports it finished,
        // idle at its end point.
        if (job_finished(s)) break;
        if (interrupt.active() && interrupt.settled(s)) {
            outcome_.interrupted = interrupt.outcome();
            break;
        }
    }
    if (feed_.error()) finish_after_supply_error(s);
    outcome_.final_status = s;
    outcome_.ticks_executed = s.finished_job_ticks;
    outcome_.job = outcome_.interrupted != 0 ? base_ : s.finished_job;
    outcome_.last_completed = s.last_completed;
    outcome_.duplicates = s.duplicates;
    // This job's underruns: the device counts since it started (16 bits on the bus).
    outcome_.underruns = static_cast<std::uint16_t>(s.underruns - underruns_at_start_);
    std::copy(s.position, s.position + kMaxAxes, outcome_.final_position);
    outcome_.wall_seconds = std::chrono::duration<double>(Clock::now() - wall_start).count();
    return outcome_;
}

// The plan failed while the job ran: the device holds at rest (or never started); drop the
// rest of its queue, then report the plan's error.
void SpanStreamer::finish_after_supply_error(DeviceSnapshot& s) {
    command(device::Command::kStop, true);
    const auto deadline =
        Clock::now() + std::chrono::duration<double>(settings_.interrupt->hold_timeout_seconds);
    while (s.state != DeviceState::kIdle && Clock::now() < deadline) {
        std::this_thread::sleep_for(std::chrono::milliseconds(settings_.poll_interval_ms));
        s = bus_.read_status();
    }
    std::rethrow_exception(feed_.error());
}

// A held job (docs/cli.md, "Interrupt and resume"): the device must hold it, configured, with
// no span of it dropped; returns the index of the first span it has not accepted.
std::size_t SpanStreamer::continue_held(const DeviceSnapshot& s) {
    check_identity(s, false, DeviceState::kHolding);
    const HeldJob& h = *settings_.held;
    if (!s.configured())
        bus_.fail("device lost its configuration: it restarted; resume from its rest instead");
    if (s.last_accepted < h.job || !feed_.available(s.last_accepted - h.job) ||
        s.last_completed + 1 < h.job) {
        std::ostringstream m;
        m << "device holds spans up to " << s.last_accepted << ", not job " << h.job << " of "
          << feed_.count() << " spans";
        bus_.fail(m.str());
    }
    base_ = h.job;
    acknowledged_ = s.last_accepted;
    configured_ = true;
    const std::size_t completed = s.last_completed + 1 - h.job;
    start_ticks_ = s.ticks_executed - static_cast<std::uint32_t>(feed_.ticks_before(completed));
    return s.last_accepted + 1 - h.job;
}

// The device speaks this protocol, has the plan's axes, is in the `wanted` state and (with
// check_start) rests where the job starts.
void SpanStreamer::check_identity(const DeviceSnapshot& s, bool check_start, DeviceState wanted) {
    bus_.check_protocol(s);
    std::ostringstream m;
    if (s.axes != axes_) {
        m << "device has " << s.axes << " axes, the plan " << axes_;
        bus_.fail(m.str());
    }
    if (s.state != wanted) {
        m << "device is " << device_state_name(s.state) << fault_suffix(s.state, s.fault_code);
        m << (wanted == DeviceState::kIdle ? ", not idle: reset or stop it first"
                                           : ", not holding the job");
        bus_.fail(m.str());
    }
    for (unsigned a = 0; a < axes_ && check_start; ++a) {
        if (s.position[a] != start_[a]) {
            std::int32_t rest[kMaxAxes] = {};
            std::copy(s.position, s.position + axes_, rest);
            m << "device rests at " << position_text(profile_, rest, axes_)
              << " but the plan starts at " << position_text(profile_, start_, axes_)
              << " (stream without --no-lead-in moves there pen up first)";
            bus_.fail(m.str());
        }
    }
    start_ticks_ = s.ticks_executed;
}

// The profile's tick rate and limits, in the device's units, written to it.
void SpanStreamer::configure() {
    DeviceLimitsLsb limits;
    try {
        limits = device_limits(profile_);
    } catch (const std::range_error& e) {
        bus_.fail(e.what());
    }
    if (const auto refused = bus_.configure(limits, axes_)) {
        bus_.fail("device refused the configuration (tick rate and limits): " + *refused +
                  refusal_detail());
    }
    configured_ = true;
}

// Commands a stream may send while its job may have ended or been stopped elsewhere tolerate
// a refusal; a refused start or resume of the job fails the stream.
void SpanStreamer::command(device::Command c, bool tolerate_refusal) {
    const auto refused = bus_.command(c);
    if (refused && !tolerate_refusal) {
        bus_.fail("device refused command " + std::to_string(static_cast<int>(c)) + ": " +
                  *refused + refusal_detail());
    }
}

// Why the device refused, from its status; a device that restarted since the last
// acknowledgement refuses everything (it is unconfigured), so that is reported instead.
std::string SpanStreamer::refusal_detail() {
    DeviceSnapshot s;
    try {
        s = bus_.read_status();
    } catch (const std::exception&) {
        return "";
    }
    check_restart(s);
    return bus_.refusal_note(s);
}

// Sends the next batch the device has room for: as many spans as the bus allows from `next`;
// returns the status the answer brought, if any.
std::optional<DeviceSnapshot> SpanStreamer::send_batch(std::size_t& next) {
    const std::size_t max_spans = std::min<std::size_t>(bus_.batch_span_limit(), free_slots_);
    const std::size_t max_bytes = bus_.batch_byte_limit();
    std::vector<std::uint8_t> payload;
    std::size_t count = 0;
    while (count < max_spans && feed_.sendable(next + count) &&
           payload.size() + feed_.bytes(next + count).size() <= max_bytes) {
        const std::vector<std::uint8_t>& span = feed_.bytes(next + count);
        payload.insert(payload.end(), span.begin(), span.end());
        ++count;
    }
    const std::uint32_t first = base_ + static_cast<std::uint32_t>(next);
    const std::uint32_t last = first + static_cast<std::uint32_t>(count) - 1;
    BatchAnswer answer = bus_.send_batch(first, count, payload);
    if (answer.free_slots) free_slots_ = *answer.free_slots;
    switch (answer.kind) {
        case BatchAnswer::Kind::kAccepted:
            batch_done(next, count, last);
            return answer.status;
        case BatchAnswer::Kind::kLater:
            return answer.status;
        case BatchAnswer::Kind::kUnknown: {
            // The batch may or may not have been applied (a lost answer): the status says.
            const DeviceSnapshot s = answer.status ? *answer.status : bus_.read_status();
            check_restart(s);
            if (s.last_accepted == last) batch_done(next, count, last);
            return s;
        }
        case BatchAnswer::Kind::kRefused:
            break;
    }
    // A queue dropped under the stream, or about to be (another client's stop: the device
    // refuses batches while it stops), refuses the next batch, which no longer joins what the
    // device holds: the loop then says what happened.
    const DeviceSnapshot now = answer.status ? *answer.status : bus_.read_status();
    if (now.epoch != job_epoch_ || now.state == DeviceState::kStopping) return now;
    check_restart(now);
    std::ostringstream m;
    m << "device refused spans " << first - base_ + 1 << ".." << last - base_ + 1
      << " of the job: " << answer.reason << bus_.refusal_note(now);
    bus_.fail(m.str());
}

// Acknowledged spans are never sent again: their encoding is freed.
void SpanStreamer::batch_done(std::size_t& next, std::size_t count, std::uint32_t last) {
    next += count;
    feed_.release_before(next);
    ++outcome_.batches;
    outcome_.spans_sent += count;
    acknowledged_ = last;
}

void SpanStreamer::observe(const DeviceSnapshot& s, const StreamInterrupt& interrupt) const {
    if (settings_.observer == nullptr || !*settings_.observer) return;
    StreamTrace t;
    t.job = base_;
    t.acknowledged = acknowledged_;
    t.status = s;
    t.hold_requested = interrupt.hold_sent();
    t.stop_requested = interrupt.stop_sent();
    (*settings_.observer)(t);
}

// How long to wait before the next status poll. While more than the lead is queued, sleep
// until the device should have worked it down to the lead (at its observed tick rate), but
// never more than half the queued motion: polling every poll_interval_ms instead would fill
// a serial line with status reads. `predicted` tells whether the wait ends when the lead
// should be at the target (not at the half-lead cap or the minimum).
std::chrono::microseconds SpanStreamer::poll_wait(std::uint64_t lead, std::uint64_t lead_target,
                                                  bool started, bool& predicted) const {
    const double minimum = settings_.poll_interval_ms * 1e-3;
    double wait = minimum;
    predicted = false;
    if (started && lead > lead_target && rate_ > 0) {
        const double drain = static_cast<double>(lead - lead_target) / rate_;
        const double cap = std::max(minimum, 0.5 * static_cast<double>(lead) / rate_);
        wait = std::clamp(drain, minimum, cap);
        predicted = drain >= minimum && drain <= cap;
    }
    return std::chrono::microseconds(static_cast<std::int64_t>(wait * 1e6));
}

// The device's tick rate as observed between polls (a simulated device may run faster than
// its configured rate); starts at the configured rate, and never assumes slower than seen.
void SpanStreamer::observe_rate(const DeviceSnapshot& s, bool started) {
    const auto now = Clock::now();
    const double dt = std::chrono::duration<double>(now - rate_time_).count();
    if (!started || s.state != DeviceState::kRunning || s.ticks_executed < rate_ticks_) {
        rate_time_ = now;
        rate_ticks_ = s.ticks_executed;
        return;
    }
    if (dt < 0.02) return;
    const double observed = static_cast<double>(s.ticks_executed - rate_ticks_) / dt;
    if (observed > 0) rate_ = std::max(rate_, observed);
    rate_time_ = now;
    rate_ticks_ = s.ticks_executed;
}

// Ticks of motion sent but not yet executed, exact: the device counts path ticks.
std::uint64_t SpanStreamer::queued_ticks(const DeviceSnapshot& s, std::size_t sent) const {
    const std::uint64_t done = static_cast<std::uint32_t>(s.ticks_executed - start_ticks_);
    const std::uint64_t sent_ticks = feed_.ticks_before(sent);
    return done >= sent_ticks ? 0 : sent_ticks - done;
}

// Spans of the job the device executed to their end.
std::size_t SpanStreamer::completed_count(const DeviceSnapshot& s) const {
    return s.last_completed >= base_ ? s.last_completed - base_ + 1 : 0;
}

// Every span of the job is sent (the supply ended and the last one is encoded).
bool SpanStreamer::all_sent(std::size_t next) const {
    return feed_.complete() && next == feed_.count();
}

// Our job (its id: the sequence number of its first span) ran to its end: the device idles at
// the plan's end point.
bool SpanStreamer::job_finished(const DeviceSnapshot& s) const {
    return s.state == DeviceState::kIdle && s.finished_job == base_;
}

// A device whose sequence or tick count went backwards, or that lost its configuration, lost
// its queue: it restarted.
void SpanStreamer::check_restart(const DeviceSnapshot& s) const {
    bus_.check_protocol(s);
    if (s.last_accepted < acknowledged_ || s.ticks_executed < start_ticks_ ||
        (configured_ && !s.configured())) {
        std::ostringstream m;
        m << "device restarted mid-stream (it reports sequence " << s.last_accepted << " and "
          << s.ticks_executed << " ticks" << (s.configured() ? "" : ", unconfigured")
          << "; it had acknowledged " << acknowledged_
          << "): stopping; the drawing is incomplete, restart it from the beginning";
        bus_.fail(m.str());
    }
}

void SpanStreamer::check_running(const DeviceSnapshot& s, bool started) {
    check_restart(s);
    std::ostringstream m;
    if (s.state == DeviceState::kFault || s.state == DeviceState::kEstop) {
        m << "device stopped in " << device_state_name(s.state)
          << fault_suffix(s.state, s.fault_code) << " after " << completed_count(s) << " spans";
        bus_.fail(m.str());
    }
    // The device applies a start at its next tick: idle right after the acknowledged start is
    // the start still pending, not a stop, until it has been seen running or has had ample
    // time (half a second) to tick.
    if (started && s.state != DeviceState::kIdle) seen_running_ = true;
    const bool start_pending =
        !seen_running_ && std::chrono::duration<double>(Clock::now() - started_at_).count() < 0.5;
    if (started && s.state == DeviceState::kIdle && !job_finished(s) && !start_pending) {
        m << "device went idle after span " << s.last_completed << " (stopped by another master?)";
        bus_.fail(m.str());
    }
}

}  // namespace pathstream::host
