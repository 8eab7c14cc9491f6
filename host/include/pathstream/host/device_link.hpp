// A device that runs the core, seen from the host through one bus: its status, read whole,
// and its commands. The Modbus (TCP, RTU) and native CAN links implement the transport once;
// the streamers and `pathstream ctl` use them.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "pathstream/device/device_state.hpp"
#include "pathstream/device/homing.hpp"
#include "pathstream/hal/can_bus.hpp"
#include "pathstream/machine/device_setup.hpp"
#include "pathstream/span.hpp"
#include "pathstream/status.hpp"
#include "pathstream/units.hpp"

namespace pathstream::hal {
class ModbusClient;
}

namespace pathstream::host {

struct StreamOptions;
struct CanStreamOptions;

/// One read of a device's status, whichever bus carried it; every tick-side field is from one
/// tick (docs/device.md, "What the status says"). Fields a bus does not carry are 0 and named.
struct DeviceSnapshot {
    unsigned magic = 0;  ///< Modbus only: 0x5053 ("PS")
    unsigned version = 0, axes = 0;
    device::DeviceState state = device::DeviceState::kIdle;
    std::uint16_t fault_code = 0;
    unsigned free_slots = 0, queued = 0;
    unsigned capacity = 0;  ///< Modbus only (0 over CAN)
    unsigned flags = 0;     ///< kSnapshot* bits (the same on both buses)
    unsigned underruns = 0, duplicates = 0;
    unsigned outputs = 0;       ///< bit 0 pen down on the last tick (CAN: from its pen flag)
    unsigned last_refusal = 0;  ///< Modbus only: core Status of the last refused write
    std::uint32_t last_accepted = 0, last_completed = 0, ticks_executed = 0;
    std::uint32_t finished_job = 0, finished_job_ticks = 0;
    std::uint32_t epoch = 0;  ///< CAN: low 16 bits only
    std::int32_t position[kMaxAxes] = {};
    device::HomingReport homing[kMaxAxes] = {};  ///< each axis's homing state

    bool configured() const { return (flags & kSnapshotConfigured) != 0; }
    bool held_by_underrun() const { return (flags & kSnapshotHeldByUnderrun) != 0; }
    bool own_move() const { return (flags & kSnapshotOwnMove) != 0; }
    bool homing_runs() const { return (flags & kSnapshotHoming) != 0; }
    /// Holding at a programmed pause (a pen change, M0): the operator's resume continues.
    bool paused() const { return (flags & kSnapshotPaused) != 0; }
    bool pen_down() const { return (outputs & kOutputPenDown) != 0; }

    /// DeviceSnapshot::flags bits: Modbus register 35's and CAN status A's agree on these.
    static constexpr unsigned kSnapshotConfigured = 1u << 0;
    static constexpr unsigned kSnapshotHeldByUnderrun = 1u << 1;
    static constexpr unsigned kSnapshotOwnMove = 1u << 3;
    static constexpr unsigned kSnapshotHoming = 1u << 4;
    static constexpr unsigned kSnapshotPaused = 1u << 6;
};

/// "not homed", "homing", "homed", "failed".
const char* axis_homing_name(device::AxisHoming h);
/// Why homing failed: "switch not found", ... ("none" for kNone).
const char* homing_error_name(device::HomingError e);

/// A command's verb as `pathstream ctl` spells it ("start", "hold", ...).
const char* command_verb(device::Command c);

/// The transport to one device. Not thread-safe: one thread at a time.
class DeviceLink {
public:
    virtual ~DeviceLink() = default;
    /// One status read. Throws StreamError when nothing answers for the link timeout.
    virtual DeviceSnapshot status() = 0;
    /// Sends command `c` and returns the device's answer (kOk, or the core Status it refused
    /// with). Throws StreamError when nothing answers for the link timeout.
    virtual Status command(device::Command c) = 0;
    /// A command with arguments (docs/device.md, "Operator commands"): 6 jog `axis` by
    /// `value` LSB at `feed` per mille of its max velocity, 7 set `axis`'s position to
    /// `value`, 8 home the axes of bit mask `axis` (0: all), 9 pen (`value` 1 down, 0 up).
    /// Returns the device's answer. Throws StreamError on a dead link.
    virtual Status command_with_arguments(std::uint8_t command, unsigned axis, std::int32_t value,
                                          std::uint16_t feed) = 0;
    /// The target as messages name it (its URL).
    virtual const std::string& name() const = 0;
};

/// Timeouts of a link opened from a URL.
struct LinkOptions {
    unsigned response_timeout_ms =
        500;                          ///< Modbus: per try; CAN: before asking again (at most 100)
    unsigned attempts = 3;            ///< Modbus: tries per transaction
    double link_timeout_seconds = 5;  ///< give up after this long without an answer
};

/// Opens modbus-tcp://, modbus-rtu:// or can://IFACE?node=N (native protocol; the link owns
/// its SocketCAN socket). Throws std::invalid_argument (bad URL, CiA 402 target) and
/// StreamError (cannot connect within the link timeout).
std::unique_ptr<DeviceLink> open_device_link(const std::string& target, const LinkOptions& options);

/// A native CAN link over a bus the caller owns (tests: a loopback endpoint).
std::unique_ptr<DeviceLink> open_can_link(hal::CanBus& bus, const CanStreamOptions& options);

}  // namespace pathstream::host
