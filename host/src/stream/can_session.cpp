// The native CAN bus session: what SpanStreamer asks of a device, in frames.
#include "can_session.hpp"

#include <sstream>

#include "pathstream/device/motion_device.hpp"
#include "pathstream/status.hpp"

namespace pathstream::host {

void CanSession::check_protocol(const DeviceSnapshot& s) const {
    if (s.version != pc::kProtocolVersion) {
        std::ostringstream m;
        m << "device speaks native CAN protocol version " << s.version << ", this host "
          << unsigned(pc::kProtocolVersion);
        fail(m.str());
    }
}

// Every item is sent, then the ack of the last one answers for all (an incomplete set is
// nacked and sent again).
std::optional<std::string> CanSession::configure(const DeviceLimitsLsb& l, unsigned axes) {
    const std::uint8_t node = options_.node;
    const auto n = static_cast<std::uint8_t>(axes);
    std::vector<pc::Frame> frames{pc::encode_config(node, 0, n, l.tick_hz)};
    for (unsigned a = 0; a < axes; ++a) {
        frames.push_back(
            pc::encode_config(node, pc::config_item_velocity(a), n, l.max_velocity[a]));
        frames.push_back(
            pc::encode_config(node, pc::config_item_acceleration(a), n, l.max_acceleration[a]));
        frames.push_back(pc::encode_config(node, pc::config_item_min_position(a), n,
                                           static_cast<std::uint32_t>(l.min_position[a])));
        frames.push_back(pc::encode_config(node, pc::config_item_max_position(a), n,
                                           static_cast<std::uint32_t>(l.max_position[a])));
        frames.push_back(pc::encode_config(node, pc::config_item_jerk(a), n, l.max_jerk[a]));
    }
    frames.push_back(pc::encode_config(node, pc::kConfigItemPenDown, n, l.pen_down_ticks));
    while (true) {
        for (const pc::Frame& f : frames) link_.send(f);
        pc::Ack ack;
        if (!link_.wait_ack(pc::kAckConfig, pc::kConfigItemPenDown, ack)) continue;
        if (ack.result == pc::kResultIncomplete) continue;  // a configuration frame was lost
        if (ack.result != 0) return can_result_name(ack.result);
        return std::nullopt;
    }
}

std::optional<std::string> CanSession::command(device::Command c) {
    const std::uint8_t result = link_.command(static_cast<std::uint8_t>(c));
    if (result == 0) return std::nullopt;
    return can_result_name(result);
}

// Stop-and-wait: the span-start frame and the data frames, again until the device acks or
// refuses them (a lost frame or a lost ack looks the same: a timeout).
BatchAnswer CanSession::send_batch(std::uint32_t first, std::size_t count,
                                   const std::vector<std::uint8_t>& payload) {
    pc::SpanStart start;
    start.first_sequence = first;
    start.count = static_cast<std::uint8_t>(count);
    start.length = static_cast<std::uint16_t>(payload.size());
    const std::size_t frames = pc::data_frames(payload.size());
    BatchAnswer answer;
    for (bool first_try = true;; first_try = false) {
        if (!first_try) ++counters_.retransmissions;
        link_.send(pc::encode_span_start(options_.node, start));
        for (std::size_t i = 0; i < frames; ++i) {
            link_.send(pc::encode_span_data(options_.node, static_cast<std::uint8_t>(i),
                                            payload.data(), payload.size()));
        }
        pc::Ack ack;
        if (!link_.wait_ack(pc::kAckSpans, first, ack)) continue;
        answer.free_slots = ack.free_slots;
        if (ack.result == pc::kResultIncomplete) {
            ++counters_.incomplete;
            continue;
        }
        if (ack.result == static_cast<std::uint8_t>(Status::kQueueFull)) {
            answer.kind = BatchAnswer::Kind::kLater;  // never expected: slots are counted
        } else if (ack.result != 0) {
            answer.kind = BatchAnswer::Kind::kRefused;
            answer.reason = can_result_name(ack.result);
            if (ack.result == static_cast<std::uint8_t>(Status::kBadSequence)) {
                answer.reason += " (it restarted, or another master streams to node " +
                                 std::to_string(unsigned(options_.node)) + ")";
            }
        }
        return answer;
    }
}

}  // namespace pathstream::host
