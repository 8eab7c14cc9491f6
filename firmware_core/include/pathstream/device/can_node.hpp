// The device end of the native CAN protocol (can_protocol.hpp): assembles span batches from
// span-start and span-data frames and feeds MotionDevice::accept_batch (all or nothing,
// duplicates acknowledged, a resend with other bytes refused by the core), applies commands
// and the configuration, answers with acks and status frames. Freestanding: no heap, storage
// inline (the batch being received: 1792 bytes).
#pragma once

#include <cstddef>
#include <cstdint>

#include "pathstream/device/can_protocol.hpp"
#include "pathstream/device/motion_device.hpp"
#include "pathstream/device/operator_commands.hpp"
#include "pathstream/status.hpp"

namespace pathstream::device::can {

/// Serves node `node` over a MotionDevice<Axes, Capacity>. Task context only (the bus task);
/// the device's tick runs elsewhere as usual.
template <unsigned Axes, std::uint32_t Capacity>
class CanNode {
public:
    /// `node` must be kMinNode..kMaxNode (the caller checks it).
    CanNode(MotionDevice<Axes, Capacity>& device, std::uint8_t node)
        : device_(device), node_(node), operator_(device) {}

    /// Task loop: feeds a jog in progress (call at least once per span period).
    void service() { operator_.service(); }

    /// The commands with arguments (the port connects its homing here).
    OperatorCommands<Axes, Capacity>& operator_commands() { return operator_; }

    std::uint8_t node() const { return node_; }

    /// True when `id` is a host -> device frame addressed to this node (the receive filter).
    bool addressed(std::uint32_t id) const {
        if (node_of(id) != node_) return false;
        const std::uint32_t f = function_of(id);
        return f == kCommandBase || f == kConfigBase || f == kSpanStartBase || f == kSpanDataBase ||
               f == kCommandArgsBase;
    }

    /// Handles one received frame; calls `send(const Frame&)` for each answer (a status request is
    /// answered by 4 + Axes frames; anything else by 0 or 1). Frames for other nodes or functions
    /// are ignored; a frame claiming more than 8 data bytes is refused (kResultBadFrame, and a
    /// transfer in progress is dropped) whatever the driver filled in. Cost: a batch's accept_batch
    /// when its last data frame arrives, O(1) otherwise.
    template <typename Send>
    void handle(const Frame& f, Send&& send) {
        if (!addressed(f.id)) return;
        if (f.length > sizeof f.data) return refuse_oversized(f, send);
        switch (function_of(f.id)) {
            case kCommandBase:
                on_command(f, send);
                break;
            case kCommandArgsBase:
                on_command_args(f, send);
                break;
            case kConfigBase:
                on_config(f, send);
                break;
            case kSpanStartBase:
                on_span_start(f, send);
                break;
            case kSpanDataBase:
                on_span_data(f, send);
                break;
            default:
                break;
        }
    }

    /// Sends the status frames (A, B, C, D, then E for each axis), every tick-side value from
    /// one status read.
    template <typename Send>
    void send_status(Send&& send) const {
        const DeviceStatus<Axes> d = device_.status();
        Status3 s;
        s.state = static_cast<std::uint8_t>(d.state);
        s.flags = static_cast<std::uint8_t>(
            (device_.configured() ? kFlagConfigured : 0) |
            (d.held_by_underrun() ? kFlagHeldByUnderrun : 0) | (d.own_move() ? kFlagOwnMove : 0) |
            (d.paused() ? kFlagPaused : 0) | (operator_.homing() ? kFlagHoming : 0) |
            ((d.outputs & kOutputPenDown) != 0 ? kFlagPenDown : 0) |
            ((d.outputs & kOutputSpindle) != 0 ? kFlagSpindle : 0) |
            (bus_problem_ ? kFlagBusProblem : 0));
        s.free_slots = saturate8(device_.free_slots());
        s.queued = saturate8(device_.queued_spans());
        s.fault_code = static_cast<std::uint16_t>(d.fault_code);
        s.underruns = static_cast<std::uint16_t>(d.underruns);
        s.last_accepted = device_.last_accepted_sequence();
        s.last_completed = d.last_completed_sequence;
        s.ticks_executed = d.ticks_executed_low;
        s.duplicates = static_cast<std::uint16_t>(device_.duplicates());
        s.axes = static_cast<std::uint8_t>(Axes);
        s.version = kProtocolVersion;
        s.finished_job = d.finished_job;
        s.finished_job_ticks = d.finished_job_ticks;
        Frame out[kStatusFrames];
        encode_status(node_, s, out);
        for (const Frame& o : out) send(o);
        for (unsigned a = 0; a < Axes; ++a) {
            const HomingReport h = operator_.homing_report(a);
            const auto homing = static_cast<std::uint8_t>(static_cast<unsigned>(h.state) |
                                                          (static_cast<unsigned>(h.error) << 4));
            send(encode_status_axis(node_, static_cast<std::uint8_t>(a), d.position[a], d.epoch,
                                    homing));
        }
    }

    /// The bus went error-passive or bus-off: the link to the host may be gone, so a running
    /// device holds (a controlled stop; the host resumes once it hears from it again).
    void link_lost() {
        bus_problem_ = true;
        if (device_.state() == DeviceState::kRunning) (void)device_.command(Command::kHold);
    }

    /// Batches refused because a data frame was missing (the host resends them).
    std::uint32_t incomplete_transfers() const { return incomplete_; }
    /// Batches refused for any other reason (kQueueFull included): a correct host keeps it 0.
    std::uint32_t refused_batches() const { return refused_; }

private:
    static std::uint8_t saturate8(std::uint32_t v) {
        return static_cast<std::uint8_t>(v > 255 ? 255 : v);
    }

    template <typename Send>
    void ack(std::uint8_t kind, std::uint8_t result, std::uint32_t sequence, Send& send) const {
        Ack a;
        a.kind = kind;
        a.result = result;
        a.sequence = sequence;
        a.free_slots = saturate8(device_.free_slots());
        a.state = static_cast<std::uint8_t>(device_.state());
        send(encode_ack(node_, a));
    }

    // Never read past Frame::data: a corrupt length is the driver's or the bus's fault, so the
    // node answers it like any malformed frame of that function.
    template <typename Send>
    void refuse_oversized(const Frame& f, Send& send) {
        switch (function_of(f.id)) {
            case kConfigBase:
                config_seen_ = 0;
                return ack(kAckConfig, kResultBadFrame, 0, send);
            case kSpanStartBase:
            case kSpanDataBase: {
                const std::uint32_t sequence = active_ ? transfer_.first_sequence : 0;
                if (active_) ++refused_;
                active_ = false;
                return ack(kAckSpans, kResultBadFrame, sequence, send);
            }
            default:
                return ack(kAckCommand, kResultBadFrame, 0, send);
        }
    }

    template <typename Send>
    void on_command(const Frame& f, Send& send) {
        if (f.length < 1) return;
        const std::uint8_t c = f.data[0];
        if (c == kCommandStatusRequest) {
            send_status(send);
            return;
        }
        // Every value but the status request goes to the core, which refuses what is no command.
        const std::uint8_t result =
            static_cast<std::uint8_t>(device_.command(static_cast<Command>(c)));
        if (c == static_cast<std::uint8_t>(Command::kReset) && result == 0) bus_problem_ = false;
        ack(kAckCommand, result, c, send);
    }

    // Jog, set position, home or pen, answered like a command (ack kind 2, sequence = the
    // command).
    template <typename Send>
    void on_command_args(const Frame& f, Send& send) {
        CommandArgs c;
        if (!decode_command_args(f, c)) return ack(kAckCommand, kResultBadFrame, 0, send);
        OperatorCommand o;
        o.command = c.command;
        o.axis = c.axis;
        o.value = c.value;
        o.feed = c.feed;
        const Status s = operator_.execute(o);
        ack(kAckCommand, static_cast<std::uint8_t>(s), c.command, send);
    }

    template <typename Send>
    void on_config(const Frame& f, Send& send) {
        if (f.length != 6) return ack(kAckConfig, kResultBadFrame, 0, send);
        const std::uint8_t item = static_cast<std::uint8_t>(get(f, kConfigSignals[0]));
        const std::uint8_t axes = static_cast<std::uint8_t>(get(f, kConfigSignals[1]));
        const std::uint32_t value = get(f, kConfigSignals[2]);
        if (axes != Axes)
            return ack(kAckConfig, static_cast<std::uint8_t>(Status::kBadLimits), item, send);
        const bool travel_item =
            item >= config_item_min_position(0) && item < config_item_min_position(Axes);
        const bool jerk_item = item >= config_item_jerk(0) && item < config_item_jerk(Axes);
        if (item > 2 * Axes && item != kConfigItemPenDown && !travel_item && !jerk_item) {
            return ack(kAckConfig, kResultBadFrame, item, send);
        }
        if (item == 0) {
            config_seen_ = 0;
            pending_ = MotionLimits<Axes>{};  // travel and jerk items are optional: none
            pending_.tick_hz = value;
        } else if (item == kConfigItemPenDown) {
            pending_.pen_down_ticks = value;
        } else if (jerk_item) {
            pending_.axis[item - config_item_jerk(0)].max_jerk = value;
        } else if (travel_item) {
            const unsigned axis = (item - config_item_min_position(0)) / 2u;
            if ((item - config_item_min_position(0)) % 2u == 0) {
                pending_.axis[axis].min_position = static_cast<std::int32_t>(value);
            } else {
                pending_.axis[axis].max_position = static_cast<std::int32_t>(value);
            }
        } else if (item % 2 == 1) {
            pending_.axis[(item - 1) / 2].max_velocity = value;
        } else {
            pending_.axis[(item - 2) / 2].max_acceleration = value;
        }
        config_seen_ |= std::uint64_t{1} << item;
        // Items before the last (the pen-down delay) are not acknowledged: one ack per set.
        if (item != kConfigItemPenDown) return;
        const std::uint64_t all =
            ((std::uint64_t{1} << (2 * Axes + 1)) - 1u) | (std::uint64_t{1} << kConfigItemPenDown);
        const std::uint8_t result = (config_seen_ & all) == all
                                        ? static_cast<std::uint8_t>(device_.configure(pending_))
                                        : kResultIncomplete;
        config_seen_ = 0;
        ack(kAckConfig, result, item, send);
    }

    template <typename Send>
    void on_span_start(const Frame& f, Send& send) {
        SpanStart s;
        active_ = false;
        if (!decode_span_start(f, s)) return ack(kAckSpans, kResultBadFrame, 0, send);
        if (s.length > kMaxTransferBytes)
            return ack(kAckSpans, kResultTooLong, s.first_sequence, send);
        if (s.length == 0 || s.count == 0) {
            return ack(kAckSpans, static_cast<std::uint8_t>(Status::kBadBatch), s.first_sequence,
                       send);
        }
        transfer_ = s;
        received_ = 0;
        next_index_ = 0;
        active_ = true;
    }

    template <typename Send>
    void on_span_data(const Frame& f, Send& send) {
        if (!active_ || f.length < 2)
            return;  // no transfer (its start was lost): the host times out
        const std::uint8_t index = f.data[0];
        const std::size_t n = static_cast<std::size_t>(f.length) - 1;
        if (n > sizeof f.data - 1)
            return refuse_oversized(f, send);  // handle() checks too: keep local
        if (index != next_index_ || received_ + n > transfer_.length) {
            // A frame was lost: refuse now rather than let the host wait for its timeout.
            active_ = false;
            ++incomplete_;
            return ack(kAckSpans, kResultIncomplete, transfer_.first_sequence, send);
        }
        for (std::size_t i = 0; i < n; ++i) buffer_[received_ + i] = f.data[1 + i];
        received_ += n;
        ++next_index_;
        if (received_ < transfer_.length) return;
        active_ = false;
        const Status st =
            device_.accept_batch(transfer_.first_sequence, transfer_.count, buffer_, received_);
        if (st != Status::kOk) ++refused_;
        ack(kAckSpans, static_cast<std::uint8_t>(st), transfer_.first_sequence, send);
    }

    MotionDevice<Axes, Capacity>& device_;
    std::uint8_t node_;
    OperatorCommands<Axes, Capacity> operator_;
    MotionLimits<Axes> pending_{};
    std::uint64_t config_seen_ = 0;  // bit per configuration item received since item 0
    SpanStart transfer_{};
    bool active_ = false;
    std::size_t received_ = 0;
    std::uint8_t next_index_ = 0;
    std::uint32_t incomplete_ = 0;
    std::uint32_t refused_ = 0;
    bool bus_problem_ = false;
    std::uint8_t buffer_[kMaxTransferBytes] = {};
};

}  // namespace pathstream::device::can
