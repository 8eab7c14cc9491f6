// A stream's bus session over CAN with the native protocol (docs/can.md): status requests
// answered by frames A to E, configuration items, commands, and span batches as a span-start
// frame and 7-byte data frames, stop-and-wait, resent until the device acks them.
#pragma once

#include <cstddef>
#include <cstdint>

#include "bus_session.hpp"
#include "can_link.hpp"
#include "pathstream/host/can_stream.hpp"

namespace pathstream::host {

/// The BusSession of stream_can: node options.node on `bus`. Counts frames, bits, timeouts,
/// retransmissions and incomplete transfers into the report it is given.
class CanSession final : public BusSession {
public:
    /// Throws std::invalid_argument for a node outside 1..127.
    CanSession(hal::CanBus& bus, const CanStreamOptions& options, CanStreamReport& counters)
        : options_(options), counters_(counters), link_(bus, options, counters) {}

    const std::string& target_name() const override { return options_.name; }
    void mark_alive() override { link_.mark_alive(); }
    DeviceSnapshot read_status() override { return snapshot_of(link_.request_status()); }
    void check_protocol(const DeviceSnapshot& s) const override;
    std::optional<std::string> configure(const DeviceLimitsLsb& limits, unsigned axes) override;
    std::optional<std::string> command(device::Command c) override;
    std::size_t batch_span_limit() const override { return device::kMaxBatchSpans; }
    std::size_t batch_byte_limit() const override { return device::can::kMaxTransferBytes; }
    BatchAnswer send_batch(std::uint32_t first, std::size_t count,
                           const std::vector<std::uint8_t>& payload) override;
    bool batch_answers_with_status() const override { return false; }
    std::string refusal_note(const DeviceSnapshot&) const override { return ""; }

private:
    const CanStreamOptions& options_;
    CanStreamReport& counters_;
    CanLink link_;
};

}  // namespace pathstream::host
