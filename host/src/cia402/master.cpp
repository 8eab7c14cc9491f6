// The master's plumbing: frames in and out, the cycle exchange (RPDO1 per drive, then SYNC),
// the consumers (heartbeat, EMCY, TPDOs) and the health check every cycle runs.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <stdexcept>
#include <string>

#include "frame_bytes.hpp"
#include "pathstream/host/cia402_master.hpp"

namespace pathstream::host {

using namespace cia402;

const char* cia402_stop_name(Cia402Stop stop) {
    switch (stop) {
        case Cia402Stop::kNone:
            return "completed";
        case Cia402Stop::kDriveFault:
            return "drive fault";
        case Cia402Stop::kHeartbeatLost:
            return "heartbeat lost";
        case Cia402Stop::kFeedbackLost:
            return "feedback lost";
        case Cia402Stop::kDriveLeftOperation:
            return "drive left operation";
        case Cia402Stop::kStepLimit:
            return "step limit";
        case Cia402Stop::kBusOff:
            return "bus off";
        case Cia402Stop::kSettleTimeout:
            return "settle timeout";
    }
    return "unknown";
}

const char* cia402_feed_forward_name(Cia402FeedForward feed_forward) {
    switch (feed_forward) {
        case Cia402FeedForward::kNone:
            return "none";
        case Cia402FeedForward::kVelocity:
            return "velocity";
        case Cia402FeedForward::kTorque:
            return "torque";
    }
    return "unknown";
}

Cia402Master::Cia402Master(hal::CanBus& bus, hal::Clock& clock_us, Cia402Options options)
    : bus_(bus), clock_(clock_us), options_(std::move(options)) {
    if (options_.nodes.empty()) throw std::invalid_argument("CiA 402: no drive nodes given");
    std::set<std::uint8_t> seen;
    for (const std::uint8_t n : options_.nodes) {
        if (n < 1 || n > 127)
            throw std::invalid_argument("CiA 402: node id " + std::to_string(n) +
                                        " outside 1..127");
        if (!seen.insert(n).second)
            throw std::invalid_argument("CiA 402: node " + std::to_string(n) + " given twice");
        Cia402DriveView v;
        v.node = n;
        drives_.push_back(v);
    }
    if (options_.cycle_ms == 0 || options_.cycle_ms > 255)
        throw std::invalid_argument("CiA 402: cycle 1..255 ms");
    if (options_.sdo_attempts == 0)
        throw std::invalid_argument("CiA 402: sdo_attempts must be >= 1");
    const double k = options_.torque_per_acceleration;
    if (!std::isfinite(k) || k < 0)
        throw std::invalid_argument("CiA 402: torque per acceleration must be a number >= 0");
    if (options_.feed_forward == Cia402FeedForward::kTorque && k == 0) {
        throw std::invalid_argument(
            "CiA 402: torque feed-forward needs the axes' inertia (per mille of rated torque per "
            "LSB/s^2)");
    }
}

Cia402DriveView& Cia402Master::view(std::uint8_t node) {
    for (auto& d : drives_) {
        if (d.node == node) return d;
    }
    throw std::logic_error("CiA 402: unknown node");
}

void Cia402Master::send(const hal::CanFrame& frame) {
    const hal::CanSendResult r = bus_.send(frame);
    if (r == hal::CanSendResult::kQueued) {
        ++report_.frames_sent;
        return;
    }
    const std::string what = r == hal::CanSendResult::kBusOff ? "the CAN controller is bus-off"
                             : r == hal::CanSendResult::kQueueFull
                                 ? "the CAN transmit queue is full"
                                 : "the CAN interface refused a frame";
    // While cycling the loop must still stop the drives cleanly: record, let check_health act.
    if (cycling_) {
        send_failure_ = what;
        return;
    }
    throw Cia402Error("CiA 402: " + what);
}

void Cia402Master::nmt(NmtCommand command, std::uint8_t node) {
    hal::CanFrame f = make_frame(kNmtId, 2);
    f.data[0] = static_cast<std::uint8_t>(command);
    f.data[1] = node;
    send(f);
}

void Cia402Master::handle(const hal::CanFrame& f) {
    ++report_.frames_received;
    if (f.extended || f.remote) return;
    const std::uint32_t function = f.id & 0x780;
    const auto node = static_cast<std::uint8_t>(f.id & 0x7F);
    if (node == 0) return;               // NMT and SYNC from another master: not ours to read
    if (function == kSdoResponseBase) {  // any node may be asked, configured or not
        if (node == sdo_node_ && !sdo_done_ && f.length == 8) {
            sdo_response_ = f;
            sdo_done_ = true;
        }
        return;
    }
    Cia402DriveView* d = nullptr;
    for (auto& v : drives_) {
        if (v.node == node) d = &v;
    }
    if (d == nullptr) return;
    switch (function) {
        case kHeartbeatBase:
            if (f.length >= 1) {
                d->nmt = static_cast<NmtState>(f.data[0] & 0x7F);
                d->heartbeat_seen = true;
                d->last_heartbeat_us = clock_.now();
            }
            break;
        case kEmcyBase:
            if (f.length >= 2) {
                d->emcy_code = static_cast<std::uint16_t>(get_le(f, 0, 2));
                if (d->emcy_code != kEmcyNoError) {
                    d->emcy_pending = true;
                    if (report_.emcy_code == 0) {
                        report_.emcy_code = d->emcy_code;
                        report_.emcy_node = node;
                    }
                }
            }
            break;
        case kTpdo1Base:
            if (f.length >= 6) {
                d->statusword = static_cast<std::uint16_t>(get_le(f, 0, 2));
                d->position = static_cast<std::int32_t>(get_le(f, 2, 4));
                d->feedback_cycle = cycle_;
            }
            break;
        case kTpdo2Base:
            if (f.length >= 4) {
                d->demand = static_cast<std::int32_t>(get_le(f, 0, 4));
                d->demand_cycle = cycle_;
            }
            break;
        default:
            break;
    }
}

void Cia402Master::wait_until(std::uint64_t deadline_us) {
    hal::CanFrame f;
    for (;;) {
        const std::uint64_t now = clock_.now();
        if (now >= deadline_us) return;
        const std::uint64_t left = deadline_us - now;
        if (bus_.receive(f, static_cast<std::uint32_t>(std::min<std::uint64_t>(left, 0xFFFFFFFFu))))
            handle(f);
    }
}

void Cia402Master::exchange(const std::vector<std::uint16_t>& controlwords,
                            const std::vector<std::int32_t>& targets, const Offsets* offsets) {
    cycling_ = true;
    const std::uint64_t now = clock_.now();
    const std::uint64_t period = std::uint64_t{options_.cycle_ms} * 1000;
    // Absolute deadlines: a late cycle is not made up by a short one later, but lateness
    // does not accumulate either; a cycle more than one period late restarts the grid.
    if (next_deadline_ + period < now || next_deadline_ == 0) next_deadline_ = now;
    // RPDOs first: a synchronous RPDO is applied at the next SYNC, so the drive takes this
    // cycle's target at this cycle's SYNC.
    const bool torque = options_.feed_forward == Cia402FeedForward::kTorque;
    for (std::size_t i = 0; i < drives_.size(); ++i) {
        hal::CanFrame f = make_frame(kRpdo1Base + drives_[i].node, 6);
        put_le(f, 0, 2, controlwords[i]);
        put_le(f, 2, 4, static_cast<std::uint32_t>(targets[i]));
        send(f);
        if (options_.feed_forward == Cia402FeedForward::kNone) continue;
        // Zero offsets while enabling, holding or stopping: a drive keeps an offset until
        // told otherwise.
        hal::CanFrame o = make_frame(kRpdo2Base + drives_[i].node, torque ? 6 : 4);
        put_le(o, 0, 4, static_cast<std::uint32_t>(offsets ? offsets->velocity[i] : 0));
        if (torque) put_le(o, 4, 2, static_cast<std::uint16_t>(offsets ? offsets->torque[i] : 0));
        send(o);
    }
    send(make_frame(kSyncId, 0));
    ++cycle_;
    ++report_.cycles;
    next_deadline_ += period;
    wait_until(next_deadline_);
    for (auto& d : drives_) {
        if (d.feedback_cycle == cycle_) {
            d.missed_in_row = 0;
        } else {
            ++d.missed_in_row;
            ++report_.missed_feedback;
        }
    }
}

Cia402Stop Cia402Master::stop_with(Cia402Stop why, const std::string& message) {
    if (report_.stop == Cia402Stop::kNone) {
        report_.stop = why;
        report_.message = message;
    }
    return why;
}

Cia402Stop Cia402Master::check_health(bool moving) {
    if (!send_failure_.empty()) return stop_with(Cia402Stop::kBusOff, "CiA 402: " + send_failure_);
    if (bus_.state() == hal::CanBusState::kBusOff) {
        return stop_with(Cia402Stop::kBusOff, "CiA 402: the CAN controller is bus-off");
    }
    const std::uint64_t now = clock_.now();
    for (const auto& d : drives_) {
        const std::string who = "node " + std::to_string(d.node) + ": ";
        const DriveState s = d.state();
        if (d.emcy_pending || (d.feedback_cycle > 0 && (s == DriveState::kFault ||
                                                        s == DriveState::kFaultReactionActive))) {
            return stop_with(
                Cia402Stop::kDriveFault,
                who + "drive fault: " +
                    (d.emcy_pending ? emcy_text(d.emcy_code) : std::string("statusword fault")));
        }
        if (options_.heartbeat_ms > 0 && d.heartbeat_seen &&
            now - d.last_heartbeat_us > std::uint64_t{options_.heartbeat_timeout_ms} * 1000) {
            return stop_with(
                Cia402Stop::kHeartbeatLost,
                who + "no heartbeat for " + std::to_string((now - d.last_heartbeat_us) / 1000) +
                    " ms (timeout " + std::to_string(options_.heartbeat_timeout_ms) + " ms)");
        }
        if (d.heartbeat_seen && d.nmt != NmtState::kOperational) {
            return stop_with(Cia402Stop::kDriveLeftOperation,
                             who + "left NMT operational (heartbeat state 0x" +
                                 std::to_string(static_cast<int>(d.nmt)) + ")");
        }
        if (d.missed_in_row >= options_.max_missed_feedback) {
            return stop_with(Cia402Stop::kFeedbackLost,
                             who + "no TPDO1 for " + std::to_string(d.missed_in_row) + " cycles");
        }
        if (moving && d.feedback_cycle == cycle_ && s != DriveState::kOperationEnabled) {
            return stop_with(
                Cia402Stop::kDriveLeftOperation,
                who + "left operation enabled during motion (now " + drive_state_name(s) + ")");
        }
    }
    return Cia402Stop::kNone;
}

void Cia402Master::quick_stop(const std::vector<std::int32_t>& hold) {
    // Quick stop (not disable voltage): the drive brakes on its own quick stop ramp instead
    // of letting the axes coast, then goes to switch on disabled.
    if (bus_.state() == hal::CanBusState::kBusOff || !send_failure_.empty()) return;
    const std::vector<std::uint16_t> cws(drives_.size(), kCwQuickStop);
    const std::uint64_t deadline = clock_.now() + std::uint64_t{options_.enable_timeout_ms} * 1000;
    while (clock_.now() < deadline) {
        exchange(cws, hold);
        bool all_stopped = true;
        for (const auto& d : drives_) {
            const DriveState s = d.state();
            const bool silent = d.missed_in_row >= options_.max_missed_feedback;
            if (!silent &&
                (s == DriveState::kOperationEnabled || s == DriveState::kQuickStopActive))
                all_stopped = false;
        }
        if (all_stopped) return;
    }
}

}  // namespace pathstream::host
