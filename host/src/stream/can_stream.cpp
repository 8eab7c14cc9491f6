// The native CAN streaming client: plan -> wire spans -> sequenced batches, each a span-start
// frame and 7-byte data frames, stop-and-wait per batch (the device acks or nacks it), flow
// control from the acks and status frames (docs/can.md).
#include "pathstream/host/can_stream.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <vector>

#include "can_link.hpp"
#include "pathstream/device/can_protocol.hpp"
#include "pathstream/device/motion_device.hpp"
#include "pathstream/device/wire_span.hpp"
#include "pathstream/host/device_link.hpp"
#include "pathstream/machine/device_setup.hpp"
#include "pathstream/host/wire_plan.hpp"
#include "pathstream/status.hpp"
#include "stream_interrupt.hpp"
#include "wire_feed.hpp"

namespace pathstream::host {
namespace {

namespace pc = device::can;
using Clock = std::chrono::steady_clock;

class CanStreamer {
public:
    CanStreamer(SpanSupply& supply, const MachineProfile& profile, hal::CanBus& bus,
                const CanStreamOptions& options)
        : feed_(supply),
          profile_(profile),
          options_(options),
          node_(options.node),
          link_(bus, options, report_) {}

    /// Identity and state checked, the device's rest position (LSB per axis, status E).
    std::vector<Lsb> rest_position() {
        link_.mark_alive();
        axes_ = static_cast<unsigned>(profile_.axes.size());
        const pc::Status3 s = link_.request_status();
        check_identity(s, false);
        return std::vector<Lsb>(s.position, s.position + axes_);
    }

    CanStreamReport run(const SupplyProgress& progress) {
        const auto wall_start = Clock::now();
        link_.mark_alive();
        encode_plan();
        pc::Status3 s = link_.request_status();
        std::size_t next = 0;
        if (options_.held != nullptr) {
            next = continue_held(s);
        } else {
            check_identity(s);
            configure();
            base_ = s.last_accepted + 1;
            acknowledged_ = s.last_accepted;
        }
        free_slots_ = s.free_slots;
        // The queue epoch the job lives in (low 16 bits): a change this stream did not ask for
        // is a stop, fault or e-stop from elsewhere.
        job_epoch_ = s.epoch;
        underruns_at_start_ = s.underruns;
        // A held job goes on with a resume (the device's own re-entry) instead of a start.
        const device::Command go =
            options_.held != nullptr ? device::Command::kResume : device::Command::kStart;
        const auto lead_target =
            static_cast<std::uint64_t>(std::ceil(options_.lead_seconds * profile_.tick_hz));
        bool started = false;
        StreamInterrupt interrupt(options_.interrupt);
        PauseWatch pauses(options_.interrupt, feed_.pauses());
        while (true) {
            if (feed_.error()) interrupt.force_hold();
            const StreamInterrupt::Action action = interrupt.next_action(started);
            if (action == StreamInterrupt::Action::kHold)
                command(static_cast<std::uint8_t>(device::Command::kHold), true);
            if (action == StreamInterrupt::Action::kStop)
                command(static_cast<std::uint8_t>(device::Command::kStop), true);
            const std::uint64_t lead = queued_ticks(s, next);
            if (!interrupt.active() && free_slots_ > 0 && (lead < lead_target || !started) &&
                s.state != static_cast<std::uint8_t>(device::DeviceState::kStopping) &&
                feed_.sendable(next)) {
                send_batch(next);
                // Flow control: never more than the device's free slots, as last reported.
                s.last_accepted = acknowledged_;
            } else {
                std::this_thread::sleep_for(std::chrono::milliseconds(options_.poll_interval_ms));
                s = link_.request_status();
                free_slots_ = s.free_slots;
                observe(s, interrupt);
                if (!interrupt.stop_sent() && s.epoch != job_epoch_ &&
                    s.state == static_cast<std::uint8_t>(device::DeviceState::kIdle) &&
                    !job_finished(s)) {
                    report_.interrupted =
                        2;  // dropped by another client's stop: report it as a stop
                    report_.stopped_elsewhere = true;
                    break;
                }
                check_running(s, started && !interrupt.stop_sent());
            }
            if (!started && !interrupt.active() &&
                (queued_ticks(s, next) >= lead_target || all_sent(next))) {
                command(static_cast<std::uint8_t>(go), false);
                started = true;
                started_at_ = Clock::now();
            }
            if (!interrupt.active() &&
                s.state == static_cast<std::uint8_t>(device::DeviceState::kHolding) &&
                (s.flags & pc::kFlagHeldByUnderrun) != 0 && s.queued > 0) {
                command(static_cast<std::uint8_t>(device::Command::kResume), true);
            }
            if (pauses.observe(snapshot_of(s), s.ticks_executed - start_ticks_) &&
                !interrupt.active()) {
                command(static_cast<std::uint8_t>(device::Command::kResume), true);
            }
            if (progress) {
                progress(static_cast<std::uint32_t>(s.ticks_executed - start_ticks_),
                         feed_.total_ticks(),
                         static_cast<double>(queued_ticks(s, next)) / profile_.tick_hz);
            }
            feed_.release_before(
                std::min(next, completed_count(s)));  // executed: never needed again
            // The plan is one job (its last span marks the end): done when the device reports
            // it finished, idle at its end point.
            if (job_finished(s)) break;
            if (interrupt.active() && interrupt.settled(snapshot_of(s))) {
                report_.interrupted = interrupt.outcome();
                break;
            }
        }
        if (feed_.error()) {
            // The plan failed while the job ran: the device holds at rest (or never started);
            // drop the rest of its queue, then report the plan's error.
            command(static_cast<std::uint8_t>(device::Command::kStop), true);
            const auto deadline = Clock::now() + std::chrono::duration<double>(
                                                     options_.interrupt.hold_timeout_seconds);
            while (s.state != static_cast<std::uint8_t>(device::DeviceState::kIdle) &&
                   Clock::now() < deadline) {
                std::this_thread::sleep_for(std::chrono::milliseconds(options_.poll_interval_ms));
                s = link_.request_status();
            }
            std::rethrow_exception(feed_.error());
        }
        report_.final_status = snapshot_of(s);
        report_.ticks_executed = s.finished_job_ticks;
        report_.job = report_.interrupted != 0 ? base_ : s.finished_job;
        report_.last_completed = s.last_completed - base_ + 1;
        report_.duplicates = s.duplicates;
        // This job's underruns: the device counts since it started (16 bits on the bus).
        report_.underruns = static_cast<std::uint16_t>(s.underruns - underruns_at_start_);
        for (unsigned a = 0; a < axes_; ++a) report_.final_position[a] = feed_.end()[a];
        report_.wall_seconds = std::chrono::duration<double>(Clock::now() - wall_start).count();
        return report_;
    }

private:
    DeviceLimitsLsb limits_or_fail() const {
        try {
            return device_limits(profile_);
        } catch (const std::range_error& e) {
            fail(e.what());
        }
    }

    [[noreturn]] void fail(const std::string& what) const {
        throw StreamError(options_.name + ": " + what);
    }

    // A held job (docs/cli.md, "Interrupt and resume"): the device must hold it, configured,
    // with no span of it dropped; returns the index of the first span it has not accepted.
    std::size_t continue_held(const pc::Status3& s) {
        check_identity(s, false, device::DeviceState::kHolding);
        const HeldJob& h = *options_.held;
        if ((s.flags & pc::kFlagConfigured) == 0) {
            fail("device lost its configuration: it restarted; resume from its rest instead");
        }
        if (s.last_accepted < h.job || !feed_.available(s.last_accepted - h.job) ||
            s.last_completed + 1 < h.job) {
            std::ostringstream m;
            m << "device holds spans up to " << s.last_accepted << ", not job " << h.job << " of "
              << feed_.count() << " spans";
            fail(m.str());
        }
        base_ = h.job;
        acknowledged_ = s.last_accepted;
        const std::size_t completed = s.last_completed + 1 - h.job;
        start_ticks_ = s.ticks_executed - static_cast<std::uint32_t>(feed_.ticks_before(completed));
        return s.last_accepted + 1 - h.job;
    }

    void observe(const pc::Status3& s, const StreamInterrupt& interrupt) const {
        if (!options_.observer) return;
        StreamTrace t;
        t.job = base_;
        t.acknowledged = acknowledged_;
        t.status = snapshot_of(s);
        t.hold_requested = interrupt.hold_sent();
        t.stop_requested = interrupt.stop_sent();
        options_.observer(t);
    }

    void check_identity(const pc::Status3& s, bool check_start = true,
                        device::DeviceState wanted = device::DeviceState::kIdle) {
        std::ostringstream m;
        if (s.version != pc::kProtocolVersion) {
            m << "device speaks native CAN protocol version " << unsigned(s.version)
              << ", this host " << unsigned(pc::kProtocolVersion);
            fail(m.str());
        }
        if (s.axes != axes_) {
            m << "device has " << unsigned(s.axes) << " axes, the plan " << axes_;
            fail(m.str());
        }
        if (s.state != static_cast<std::uint8_t>(wanted)) {
            m << "device is " << device_state_name(s.state) << fault_suffix(s.state, s.fault_code);
            if (wanted == device::DeviceState::kIdle) {
                m << ", not idle: reset or stop it first";
            } else {
                m << ", not holding the job";
            }
            fail(m.str());
        }
        for (unsigned a = 0; a < axes_ && check_start; ++a) {
            if (s.position[a] != plan_start_[a]) {
                std::int32_t rest[8] = {};
                for (unsigned b = 0; b < axes_; ++b) rest[b] = s.position[b];
                m << "device rests at " << position_text(profile_, rest, axes_)
                  << " but the plan starts at " << position_text(profile_, plan_start_, axes_)
                  << " (stream without --no-lead-in moves there pen up first)";
                fail(m.str());
            }
        }
        start_ticks_ = s.ticks_executed;
    }

    void configure() {
        const DeviceLimitsLsb l = limits_or_fail();
        std::vector<pc::Frame> frames{
            pc::encode_config(node_, 0, static_cast<std::uint8_t>(axes_), l.tick_hz)};
        for (unsigned a = 0; a < axes_; ++a) {
            frames.push_back(pc::encode_config(node_, pc::config_item_velocity(a),
                                               static_cast<std::uint8_t>(axes_),
                                               l.max_velocity[a]));
            frames.push_back(pc::encode_config(node_, pc::config_item_acceleration(a),
                                               static_cast<std::uint8_t>(axes_),
                                               l.max_acceleration[a]));
            frames.push_back(pc::encode_config(node_, pc::config_item_min_position(a),
                                               static_cast<std::uint8_t>(axes_),
                                               static_cast<std::uint32_t>(l.min_position[a])));
            frames.push_back(pc::encode_config(node_, pc::config_item_max_position(a),
                                               static_cast<std::uint8_t>(axes_),
                                               static_cast<std::uint32_t>(l.max_position[a])));
            frames.push_back(pc::encode_config(node_, pc::config_item_jerk(a),
                                               static_cast<std::uint8_t>(axes_), l.max_jerk[a]));
        }
        frames.push_back(pc::encode_config(node_, pc::kConfigItemPenDown,
                                           static_cast<std::uint8_t>(axes_), l.pen_down_ticks));
        const std::uint8_t last_item = pc::kConfigItemPenDown;
        while (true) {
            for (const pc::Frame& f : frames) link_.send(f);
            pc::Ack ack;
            if (!link_.wait_ack(pc::kAckConfig, last_item, ack)) continue;
            if (ack.result == pc::kResultIncomplete) continue;  // a configuration frame was lost
            if (ack.result != 0)
                fail("device refused the configuration (tick rate and limits): " +
                     can_result_name(ack.result));
            return;
        }
    }

    void command(std::uint8_t c, bool tolerate_refusal) {
        const std::uint8_t result = link_.command(c);
        if (result != 0 && !tolerate_refusal) {
            fail("device refused command " + std::to_string(c) + ": " + can_result_name(result));
        }
    }

    void send_batch(std::size_t& next) {
        const std::size_t max_spans = std::min<std::size_t>(device::kMaxBatchSpans, free_slots_);
        std::vector<std::uint8_t> payload;
        std::size_t count = 0;
        while (count < max_spans && feed_.sendable(next + count) &&
               payload.size() + feed_.bytes(next + count).size() <= pc::kMaxTransferBytes) {
            const std::vector<std::uint8_t>& span = feed_.bytes(next + count);
            payload.insert(payload.end(), span.begin(), span.end());
            ++count;
        }
        const std::uint32_t first = base_ + static_cast<std::uint32_t>(next);
        pc::SpanStart start;
        start.first_sequence = first;
        start.count = static_cast<std::uint8_t>(count);
        start.length = static_cast<std::uint16_t>(payload.size());
        for (bool first_try = true;; first_try = false) {
            if (!first_try) ++report_.retransmissions;
            link_.send(pc::encode_span_start(node_, start));
            const std::size_t frames = pc::data_frames(payload.size());
            for (std::size_t i = 0; i < frames; ++i) {
                link_.send(pc::encode_span_data(node_, static_cast<std::uint8_t>(i), payload.data(),
                                                payload.size()));
            }
            pc::Ack ack;
            if (!link_.wait_ack(pc::kAckSpans, first, ack))
                continue;  // lost frames or a lost ack: again
            free_slots_ = ack.free_slots;
            if (ack.result == pc::kResultIncomplete) {
                ++report_.incomplete;
                continue;
            }
            if (ack.result == static_cast<std::uint8_t>(Status::kQueueFull))
                return;  // later (never expected)
            if (ack.result != 0) {
                // A queue dropped under the stream, or about to be (another client's stop: the
                // device refuses batches while it stops): the loop's next status reads say what
                // happened.
                const pc::Status3 now = link_.request_status();
                if (now.epoch != job_epoch_ ||
                    now.state == static_cast<std::uint8_t>(device::DeviceState::kStopping)) {
                    free_slots_ = 0;
                    return;
                }
                std::ostringstream m;
                m << "device refused spans " << first - base_ + 1 << ".." << first - base_ + count
                  << ": " << can_result_name(ack.result);
                if (ack.result == static_cast<std::uint8_t>(Status::kBadSequence)) {
                    m << " (it restarted, or another master streams to node " << unsigned(node_)
                      << ")";
                }
                fail(m.str());
            }
            next += count;
            ++report_.batches;
            report_.spans_sent += count;
            acknowledged_ = first + static_cast<std::uint32_t>(count) - 1;
            return;
        }
    }

    // ---- plan and bookkeeping ------------------------------------------------------------

    // The job's first span (planning may still run): where the device must rest.
    void encode_plan() {
        feed_.wait_first();
        axes_ = feed_.axes();
        for (unsigned a = 0; a < axes_; ++a) plan_start_[a] = feed_.start()[a];
    }

    // Every span of the job is sent (the supply ended and the last one is encoded).
    bool all_sent(std::size_t next) const { return feed_.complete() && next == feed_.count(); }

    // Spans of the job the device executed to their end.
    std::size_t completed_count(const pc::Status3& s) const {
        return s.last_completed >= base_ ? s.last_completed - base_ + 1 : 0;
    }

    std::uint64_t queued_ticks(const pc::Status3& s, std::size_t sent) const {
        const std::size_t done = completed_count(s);
        return done >= sent ? 0 : feed_.ticks_before(sent) - feed_.ticks_before(done);
    }

    // A device whose sequence or tick count went backwards, or that lost its configuration,
    // restarted: its queue is gone.
    void check_running(const pc::Status3& s, bool started) {
        std::ostringstream m;
        if (s.last_accepted < acknowledged_ || s.ticks_executed < start_ticks_ ||
            (s.flags & pc::kFlagConfigured) == 0) {
            m << "device restarted mid-stream (it reports sequence " << s.last_accepted << " and "
              << s.ticks_executed << " ticks; it had acknowledged " << acknowledged_
              << "): stopping; the drawing is incomplete, restart it from the beginning";
            fail(m.str());
        }
        if (s.state == static_cast<std::uint8_t>(device::DeviceState::kFault) ||
            s.state == static_cast<std::uint8_t>(device::DeviceState::kEstop)) {
            m << "device stopped in " << device_state_name(s.state)
              << fault_suffix(s.state, s.fault_code) << " after span "
              << (s.last_completed >= base_ ? s.last_completed - base_ + 1 : 0);
            fail(m.str());
        }
        // The device applies a start at its next tick: idle right after the acknowledged start
        // is the start still pending, not a stop, until it has been seen running or has had
        // ample time (half a second) to tick.
        if (started && s.state != static_cast<std::uint8_t>(device::DeviceState::kIdle))
            seen_running_ = true;
        const bool start_pending =
            !seen_running_ &&
            std::chrono::duration<double>(Clock::now() - started_at_).count() < 0.5;
        if (started && s.state == static_cast<std::uint8_t>(device::DeviceState::kIdle) &&
            !start_pending && !job_finished(s)) {
            m << "device went idle after span " << s.last_completed
              << " (stopped by another master?)";
            fail(m.str());
        }
    }

    // Our job (its id: the sequence number of its first span) ran to its end: the device idles
    // at the plan's end point.
    bool job_finished(const pc::Status3& s) const {
        return s.state == static_cast<std::uint8_t>(device::DeviceState::kIdle) &&
               s.finished_job == base_;
    }

    WireFeed feed_;
    const MachineProfile& profile_;
    const CanStreamOptions& options_;
    std::uint8_t node_;
    CanStreamReport report_;
    CanLink link_;
    unsigned axes_ = 0;
    std::uint32_t base_ = 1;
    std::uint16_t job_epoch_ = 0;
    std::uint32_t underruns_at_start_ = 0;
    std::uint32_t acknowledged_ = 0;
    std::uint32_t start_ticks_ = 0;
    std::int32_t plan_start_[8] = {};  // the plan's first point, LSB
    std::size_t free_slots_ = 0;
    Clock::time_point started_at_;
    bool seen_running_ = false;
};

}  // namespace

CanTarget parse_can_target(const std::string& url) {
    const std::string scheme = "can://";
    if (url.compare(0, scheme.size(), scheme) != 0)
        throw std::invalid_argument("not a can:// target: " + url);
    const std::string rest = url.substr(scheme.size());
    const auto q = rest.find('?');
    CanTarget t;
    t.interface_name = rest.substr(0, q);
    if (t.interface_name.empty())
        throw std::invalid_argument(url + ": no CAN interface (can://IFACE?node=N)");
    bool have_node = false;
    std::string query = q == std::string::npos ? "" : rest.substr(q + 1);
    std::istringstream in(query);
    std::string item;
    while (std::getline(in, item, '&')) {
        if (item.empty()) continue;
        const auto eq = item.find('=');
        const std::string key = item.substr(0, eq),
                          value = eq == std::string::npos ? "" : item.substr(eq + 1);
        if (key == "node") {
            std::size_t used = 0;
            int n = -1;
            try {
                n = std::stoi(value, &used);
            } catch (const std::exception&) {
                used = 0;
            }
            if (used != value.size() || value.empty() || n < pc::kMinNode || n > pc::kMaxNode) {
                throw std::invalid_argument(url + ": node must be 1..127, not '" + value + "'");
            }
            t.node = static_cast<std::uint8_t>(n);
            have_node = true;
        } else if (key == "protocol") {
            if (value != "native" && value != "cia402") {
                throw std::invalid_argument(url + ": protocol must be native or cia402, not '" +
                                            value + "'");
            }
            t.protocol = value;
        } else {
            throw std::invalid_argument(url + ": unknown parameter '" + key + "' (node, protocol)");
        }
    }
    if (!have_node) throw std::invalid_argument(url + ": node=N (1..127) missing");
    return t;
}

std::vector<Lsb> can_rest_position(const MachineProfile& profile, hal::CanBus& bus,
                                   const CanStreamOptions& options) {
    const Plan none;
    PlanSupply supply(none);
    CanStreamer s(supply, profile, bus, options);
    return s.rest_position();
}

CanStreamReport stream_can(const Plan& plan, const MachineProfile& profile, hal::CanBus& bus,
                           const CanStreamOptions& options, const StreamProgress& progress) {
    PlanSupply supply(plan);
    CanStreamer s(supply, profile, bus, options);
    return s.run(plan_progress(progress));
}

CanStreamReport stream_can(SpanSupply& supply, const MachineProfile& profile, hal::CanBus& bus,
                           const CanStreamOptions& options, const SupplyProgress& progress) {
    CanStreamer s(supply, profile, bus, options);
    return s.run(progress);
}

}  // namespace pathstream::host
