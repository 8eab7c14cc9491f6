// A stream's bus session over Modbus TCP or RTU (docs/modbus.md): status block reads (FC4),
// configuration (FC16), the command register, and span batches that answer with the status
// (FC23), sized down on a noisy line and up again on a clean one.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>

#include "bus_session.hpp"
#include "modbus_link.hpp"
#include "pathstream/host/modbus_stream.hpp"

namespace pathstream::host {

/// The BusSession of stream_modbus. Connects in its constructor (retrying until the link
/// timeout).
class ModbusSession final : public BusSession {
public:
    explicit ModbusSession(const StreamOptions& options) : options_(options), link_(options) {}

    const std::string& target_name() const override { return options_.target; }
    void mark_alive() override;
    DeviceSnapshot read_status() override;
    void check_protocol(const DeviceSnapshot& s) const override;
    std::optional<std::string> configure(const DeviceLimitsLsb& limits, unsigned axes) override;
    std::optional<std::string> command(device::Command c) override;
    std::size_t batch_span_limit() const override { return batch_limit_; }
    std::size_t batch_byte_limit() const override;
    BatchAnswer send_batch(std::uint32_t first, std::size_t count,
                           const std::vector<std::uint8_t>& payload) override;
    bool batch_answers_with_status() const override { return true; }
    std::string refusal_note(const DeviceSnapshot& s) const override;

    /// The link's transaction counters and this session's status reads, into `report`.
    void count_into(StreamReport& report) const;

private:
    using Clock = std::chrono::steady_clock;
    void shrink_batches(std::size_t count);

    const StreamOptions& options_;
    ModbusLink link_;
    // Adaptive batch size: halved after a batch that needed a retry, doubled after
    // kCleanBatchesToGrow clean ones (a clean link stays at the largest batch).
    static constexpr unsigned kCleanBatchesToGrow = 16;
    std::size_t batch_limit_ = device::kMaxBatchSpans;
    unsigned clean_batches_ = 0;
    Clock::time_point last_batch_ok_ = Clock::now();
};

}  // namespace pathstream::host
