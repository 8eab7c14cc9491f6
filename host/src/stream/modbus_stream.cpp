// The Modbus streaming client: plan -> wire spans -> sequenced batches, flow-controlled by the
// device's status block, with its own reconnect logic (docs/modbus.md).
#include "pathstream/host/modbus_stream.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <sstream>
#include <thread>
#include <vector>

#include "modbus_link.hpp"
#include "pathstream/device/modbus_map.hpp"
#include "pathstream/device/motion_device.hpp"
#include "pathstream/device/wire_span.hpp"
#include "pathstream/hal/modbus_client.hpp"
#include "pathstream/hal/modbus_error.hpp"
#include "pathstream/machine/device_setup.hpp"
#include "pathstream/host/wire_plan.hpp"
#include "pathstream/status.hpp"
#include "stream_interrupt.hpp"
#include "wire_feed.hpp"

namespace pathstream::host {
namespace {

namespace mb = device::modbus;
namespace st = device::modbus::status;
using Clock = std::chrono::steady_clock;

using DeviceStatus = DeviceSnapshot;

class Streamer {
public:
    Streamer(SpanSupply& supply, const MachineProfile& profile, const StreamOptions& options)
        : feed_(supply), profile_(profile), options_(options), link_(options) {}

    /// Identity and state checked, the device's rest position (LSB per axis).
    std::vector<Lsb> rest_position() {
        link_.mark_alive();
        last_batch_ok_ = Clock::now();
        axes_ = static_cast<unsigned>(profile_.axes.size());
        const DeviceStatus s = read_status();
        check_identity(s, false);
        return std::vector<Lsb>(s.position, s.position + axes_);
    }

    StreamReport run(const SupplyProgress& progress) {
        const auto wall_start = Clock::now();
        link_.mark_alive();
        last_batch_ok_ = Clock::now();
        encode_plan();
        DeviceStatus s = read_status();
        std::size_t next = 0;
        if (options_.held != nullptr) {
            next = continue_held(s);
        } else {
            check_identity(s);
            configure();
            base_ = s.last_accepted + 1;
            acknowledged_ = s.last_accepted;
        }
        // The queue epoch the job lives in: a change that this stream did not ask for is a stop,
        // fault or e-stop from elsewhere.
        job_epoch_ = s.epoch;
        underruns_at_start_ = s.underruns;
        // A held job goes on with a resume (the device's own re-entry) instead of a start.
        const device::Command go =
            options_.held != nullptr ? device::Command::kResume : device::Command::kStart;
        rate_ = profile_.tick_hz;
        const std::uint64_t lead_target =
            static_cast<std::uint64_t>(std::ceil(options_.lead_seconds * profile_.tick_hz));
        bool started = false;
        StreamInterrupt interrupt(options_.interrupt);
        PauseWatch pauses(options_.interrupt, feed_.pauses());
        while (true) {
            if (feed_.error()) interrupt.force_hold();
            const StreamInterrupt::Action action = interrupt.next_action(started);
            if (action == StreamInterrupt::Action::kHold) command(device::Command::kHold, true);
            if (action == StreamInterrupt::Action::kStop) command(device::Command::kStop, true);
            const std::uint64_t lead = queued_ticks(s, next);
            if (interrupt.active()) {
                std::this_thread::sleep_for(std::chrono::milliseconds(options_.poll_interval_ms));
                s = read_status();
            } else if (s.free_slots > 0 && (lead < lead_target || !started) &&
                       s.state != static_cast<std::uint16_t>(device::DeviceState::kStopping) &&
                       feed_.sendable(next)) {
                s = send_batch(next, s.free_slots);
            } else {
                bool predicted = false;
                std::this_thread::sleep_for(poll_wait(lead, lead_target, started, predicted));
                // Woken when the lead should have drained to the target: send the next batch
                // at once (its FC23 answer is the status) instead of polling first. The free
                // slots known are a lower bound (slots only free up), so the batch fits.
                if (predicted && s.free_slots > 0 &&
                    s.state != static_cast<std::uint16_t>(device::DeviceState::kStopping) &&
                    feed_.sendable(next)) {
                    s = send_batch(next, s.free_slots);
                } else {
                    s = read_status();
                }
            }
            observe(s, interrupt);
            observe_rate(s, started);
            if (!interrupt.stop_sent() && s.epoch != job_epoch_ &&
                s.state == static_cast<std::uint16_t>(device::DeviceState::kIdle) &&
                !job_finished(s)) {
                report_.interrupted = 2;  // dropped by another client's stop: report it as a stop
                report_.stopped_elsewhere = true;
                break;
            }
            check_running(s, started && !interrupt.stop_sent());
            // Start once the lead is queued, or everything is, or the device's queue is full
            // (a lead longer than the queue holds would otherwise never start).
            if (!started && !interrupt.active() &&
                (queued_ticks(s, next) >= lead_target || all_sent(next) || s.free_slots == 0)) {
                command(go, false);
                started = true;
                started_at_ = Clock::now();
            }
            if (!interrupt.active() &&
                s.state == static_cast<std::uint16_t>(device::DeviceState::kHolding) &&
                (s.flags & 2u) != 0 && s.queued > 0) {
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
            // The plan is one job (its last span marks the end): done when the device reports
            // it finished, idle at its end point.
            if (job_finished(s)) break;
            if (interrupt.active() && interrupt.settled(s)) {
                report_.interrupted = interrupt.outcome();
                break;
            }
        }
        if (feed_.error()) {
            // The plan failed while the job ran: the device holds at rest (or never started);
            // drop the rest of its queue, then report the plan's error.
            command(device::Command::kStop, true);
            const auto deadline = Clock::now() + std::chrono::duration<double>(
                                                     options_.interrupt.hold_timeout_seconds);
            while (s.state != static_cast<std::uint16_t>(device::DeviceState::kIdle) &&
                   Clock::now() < deadline) {
                std::this_thread::sleep_for(std::chrono::milliseconds(options_.poll_interval_ms));
                s = read_status();
            }
            std::rethrow_exception(feed_.error());
        }
        report_.final_status = s;
        report_.ticks_executed = s.finished_job_ticks;
        report_.job = report_.interrupted != 0 ? base_ : s.finished_job;
        report_.last_completed = s.last_completed;
        report_.duplicates = s.duplicates;
        // This job's underruns: the device counts since it started (16 bits on the bus).
        report_.underruns = static_cast<std::uint16_t>(s.underruns - underruns_at_start_);
        for (unsigned a = 0; a < 8; ++a) report_.final_position[a] = s.position[a];
        const auto& c = link_.client().counters();
        report_.transactions = c.transactions;
        report_.retries = c.retries;
        report_.attempts = c.attempts;
        report_.exception_responses = c.exception_responses;
        report_.reconnects = c.reconnects;
        report_.bytes_sent = c.adu_bytes_sent;
        report_.bytes_received = c.adu_bytes_received;
        report_.wall_seconds = std::chrono::duration<double>(Clock::now() - wall_start).count();
        return report_;
    }

private:
    // A held job (docs/cli.md, "Interrupt and resume"): the device must hold it, configured,
    // with no span of it dropped; returns the index of the first span it has not accepted.
    std::size_t continue_held(const DeviceStatus& s) {
        check_identity(s, false, device::DeviceState::kHolding);
        const HeldJob& h = *options_.held;
        if ((s.flags & 1u) == 0)
            fail("device lost its configuration: it restarted; resume from its rest instead");
        if (s.last_accepted < h.job || !feed_.available(s.last_accepted - h.job) ||
            s.last_completed + 1 < h.job) {
            std::ostringstream m;
            m << "device holds spans up to " << s.last_accepted << ", not job " << h.job << " of "
              << feed_.count() << " spans";
            fail(m.str());
        }
        base_ = h.job;
        acknowledged_ = s.last_accepted;
        configured_ = true;
        const std::size_t completed = s.last_completed + 1 - h.job;
        start_ticks_ = s.ticks_executed - static_cast<std::uint32_t>(feed_.ticks_before(completed));
        return s.last_accepted + 1 - h.job;
    }

    void observe(const DeviceStatus& s, const StreamInterrupt& interrupt) const {
        if (!options_.observer) return;
        StreamTrace t;
        t.job = base_;
        t.acknowledged = acknowledged_;
        t.status = s;
        t.hold_requested = interrupt.hold_sent();
        t.stop_requested = interrupt.stop_sent();
        options_.observer(t);
    }

    DeviceLimitsLsb limits_or_fail() const {
        try {
            return device_limits(profile_);
        } catch (const std::range_error& e) {
            fail(e.what());
        }
    }

    [[noreturn]] void fail(const std::string& what) const { link_.fail(what); }

    DeviceStatus read_status() {
        ++report_.status_reads;
        return link_.read_status(st::kStreamingCount);
    }

    void check_identity(const DeviceStatus& s, bool check_start = true,
                        device::DeviceState wanted = device::DeviceState::kIdle) {
        std::ostringstream m;
        if (s.magic != mb::kMagic) {
            m << "not a pathstream device (register 0 is 0x" << std::hex << s.magic
              << ", expected 0x5053)";
            fail(m.str());
        }
        if (s.version != mb::kProtocolVersion) {
            m << "device speaks protocol version " << s.version << ", this host "
              << mb::kProtocolVersion;
            fail(m.str());
        }
        if (s.axes != axes_) {
            m << "device has " << s.axes << " axes, the plan " << axes_;
            fail(m.str());
        }
        if (s.state != static_cast<unsigned>(wanted)) {
            m << "device is " << device_state_name(s.state) << fault_suffix(s.state, s.fault_code);
            if (wanted == device::DeviceState::kIdle) {
                m << ", not idle: reset or stop it first";
            } else {
                m << ", not holding the job";
            }
            fail(m.str());
        }
        for (unsigned a = 0; a < axes_ && check_start; ++a) {
            if (s.position[a] != start_[a]) {
                std::int32_t rest[8] = {};
                for (unsigned b = 0; b < axes_; ++b) rest[b] = s.position[b];
                m << "device rests at " << position_text(profile_, rest, axes_)
                  << " but the plan starts at " << position_text(profile_, start_, axes_)
                  << " (stream without --no-lead-in moves there pen up first)";
                fail(m.str());
            }
        }
        start_ticks_ = s.ticks_executed;
    }

    void configure() {
        std::vector<std::uint16_t> r(mb::config_registers(axes_), 0);
        const DeviceLimitsLsb l = limits_or_fail();
        r[0] = static_cast<std::uint16_t>(l.tick_hz >> 16);
        r[1] = static_cast<std::uint16_t>(l.tick_hz & 0xFFFFu);
        r[2] = static_cast<std::uint16_t>(axes_);
        r[mb::kConfigPenDownTicks] = static_cast<std::uint16_t>(l.pen_down_ticks);
        for (unsigned a = 0; a < axes_; ++a) {
            const std::uint32_t vv = l.max_velocity[a], aa = l.max_acceleration[a];
            r[mb::kConfigAxisBase + 4 * a] = static_cast<std::uint16_t>(vv >> 16);
            r[mb::kConfigAxisBase + 4 * a + 1] = static_cast<std::uint16_t>(vv & 0xFFFFu);
            r[mb::kConfigAxisBase + 4 * a + 2] = static_cast<std::uint16_t>(aa >> 16);
            r[mb::kConfigAxisBase + 4 * a + 3] = static_cast<std::uint16_t>(aa & 0xFFFFu);
            const std::uint16_t t = mb::config_travel_register(axes_, a);
            const auto lo = static_cast<std::uint32_t>(l.min_position[a]);
            const auto hi = static_cast<std::uint32_t>(l.max_position[a]);
            r[t] = static_cast<std::uint16_t>(lo >> 16);
            r[t + 1] = static_cast<std::uint16_t>(lo & 0xFFFFu);
            r[t + 2] = static_cast<std::uint16_t>(hi >> 16);
            r[t + 3] = static_cast<std::uint16_t>(hi & 0xFFFFu);
            const std::uint16_t j = mb::config_jerk_register(axes_, a);
            r[j] = static_cast<std::uint16_t>(l.max_jerk[a] >> 16);
            r[j + 1] = static_cast<std::uint16_t>(l.max_jerk[a] & 0xFFFFu);
        }
        try {
            link_.transact([&] { link_.client().write_registers(mb::kConfig, r); });
        } catch (const hal::ModbusError& e) {
            fail(std::string("device refused the configuration (tick rate and limits): ") +
                 e.what() + refusal());
        }
        configured_ = true;
    }

    // Why the device refused, from its status block; a device that restarted since the last
    // acknowledgement refuses everything (it is unconfigured), so that is reported instead.
    std::string refusal() {
        DeviceStatus s;
        try {
            s = read_status();
        } catch (const std::exception&) {
            return "";
        }
        check_restart(s);
        return std::string(" [device: ") + status_name(static_cast<Status>(s.last_refusal)) + "]";
    }

    void command(device::Command c, bool tolerate_refusal) {
        try {
            link_.write_command(c);
        } catch (const hal::ModbusError& e) {
            if (!tolerate_refusal)
                fail(std::string("device refused command ") + std::to_string(static_cast<int>(c)) +
                     ": " + e.what() + refusal());
        }
    }

    // The job's first span (planning may still run): where the device must rest.
    void encode_plan() {
        feed_.wait_first();
        axes_ = feed_.axes();
        for (unsigned a = 0; a < axes_; ++a) start_[a] = feed_.start()[a];
    }

    // Every span of the job is sent (the supply ended and the last one is encoded).
    bool all_sent(std::size_t next) const { return feed_.complete() && next == feed_.count(); }

    // Ticks of motion sent but not yet executed, exact: the device counts path ticks.
    std::uint64_t queued_ticks(const DeviceStatus& s, std::size_t sent) const {
        const std::uint64_t done = static_cast<std::uint32_t>(s.ticks_executed - start_ticks_);
        const std::uint64_t sent_ticks = feed_.ticks_before(sent);
        return done >= sent_ticks ? 0 : sent_ticks - done;
    }

    DeviceStatus send_batch(std::size_t& next, std::uint16_t free_slots) {
        const std::size_t max_bytes = 2u * mb::kMaxPayloadRegistersFc23;
        const std::size_t max_spans = std::min<std::size_t>(batch_limit_, free_slots);
        std::vector<std::uint8_t> payload;
        std::size_t count = 0;
        while (count < max_spans && feed_.sendable(next + count) &&
               payload.size() + feed_.bytes(next + count).size() <= max_bytes) {
            const std::vector<std::uint8_t>& span = feed_.bytes(next + count);
            payload.insert(payload.end(), span.begin(), span.end());
            ++count;
        }
        const std::uint32_t first = base_ + static_cast<std::uint32_t>(next);
        std::vector<std::uint16_t> window = {
            static_cast<std::uint16_t>(first >> 16), static_cast<std::uint16_t>(first & 0xFFFFu),
            static_cast<std::uint16_t>(count), static_cast<std::uint16_t>(payload.size()),
            device::crc16_modbus(payload.data(), payload.size())};
        for (std::size_t i = 0; i < payload.size(); i += 2) {
            const std::uint16_t low = i + 1 < payload.size() ? payload[i + 1] : 0;
            window.push_back(static_cast<std::uint16_t>((payload[i] << 8) | low));
        }
        std::uint16_t r[st::kStreamingCount];
        const std::uint32_t last = first + static_cast<std::uint32_t>(count) - 1;
        const std::uint64_t retries_before = link_.client().counters().retries;
        try {
            link_.client().write_read_registers(mb::kSpanWindow, window, 0,
                                                std::span<std::uint16_t>(r, st::kStreamingCount));
        } catch (const hal::ModbusError& e) {
            if (e.exception_code() == static_cast<std::uint8_t>(mb::Exception::kServerDeviceBusy)) {
                return read_status();  // queue fuller than we knew: send later
            }
            if (!e.transient()) {
                // A queue dropped under the stream, or about to be (another client's stop: the
                // device refuses batches while it stops), refuses the next batch, which no longer
                // joins what the device holds: the loop then says what happened.
                const DeviceStatus now = read_status();
                if (now.epoch != job_epoch_ ||
                    now.state == static_cast<std::uint16_t>(device::DeviceState::kStopping)) {
                    return now;
                }
                std::ostringstream m;
                m << "device refused spans " << first << ".." << last << ": " << e.what()
                  << refusal();
                fail(m.str());
            }
            // The batch may or may not have been applied (a lost response). Resend nothing
            // blind: ask the device what it accepted, and try smaller batches, which a noisy
            // line lets through far more often (each byte is a chance to lose the frame).
            shrink_batches(count);
            const double silent =
                std::chrono::duration<double>(Clock::now() - last_batch_ok_).count();
            if (silent > options_.link_timeout_seconds) {
                std::ostringstream m;
                m << "no batch got through for " << std::lround(silent) << " s (" << e.what()
                  << ")";
                fail(m.str());
            }
            const DeviceStatus s = read_status();
            check_restart(s);
            if (s.last_accepted == last) {  // applied: only the response was lost
                batch_done(next, count, last);
            }
            return s;
        }
        link_.mark_alive();
        last_batch_ok_ = Clock::now();
        if (link_.client().counters().retries != retries_before) {
            shrink_batches(count);
        } else if (++clean_batches_ >= kCleanBatchesToGrow &&
                   batch_limit_ < device::kMaxBatchSpans) {
            batch_limit_ = std::min<std::size_t>(device::kMaxBatchSpans, 2 * batch_limit_);
            clean_batches_ = 0;
        }
        batch_done(next, count, last);
        return parse_modbus_status(r, st::kStreamingCount);
    }

    void batch_done(std::size_t& next, std::size_t count, std::uint32_t last) {
        next += count;
        feed_.release_before(next);  // acknowledged: never sent again
        ++report_.batches;
        report_.spans_sent += count;
        acknowledged_ = last;
    }

    // After a batch that needed a retry: at most half as many spans per batch from now on.
    void shrink_batches(std::size_t count) {
        batch_limit_ = std::max<std::size_t>(1, std::min(batch_limit_, count) / 2);
        clean_batches_ = 0;
    }

    // How long to wait before the next status poll. While more than the lead is queued, sleep
    // until the device should have worked it down to the lead (at its observed tick rate), but
    // never more than half the queued motion: polling every poll_interval_ms instead would
    // fill a serial line with status reads (bench_modbus: ~35 % of 115200 baud at 2 ms).
    // `predicted` tells whether the wait ends when the lead should be at the target (not at
    // the half-lead cap or the minimum).
    std::chrono::microseconds poll_wait(std::uint64_t lead, std::uint64_t lead_target, bool started,
                                        bool& predicted) const {
        const double minimum = options_.poll_interval_ms * 1e-3;
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

    // The device's tick rate as observed between polls (a simulated device may run faster
    // than its configured rate); starts at the configured rate.
    void observe_rate(const DeviceStatus& s, bool started) {
        const auto now = Clock::now();
        const double dt = std::chrono::duration<double>(now - rate_time_).count();
        if (!started || s.state != static_cast<std::uint16_t>(device::DeviceState::kRunning) ||
            s.ticks_executed < rate_ticks_) {
            rate_time_ = now;
            rate_ticks_ = s.ticks_executed;
            return;
        }
        if (dt < 0.02) return;
        const double observed = static_cast<double>(s.ticks_executed - rate_ticks_) / dt;
        if (observed > 0)
            rate_ = std::max(rate_, observed);  // never assume slower than seen: no underrun
        rate_time_ = now;
        rate_ticks_ = s.ticks_executed;
    }

    // A device whose sequence or tick count went backwards lost its queue: it restarted.
    void check_restart(const DeviceStatus& s) const {
        if (s.magic != mb::kMagic) fail("status block lost its magic number: not the same device");
        if (s.last_accepted < acknowledged_ || s.ticks_executed < start_ticks_ ||
            (configured_ && (s.flags & 1u) == 0)) {
            std::ostringstream m;
            m << "device restarted mid-stream (it reports sequence " << s.last_accepted << " and "
              << s.ticks_executed << " ticks" << ((s.flags & 1u) == 0 ? ", unconfigured" : "")
              << "; it had acknowledged " << acknowledged_
              << "): stopping; the drawing is incomplete, restart it from the beginning";
            fail(m.str());
        }
    }

    void check_running(const DeviceStatus& s, bool started) {
        std::ostringstream m;
        check_restart(s);
        if (s.state == static_cast<std::uint16_t>(device::DeviceState::kFault) ||
            s.state == static_cast<std::uint16_t>(device::DeviceState::kEstop)) {
            m << "device stopped in " << device_state_name(s.state)
              << fault_suffix(s.state, s.fault_code) << " after " << s.last_completed << " spans";
            fail(m.str());
        }
        // The device applies a start at its next tick: idle right after the acknowledged start
        // is the start still pending, not a stop, until it has been seen running or has had
        // ample time (half a second) to tick.
        if (started && s.state != static_cast<std::uint16_t>(device::DeviceState::kIdle))
            seen_running_ = true;
        const bool start_pending =
            !seen_running_ &&
            std::chrono::duration<double>(Clock::now() - started_at_).count() < 0.5;
        if (started && s.state == static_cast<std::uint16_t>(device::DeviceState::kIdle) &&
            !job_finished(s) && !start_pending) {
            m << "device went idle after span " << s.last_completed
              << " (stopped by another master?)";
            fail(m.str());
        }
    }

    // Our job (its id: the sequence number of its first span) ran to its end: the device idles
    // at the plan's end point.
    bool job_finished(const DeviceStatus& s) const {
        return s.state == static_cast<std::uint16_t>(device::DeviceState::kIdle) &&
               s.finished_job == base_;
    }

    WireFeed feed_;
    const MachineProfile& profile_;
    const StreamOptions& options_;
    ModbusLink link_;
    unsigned axes_ = 0;
    std::int32_t start_[8] = {};
    std::uint32_t base_ = 1;
    std::uint32_t job_epoch_ = 0;
    std::uint32_t underruns_at_start_ = 0;
    std::uint32_t acknowledged_ = 0;
    std::uint32_t start_ticks_ = 0;
    Clock::time_point started_at_;
    bool seen_running_ = false;
    bool configured_ = false;  // the device accepted our configuration: it must stay configured
    // Adaptive batch size: halved after a batch that needed a retry, doubled after
    // kCleanBatchesToGrow clean ones (a clean link stays at the largest batch).
    static constexpr unsigned kCleanBatchesToGrow = 16;
    std::size_t batch_limit_ = device::kMaxBatchSpans;
    unsigned clean_batches_ = 0;
    Clock::time_point last_batch_ok_ = Clock::now();
    double rate_ = 0;  // device ticks per second, for poll_wait (set from the profile in run)
    Clock::time_point rate_time_ = Clock::now();
    std::uint32_t rate_ticks_ = 0;
    StreamReport report_;
};

}  // namespace

std::vector<Lsb> modbus_rest_position(const MachineProfile& profile, const StreamOptions& options) {
    const Plan none;
    PlanSupply supply(none);
    Streamer s(supply, profile, options);
    return s.rest_position();
}

StreamReport stream_modbus(const Plan& plan, const MachineProfile& profile,
                           const StreamOptions& options, const StreamProgress& progress) {
    PlanSupply supply(plan);
    Streamer s(supply, profile, options);
    return s.run(plan_progress(progress));
}

StreamReport stream_modbus(SpanSupply& supply, const MachineProfile& profile,
                           const StreamOptions& options, const SupplyProgress& progress) {
    Streamer s(supply, profile, options);
    return s.run(progress);
}

}  // namespace pathstream::host
