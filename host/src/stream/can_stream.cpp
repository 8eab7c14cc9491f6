// The native CAN streaming client: plan -> wire spans -> sequenced batches, each a span-start
// frame and 7-byte data frames, stop-and-wait per batch (the device acks or nacks it), flow
// control from the acks and status frames (docs/can.md).
#include "pathstream/host/can_stream.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <vector>

#include "pathstream/device/can_protocol.hpp"
#include "pathstream/device/motion_device.hpp"
#include "pathstream/device/wire_span.hpp"
#include "pathstream/host/device_setup.hpp"
#include "pathstream/host/wire_plan.hpp"
#include "pathstream/status.hpp"

namespace pathstream::host {
namespace {

namespace pc = device::can;
using Clock = std::chrono::steady_clock;

const char* state_name(std::uint8_t s) {
    static const char* const names[] = {"idle", "running", "holding", "stopping", "fault", "e-stop"};
    return s < 6 ? names[s] : "unknown";
}

std::string result_name(std::uint8_t r) {
    switch (r) {
        case pc::kResultIncomplete: return "incomplete transfer";
        case pc::kResultBadFrame: return "bad frame";
        case pc::kResultTooLong: return "batch too long";
        default: return status_name(static_cast<Status>(r));
    }
}

class CanStreamer {
public:
    CanStreamer(const Plan& plan, const MachineProfile& profile, hal::CanBus& bus, const CanStreamOptions& options)
        : plan_(plan), profile_(profile), bus_(bus), options_(options), node_(options.node) {
        if (node_ < pc::kMinNode || node_ > pc::kMaxNode) throw std::invalid_argument("CAN node id outside 1..127");
    }

    CanStreamReport run(const StreamProgress& progress) {
        const auto wall_start = Clock::now();
        last_heard_ = Clock::now();
        encode_plan();
        pc::Status3 s = request_status();
        check_identity(s);
        configure();
        base_ = s.last_accepted + 1;
        acknowledged_ = s.last_accepted;
        free_slots_ = s.free_slots;
        const auto lead_target =
            static_cast<std::uint64_t>(std::ceil(options_.lead_seconds * profile_.tick_hz));
        std::size_t next = 0;
        bool started = false;
        while (true) {
            const std::uint64_t lead = queued_ticks(s, next);
            if (next < spans_.size() && free_slots_ > 0 && (lead < lead_target || !started)) {
                send_batch(next);
                // Flow control: never more than the device's free slots, as last reported.
                s.last_accepted = acknowledged_;
            } else {
                std::this_thread::sleep_for(std::chrono::milliseconds(options_.poll_interval_ms));
                s = request_status();
                free_slots_ = s.free_slots;
                check_running(s, started);
            }
            if (!started && (queued_ticks(s, next) >= lead_target || next == spans_.size())) {
                command(static_cast<std::uint8_t>(device::Command::kStart), false);
                started = true;
                started_at_ = Clock::now();
            }
            if (s.state == static_cast<std::uint8_t>(device::DeviceState::kHolding) &&
                (s.flags & pc::kFlagHeldByUnderrun) != 0 && s.queued > 0) {
                command(static_cast<std::uint8_t>(device::Command::kResume), true);
            }
            if (progress) {
                progress(static_cast<double>(s.ticks_executed - start_ticks_) / static_cast<double>(plan_.total_ticks),
                         static_cast<double>(queued_ticks(s, next)) / profile_.tick_hz);
            }
            // The plan is one job (its last span marks the end): done when the device reports
            // it finished, idle at its end point.
            if (job_finished(s)) break;
        }
        report_.ticks_executed = s.finished_job_ticks;
        report_.job = s.finished_job;
        report_.last_completed = s.last_completed - base_ + 1;
        report_.duplicates = s.duplicates;
        report_.underruns = s.underruns;
        for (unsigned a = 0; a < axes_; ++a) report_.final_position[a] = plan_.spans.back().control[a][1];
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

    [[noreturn]] void fail(const std::string& what) const { throw StreamError(options_.name + ": " + what); }

    // ---- the bus -----------------------------------------------------------------------

    void send(const pc::Frame& f) {
        hal::CanFrame h;
        h.id = f.id;
        h.length = f.length;
        std::copy(f.data, f.data + 8, h.data);
        while (true) {
            const hal::CanSendResult r = bus_.send(h);
            if (r == hal::CanSendResult::kQueued) break;
            if (r == hal::CanSendResult::kBusOff) fail("the host's CAN controller is bus-off: stopping");
            if (r == hal::CanSendResult::kError) fail("the CAN interface refused a frame (down?)");
            // Queue full: let the controller drain; a dead bus shows up as the link timeout.
            check_link();
            hal::CanFrame in;
            if (bus_.receive(in, 200)) take(in);
        }
        ++report_.frames_sent;
        report_.bits_sent += pc::frame_bits_worst_case(f.length);
    }

    // Receives one frame from our node within `timeout_us`; false when none came.
    bool next_frame(pc::Frame& out, std::uint32_t timeout_us) {
        const auto deadline = Clock::now() + std::chrono::microseconds(timeout_us);
        while (true) {
            const auto left = std::chrono::duration_cast<std::chrono::microseconds>(deadline - Clock::now()).count();
            hal::CanFrame in;
            if (!bus_.receive(in, static_cast<std::uint32_t>(std::max<long long>(0, left)))) return false;
            if (take(in)) {
                out.id = in.id;
                out.length = in.length;
                std::copy(in.data, in.data + 8, out.data);
                return true;
            }
            if (Clock::now() >= deadline) return false;
        }
    }

    // True for a device -> host frame of our node (counted, and the link is alive).
    bool take(const hal::CanFrame& in) {
        if (in.extended || in.remote || pc::node_of(in.id) != node_) return false;
        const std::uint32_t f = pc::function_of(in.id);
        if (f != pc::kAckBase && f != pc::kStatusABase && f != pc::kStatusBBase &&
            f != pc::kStatusCBase && f != pc::kStatusDBase) {
            return false;
        }
        ++report_.frames_received;
        report_.bits_received += pc::frame_bits_worst_case(in.length);
        last_heard_ = Clock::now();
        return true;
    }

    void check_link() const {
        const double silent = std::chrono::duration<double>(Clock::now() - last_heard_).count();
        if (bus_.state() == hal::CanBusState::kBusOff) fail("the host's CAN controller is bus-off: stopping");
        if (silent > options_.link_timeout_seconds) {
            std::ostringstream m;
            m << "no answer from node " << unsigned(node_) << " for " << std::fixed;
            m.precision(1);
            m << silent << " s (device off the bus, bus-off, or not there): stopping; a device that was "
                           "running holds by itself";
            fail(m.str());
        }
    }

    std::uint32_t ack_timeout_us() const { return options_.ack_timeout_ms * 1000u; }

    // Waits for an ack of `kind` for `sequence`; false on timeout.
    bool wait_ack(std::uint8_t kind, std::uint32_t sequence, pc::Ack& ack) {
        const auto deadline = Clock::now() + std::chrono::microseconds(ack_timeout_us());
        while (Clock::now() < deadline) {
            pc::Frame f;
            const auto left = std::chrono::duration_cast<std::chrono::microseconds>(deadline - Clock::now()).count();
            if (!next_frame(f, static_cast<std::uint32_t>(std::max<long long>(0, left)))) break;
            if (pc::function_of(f.id) != pc::kAckBase || !pc::decode_ack(f, ack)) continue;
            if (ack.kind == kind && ack.sequence == sequence) return true;  // stale acks are ignored
        }
        ++report_.timeouts;
        check_link();
        return false;
    }

    // ---- protocol steps ------------------------------------------------------------------

    pc::Status3 request_status() {
        while (true) {
            send(pc::encode_command(node_, pc::kCommandStatusRequest));
            ++report_.status_requests;
            pc::Status3 s;
            unsigned seen = 0;
            const auto deadline = Clock::now() + std::chrono::microseconds(ack_timeout_us());
            constexpr unsigned kAll = (1u << pc::kStatusFrames) - 1u;
            while (seen != kAll && Clock::now() < deadline) {
                pc::Frame f;
                const auto left = std::chrono::duration_cast<std::chrono::microseconds>(deadline - Clock::now()).count();
                if (!next_frame(f, static_cast<std::uint32_t>(std::max<long long>(0, left)))) break;
                const std::uint32_t fn = pc::function_of(f.id);
                if (pc::decode_status_part(f, s)) {
                    seen |= fn == pc::kStatusABase   ? 1u
                            : fn == pc::kStatusBBase ? 2u
                            : fn == pc::kStatusCBase ? 4u
                                                     : 8u;
                }
            }
            if (seen == kAll) return s;
            ++report_.timeouts;
            check_link();
        }
    }

    void check_identity(const pc::Status3& s) {
        std::ostringstream m;
        if (s.version != pc::kProtocolVersion) {
            m << "device speaks native CAN protocol version " << unsigned(s.version) << ", this host "
              << unsigned(pc::kProtocolVersion);
            fail(m.str());
        }
        if (s.axes != axes_) {
            m << "device has " << unsigned(s.axes) << " axes, the plan " << axes_;
            fail(m.str());
        }
        if (s.state != 0) {
            m << "device is " << state_name(s.state) << fault_suffix(s.state, s.fault_code)
              << ", not idle: reset or stop it first";
            fail(m.str());
        }
        start_ticks_ = s.ticks_executed;
    }

    void configure() {
        const DeviceLimitsLsb l = limits_or_fail();
        std::vector<pc::Frame> frames{pc::encode_config(node_, 0, static_cast<std::uint8_t>(axes_), l.tick_hz)};
        for (unsigned a = 0; a < axes_; ++a) {
            frames.push_back(pc::encode_config(node_, pc::config_item_velocity(a), static_cast<std::uint8_t>(axes_),
                                               l.max_velocity[a]));
            frames.push_back(pc::encode_config(node_, pc::config_item_acceleration(a),
                                               static_cast<std::uint8_t>(axes_), l.max_acceleration[a]));
        }
        frames.push_back(pc::encode_config(node_, pc::kConfigItemPenDown,
                                           static_cast<std::uint8_t>(axes_), l.pen_down_ticks));
        const std::uint8_t last_item = pc::kConfigItemPenDown;
        while (true) {
            for (const pc::Frame& f : frames) send(f);
            pc::Ack ack;
            if (!wait_ack(pc::kAckConfig, last_item, ack)) continue;
            if (ack.result == pc::kResultIncomplete) continue;  // a configuration frame was lost
            if (ack.result != 0) fail("device refused the configuration (tick rate and limits): " + result_name(ack.result));
            return;
        }
    }

    void command(std::uint8_t c, bool tolerate_refusal) {
        while (true) {
            send(pc::encode_command(node_, c));
            pc::Ack ack;
            if (!wait_ack(pc::kAckCommand, c, ack)) continue;  // lost: commands are idempotent
            if (ack.result != 0 && !tolerate_refusal) {
                fail("device refused command " + std::to_string(c) + ": " + result_name(ack.result));
            }
            return;
        }
    }

    void send_batch(std::size_t& next) {
        const std::size_t max_spans =
            std::min<std::size_t>({device::kMaxBatchSpans, free_slots_, spans_.size() - next});
        std::vector<std::uint8_t> payload;
        std::size_t count = 0;
        while (count < max_spans && payload.size() + spans_[next + count].size() <= pc::kMaxTransferBytes) {
            payload.insert(payload.end(), spans_[next + count].begin(), spans_[next + count].end());
            ++count;
        }
        const std::uint32_t first = base_ + static_cast<std::uint32_t>(next);
        pc::SpanStart start;
        start.first_sequence = first;
        start.count = static_cast<std::uint8_t>(count);
        start.length = static_cast<std::uint16_t>(payload.size());
        for (bool first_try = true;; first_try = false) {
            if (!first_try) ++report_.retransmissions;
            send(pc::encode_span_start(node_, start));
            const std::size_t frames = pc::data_frames(payload.size());
            for (std::size_t i = 0; i < frames; ++i) {
                send(pc::encode_span_data(node_, static_cast<std::uint8_t>(i), payload.data(), payload.size()));
            }
            pc::Ack ack;
            if (!wait_ack(pc::kAckSpans, first, ack)) continue;  // lost frames or a lost ack: again
            free_slots_ = ack.free_slots;
            if (ack.result == pc::kResultIncomplete) {
                ++report_.incomplete;
                continue;
            }
            if (ack.result == static_cast<std::uint8_t>(Status::kQueueFull)) return;  // later (never expected)
            if (ack.result != 0) {
                std::ostringstream m;
                m << "device refused spans " << first - base_ + 1 << ".." << first - base_ + count << ": "
                  << result_name(ack.result);
                if (ack.result == static_cast<std::uint8_t>(Status::kBadSequence)) {
                    m << " (it restarted, or another master streams to node " << unsigned(node_) << ")";
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

    void encode_plan() {
        WirePlan w = encode_wire_plan(plan_);
        axes_ = w.axes;
        spans_ = std::move(w.spans);
        prefix_ticks_ = std::move(w.prefix_ticks);
    }

    std::uint64_t queued_ticks(const pc::Status3& s, std::size_t sent) const {
        const std::size_t done = s.last_completed >= base_ ? s.last_completed - base_ + 1 : 0;
        return done >= sent ? 0 : prefix_ticks_[sent] - prefix_ticks_[done];
    }

    // A device whose sequence or tick count went backwards, or that lost its configuration,
    // restarted: its queue is gone.
    void check_running(const pc::Status3& s, bool started) {
        std::ostringstream m;
        if (s.last_accepted < acknowledged_ || s.ticks_executed < start_ticks_ || (s.flags & pc::kFlagConfigured) == 0) {
            m << "device restarted mid-stream (it reports sequence " << s.last_accepted << " and " << s.ticks_executed
              << " ticks; it had acknowledged " << acknowledged_
              << "): stopping; the drawing is incomplete, restart it from the beginning";
            fail(m.str());
        }
        if (s.state == static_cast<std::uint8_t>(device::DeviceState::kFault) ||
            s.state == static_cast<std::uint8_t>(device::DeviceState::kEstop)) {
            m << "device stopped in " << state_name(s.state) << fault_suffix(s.state, s.fault_code) << " after span "
              << (s.last_completed >= base_ ? s.last_completed - base_ + 1 : 0);
            fail(m.str());
        }
        // The device applies a start at its next tick: idle right after the acknowledged start
        // is the start still pending, not a stop, until it has been seen running or has had
        // ample time (half a second) to tick.
        if (started && s.state != static_cast<std::uint8_t>(device::DeviceState::kIdle)) seen_running_ = true;
        const bool start_pending =
            !seen_running_ && std::chrono::duration<double>(Clock::now() - started_at_).count() < 0.5;
        if (started && s.state == static_cast<std::uint8_t>(device::DeviceState::kIdle) &&
            !start_pending && !job_finished(s)) {
            m << "device went idle after span " << s.last_completed << " (stopped by another master?)";
            fail(m.str());
        }
    }

    // Our job (its id: the sequence number of its first span) ran to its end: the device idles
    // at the plan's end point.
    bool job_finished(const pc::Status3& s) const {
        return s.state == static_cast<std::uint8_t>(device::DeviceState::kIdle) &&
               s.finished_job == base_;
    }

    const Plan& plan_;
    const MachineProfile& profile_;
    hal::CanBus& bus_;
    const CanStreamOptions& options_;
    std::uint8_t node_;
    Clock::time_point last_heard_;
    unsigned axes_ = 0;
    std::vector<std::vector<std::uint8_t>> spans_;
    std::vector<std::uint64_t> prefix_ticks_;
    std::uint32_t base_ = 1;
    std::uint32_t acknowledged_ = 0;
    std::uint32_t start_ticks_ = 0;
    std::size_t free_slots_ = 0;
    Clock::time_point started_at_;
    bool seen_running_ = false;
    CanStreamReport report_;
};

}  // namespace

CanTarget parse_can_target(const std::string& url) {
    const std::string scheme = "can://";
    if (url.compare(0, scheme.size(), scheme) != 0) throw std::invalid_argument("not a can:// target: " + url);
    const std::string rest = url.substr(scheme.size());
    const auto q = rest.find('?');
    CanTarget t;
    t.interface_name = rest.substr(0, q);
    if (t.interface_name.empty()) throw std::invalid_argument(url + ": no CAN interface (can://IFACE?node=N)");
    bool have_node = false;
    std::string query = q == std::string::npos ? "" : rest.substr(q + 1);
    std::istringstream in(query);
    std::string item;
    while (std::getline(in, item, '&')) {
        if (item.empty()) continue;
        const auto eq = item.find('=');
        const std::string key = item.substr(0, eq), value = eq == std::string::npos ? "" : item.substr(eq + 1);
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
                throw std::invalid_argument(url + ": protocol must be native or cia402, not '" + value + "'");
            }
            t.protocol = value;
        } else {
            throw std::invalid_argument(url + ": unknown parameter '" + key + "' (node, protocol)");
        }
    }
    if (!have_node) throw std::invalid_argument(url + ": node=N (1..127) missing");
    return t;
}

CanStreamReport stream_can(const Plan& plan, const MachineProfile& profile, hal::CanBus& bus,
                           const CanStreamOptions& options, const StreamProgress& progress) {
    CanStreamer s(plan, profile, bus, options);
    return s.run(progress);
}

}  // namespace pathstream::host
