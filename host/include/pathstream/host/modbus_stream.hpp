// Streaming a plan to a device that runs the core, over Modbus TCP or RTU (docs/modbus.md).
#pragma once

#include <cstdint>
#include <string>

#include "pathstream/host/device_link.hpp"
#include "pathstream/host/plan.hpp"
#include "pathstream/host/span_supply.hpp"
#include "pathstream/host/stream_types.hpp"
#include "pathstream/machine/machine.hpp"

namespace pathstream::host {

struct StreamOptions {
    std::string target;          ///< modbus-tcp://HOST:PORT?unit=N or modbus-rtu:///dev/X?...
    double lead_seconds = 0.25;  ///< keep this much motion queued ahead of the device
    unsigned response_timeout_ms = 500;  ///< per Modbus transaction try
    unsigned attempts = 3;               ///< tries per transaction (reconnect between TCP tries)
    double link_timeout_seconds = 5;  ///< give up after this long without a successful transaction
    unsigned poll_interval_ms = 2;    ///< status polling while the queue is full enough
    InterruptOptions interrupt;       ///< Ctrl-C handling
    StreamObserver observer;          ///< called after every status read (may be empty)
    const HeldJob* held = nullptr;    ///< continue a held job instead of starting one
};

/// What the device executed and what the link carried.
struct StreamReport : StreamOutcome {
    std::uint64_t transactions = 0;  ///< successful Modbus transactions of every kind
    std::uint64_t status_reads =
        0;  ///< of which FC4 status polls (the rest: batches, config, commands)
    std::uint64_t attempts = 0;             ///< requests sent (first tries and retries)
    std::uint64_t exception_responses = 0;  ///< device refusals (e.g. busy: fuller than known)
    std::uint64_t retries = 0;
    std::uint64_t reconnects = 0;
    std::uint64_t bytes_sent = 0;  ///< ADU bytes as on the wire
    std::uint64_t bytes_received = 0;
};

/// Connects to options.target, checks the device's identity (magic, version, axis count =
/// the profile's) and that it is idle, and returns where it rests (LSB per axis): the start
/// of a lead-in move. Throws StreamError like stream_modbus.
std::vector<Lsb> modbus_rest_position(const MachineProfile& profile, const StreamOptions& options);

/// Streams `plan` (Hermite spans, as plan_path makes them) to the device at options.target:
/// checks its identity (magic, protocol version, axis count) and that it rests at the plan's
/// start, configures its tick rate and limits from `profile` (rounded up to whole LSB/s and
/// LSB/s^2), sends batches of spans with sequence numbers (FC23: batch + status in one
/// transaction) keeping options.lead_seconds queued, starts it, resumes it after an underrun,
/// and returns when the last span has executed. Throws StreamError (device refused a batch,
/// restarted, faulted, or the link stayed dead past link_timeout_seconds) and
/// std::invalid_argument (bad target URL, plan not streamable). The loop is SpanStreamer's
/// (host/src/stream/span_streamer.hpp), shared with stream_can.
StreamReport stream_modbus(const Plan& plan, const MachineProfile& profile,
                           const StreamOptions& options, const StreamProgress& progress = {});

/// stream_modbus for spans that are still being planned: sends what `supply` has as the
/// device's queue drains, waits (polling the device) while it has nothing yet, and marks the
/// job's end on the last span once the supply ends. The device starts once the lead is queued
/// or the whole job is. An exception from the supply (the planning error) while the device
/// runs brings it to a controlled stop first (a hold, at rest, then a stop that drops the
/// queue), then is rethrown. Memory: the spans the device has not acknowledged, not the job.
StreamReport stream_modbus(SpanSupply& supply, const MachineProfile& profile,
                           const StreamOptions& options, const SupplyProgress& progress = {});

}  // namespace pathstream::host
