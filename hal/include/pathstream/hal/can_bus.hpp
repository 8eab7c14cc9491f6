// A CAN 2.0 bus as the device loop and the host's masters see it: frames in, frames out, and
// the controller's error state. Backends: SocketCAN (hal/, Linux), an in-process loopback
// with fault injection (sim/), an MCU's CAN peripheral.
#pragma once

#include <cstdint>

namespace pathstream::hal {

/// One classic CAN frame (no CAN FD).
struct CanFrame {
    std::uint32_t id = 0;  ///< 11-bit (0..0x7FF) or, with `extended`, 29-bit identifier
    bool extended = false;
    bool remote = false;      ///< RTR frame (no data)
    std::uint8_t length = 0;  ///< data length 0..8
    std::uint8_t data[8] = {};
};

/// The controller's fault confinement state (ISO 11898-1), worst seen last.
enum class CanBusState : std::uint8_t {
    kErrorActive = 0,
    kErrorWarning = 1,  ///< an error counter reached 96
    kErrorPassive = 2,  ///< an error counter reached 128
    kBusOff = 3,        ///< transmit error counter passed 255: the node is off the bus
};

/// Outcome of a send.
enum class CanSendResult : std::uint8_t {
    kQueued = 0,     ///< accepted for transmission
    kQueueFull = 1,  ///< transmit queue full: nothing queued, try again later
    kBusOff = 2,     ///< controller is bus-off: nothing queued until it recovers
    kError = 3,      ///< any other failure (interface down, bad frame): nothing queued
};

/// A CAN interface. Not thread-safe: one task uses it. Freestanding: no heap, no exceptions.
class CanBus {
public:
    virtual ~CanBus() = default;

    /// Queues `frame` for transmission without blocking. Cost: one syscall on Linux.
    virtual CanSendResult send(const CanFrame& frame) = 0;

    /// Takes the next received frame (after the receive filters) into `out`, waiting up to
    /// `timeout_us` microseconds (0: do not wait). Returns false when none came. Error frames
    /// are not returned: they update state() and the error counters instead.
    virtual bool receive(CanFrame& out, std::uint32_t timeout_us) = 0;

    /// Current fault confinement state, from the controller's error frames.
    virtual CanBusState state() const = 0;
};

}  // namespace pathstream::hal
