// hal::CanBus on a Linux SocketCAN interface (PF_CAN, SOCK_RAW, CAN_RAW): non-blocking sends,
// receive with a poll(2) timeout, error frames decoded into the fault confinement state,
// receive filters and counters. Used by `pathstream device --can` and `pathstream stream
// --target can://...`; tested in the real-kernel VM on vcan0 (docs/can.md, docs/vm.md).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "pathstream/hal/can_bus.hpp"

namespace pathstream::hal {

/// One receive filter: a frame passes when (frame id & mask) == (id & mask). `extended`
/// selects 29-bit identifiers (standard ones otherwise).
struct CanFilter {
    std::uint32_t id = 0;
    std::uint32_t mask = 0;
    bool extended = false;
};

/// What went over this socket.
struct SocketCanCounters {
    std::uint64_t frames_sent = 0;
    std::uint64_t frames_received = 0;  ///< data and remote frames returned by receive()
    std::uint64_t tx_queue_full = 0;    ///< sends refused with ENOBUFS/EAGAIN
    std::uint64_t error_frames = 0;
    std::uint64_t bus_off_events = 0;
    std::uint64_t restarts = 0;  ///< CAN_ERR_RESTARTED seen (controller back on the bus)
};

class SocketCanBus final : public CanBus {
public:
    /// Opens a raw CAN socket bound to interface `name` (e.g. "can0", "vcan0"), non-blocking,
    /// with error frames enabled (CAN_ERR_MASK) and, when `filters` is not empty, only those
    /// identifiers received. Throws std::system_error naming the interface when it does not
    /// exist, is not a CAN interface, or the socket cannot be set up.
    explicit SocketCanBus(const std::string& name, const std::vector<CanFilter>& filters = {});
    ~SocketCanBus() override;
    SocketCanBus(const SocketCanBus&) = delete;
    SocketCanBus& operator=(const SocketCanBus&) = delete;

    /// One write(2); ENOBUFS/EAGAIN -> kQueueFull (counted); bus-off -> kBusOff.
    CanSendResult send(const CanFrame& frame) override;
    /// poll(2) up to timeout_us, then reads frames; error frames update state() and are not
    /// returned (the wait continues with the time left).
    bool receive(CanFrame& out, std::uint32_t timeout_us) override;
    CanBusState state() const override { return state_; }

    /// Replaces the receive filters (empty: everything). Throws std::system_error.
    void set_filters(const std::vector<CanFilter>& filters);
    const SocketCanCounters& counters() const { return counters_; }
    const std::string& interface_name() const { return name_; }

private:
    void on_error_frame(std::uint32_t can_id, const std::uint8_t (&data)[8]);

    std::string name_;
    int fd_ = -1;
    CanBusState state_ = CanBusState::kErrorActive;
    SocketCanCounters counters_;
};

}  // namespace pathstream::hal
