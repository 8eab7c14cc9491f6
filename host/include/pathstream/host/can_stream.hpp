// Streaming a plan to a device that runs the core, over CAN with the native pathstream
// protocol (docs/can.md; frames declared in firmware_core's device/can_protocol.hpp).
#pragma once

#include <cstdint>
#include <string>

#include "pathstream/hal/can_bus.hpp"
#include "pathstream/host/plan.hpp"
#include "pathstream/host/span_supply.hpp"
#include "pathstream/host/stream_types.hpp"
#include "pathstream/machine/machine.hpp"

namespace pathstream::host {

/// A parsed `can://IFACE?node=N&protocol=native|cia402` target.
struct CanTarget {
    std::string interface_name;
    std::uint8_t node = 0;  ///< 1..127
    std::string protocol = "native";
};

/// Parses `url`. Throws std::invalid_argument naming what is wrong (no interface, node
/// missing or outside 1..127, unknown protocol or parameter).
CanTarget parse_can_target(const std::string& url);

struct CanStreamOptions {
    std::uint8_t node = 1;          ///< the device's node id, 1..127
    std::string name = "can";       ///< how messages name the target (e.g. the URL)
    double lead_seconds = 0.25;     ///< keep this much motion queued ahead of the device
    unsigned ack_timeout_ms = 100;  ///< resend a batch, configuration or status request after this
    double link_timeout_seconds = 2;  ///< give up after this long without a frame from the device
    unsigned poll_interval_ms = 10;   ///< status requests (4 frames) while the queue is full enough
    InterruptOptions interrupt;       ///< Ctrl-C handling
    StreamObserver observer;          ///< called after every status read (may be empty)
    const HeldJob* held = nullptr;    ///< continue a held job instead of starting one
};

/// What the device executed and what the bus carried.
struct CanStreamReport : StreamOutcome {
    std::uint64_t retransmissions = 0;  ///< batches sent again (timeout or incomplete)
    std::uint64_t timeouts = 0;         ///< waits for an answer that ran out
    std::uint64_t incomplete = 0;       ///< batches the device reported a lost data frame of
    std::uint64_t status_requests = 0;
    std::uint64_t frames_sent = 0;
    std::uint64_t frames_received = 0;  ///< frames from this node
    std::uint64_t bits_sent = 0;        ///< worst-case stuffed bits (can::frame_bits_worst_case)
    std::uint64_t bits_received = 0;
};

/// Where the device at options.node rests (LSB per axis, from status frame E), after checking
/// its identity (protocol version, axis count = the profile's) and that it is idle: what
/// `stream --lead-in` plans its pen-up move from. Throws StreamError like stream_can.
std::vector<Lsb> can_rest_position(const MachineProfile& profile, hal::CanBus& bus,
                                   const CanStreamOptions& options);

/// Streams `plan` to node options.node on `bus` (native protocol): checks the device's
/// identity (protocol version, axis count, idle) and that it rests at the plan's start,
/// configures its tick rate and limits from `profile` (rounded up to whole LSB/s and
/// LSB/s^2), sends batches of spans with sequence numbers keeping options.lead_seconds queued
/// and never more spans than the device has free slots, starts it, resumes it after an
/// underrun, resends batches lost on the bus (timeouts, incomplete-transfer nacks), and
/// returns when the last span has executed. Throws StreamError (device refused a batch,
/// restarted, faulted, the host's controller went bus-off, or nothing came from the device
/// for link_timeout_seconds) and std::invalid_argument (plan not streamable). The loop is
/// SpanStreamer's, shared with stream_modbus.
CanStreamReport stream_can(const Plan& plan, const MachineProfile& profile, hal::CanBus& bus,
                           const CanStreamOptions& options, const StreamProgress& progress = {});

/// stream_can for spans that are still being planned, as stream_modbus's SpanSupply form:
/// spans sent as the supply has them, the job's end marked once it ends, a supply error
/// while the device runs brought to a controlled stop (hold, then stop) and rethrown.
/// Memory: the spans the device has not executed, not the job.
CanStreamReport stream_can(SpanSupply& supply, const MachineProfile& profile, hal::CanBus& bus,
                           const CanStreamOptions& options, const SupplyProgress& progress = {});

}  // namespace pathstream::host
