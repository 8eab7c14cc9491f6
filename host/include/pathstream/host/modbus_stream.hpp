// Streaming a plan to a device that runs the core, over Modbus TCP or RTU (docs/modbus.md).
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>

#include "pathstream/host/device_link.hpp"
#include "pathstream/machine/machine.hpp"
#include "pathstream/host/plan.hpp"
#include "pathstream/host/span_supply.hpp"

namespace pathstream::host {

/// A streaming failure the user must act on (device refused, restarted, faulted, link dead).
/// The message is complete and names the target.
class StreamError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// Where a stream stands after a status read: what a job journal and the events record.
struct StreamTrace {
    std::uint32_t job = 0;           ///< the job's id: the sequence number of its first span
    std::uint32_t acknowledged = 0;  ///< last sequence number the device acknowledged (job - 1: none)
    DeviceSnapshot status;           ///< the status just read
    bool hold_requested = false;     ///< an interrupt asked the device to hold
    bool stop_requested = false;     ///< a second interrupt (or the hold timeout) stopped it
};
using StreamObserver = std::function<void(const StreamTrace&)>;

/// A job the device holds (after an interrupted stream): its spans are still queued, so the
/// stream goes on from the last acknowledged span and ends with a resume instead of a start.
struct HeldJob {
    std::uint32_t job = 0;           ///< the held job's id; the plan streamed is that job's spans
    std::uint32_t acknowledged = 0;  ///< the device's last accepted sequence number
};

/// How a stream reacts to an operator's interrupt (Ctrl-C, SIGTERM), shared by the clients.
struct InterruptOptions {
    /// 0: none; 1: hold (controlled stop at the next span boundary, queue kept, pen up), then
    /// return once the device rests; 2 or more: stop (the queue is dropped), then return once
    /// idle. Written by a signal handler, read by the streaming loop. Not owned.
    const std::atomic<int>* request = nullptr;
    double hold_timeout_seconds = 10;  ///< a hold not at rest by then becomes a stop
    /// Called once each time the device comes to a programmed pause (Plan::pauses; the index
    /// of the pause in it). May be empty.
    std::function<void(std::size_t pause)> on_pause;
    /// Polled while the device is paused; true sends the resume (e.g. Enter at a terminal).
    /// Empty: the operator resumes the device (`pathstream ctl TARGET resume`).
    std::function<bool()> resume_requested;
};

struct StreamOptions {
    std::string target;                 ///< modbus-tcp://HOST:PORT?unit=N or modbus-rtu:///dev/X?...
    double lead_seconds = 0.25;         ///< keep this much motion queued ahead of the device
    unsigned response_timeout_ms = 500; ///< per Modbus transaction try
    unsigned attempts = 3;              ///< tries per transaction (reconnect between TCP tries)
    double link_timeout_seconds = 5;    ///< give up after this long without a successful transaction
    unsigned poll_interval_ms = 2;      ///< status polling while the queue is full enough
    InterruptOptions interrupt;         ///< Ctrl-C handling
    StreamObserver observer;            ///< called after every status read (may be empty)
    const HeldJob* held = nullptr;      ///< continue a held job instead of starting one
};

/// What the device executed and what the link carried.
struct StreamReport {
    std::uint64_t spans_sent = 0;
    std::uint64_t batches = 0;
    std::uint64_t ticks_executed = 0;     ///< device's count at the end
    std::uint32_t last_completed = 0;     ///< sequence number of the last span executed
    std::uint32_t job = 0;                ///< the job's id (its first span's sequence number), finished
    std::uint32_t duplicates = 0;         ///< batches the device acknowledged as retries
    std::uint32_t underruns = 0;           ///< this job's: the device's count since the job began
    std::uint64_t transactions = 0;       ///< successful Modbus transactions of every kind
    std::uint64_t status_reads = 0;       ///< of which FC4 status polls (the rest: batches, config, commands)
    std::uint64_t attempts = 0;           ///< requests sent (first tries and retries)
    std::uint64_t exception_responses = 0;  ///< device refusals (e.g. busy: queue fuller than known)
    std::uint64_t retries = 0;
    std::uint64_t reconnects = 0;
    std::uint64_t bytes_sent = 0;         ///< ADU bytes as on the wire
    std::uint64_t bytes_received = 0;
    double wall_seconds = 0;
    std::int32_t final_position[8] = {};
    /// 0: the job ran to its end; 1: interrupted, the device holds at rest with the rest of
    /// the job queued; 2: interrupted, the device stopped (queue dropped) and is idle.
    int interrupted = 0;
    /// With interrupted 2: the stop came from another client (`pathstream ctl stop`, the page,
    /// another host): the device dropped the job's queue (a new epoch) and went idle while this
    /// stream sent no stop.
    bool stopped_elsewhere = false;
    DeviceSnapshot final_status;          ///< the last status read
};

/// Progress: fraction of the plan's ticks executed, and the device queue's lead in seconds.
using StreamProgress = std::function<void(double fraction, double queued_seconds)>;
/// Progress of a stream whose plan may still be made: the job's path ticks executed, its
/// ticks once known (nullopt while planning goes on), the device queue's lead in seconds.
using SupplyProgress =
    std::function<void(std::uint64_t ticks, std::optional<std::uint64_t> total_ticks, double queued_seconds)>;

/// A StreamProgress fed from a SupplyProgress's figures (the total is known for a plan).
/// Cheap to copy; calls `progress` from the streaming thread.
inline SupplyProgress plan_progress(const StreamProgress& progress) {
    if (!progress) return {};
    return [progress](std::uint64_t ticks, std::optional<std::uint64_t> total, double queued) {
        progress(total && *total > 0 ? static_cast<double>(ticks) / static_cast<double>(*total) : 0.0, queued);
    };
}

/// Streams `plan` (Hermite spans, as plan_path makes them) to the device at options.target:
/// checks its identity (magic, protocol version, axis count) and that it rests at the plan's
/// start, configures its tick rate and limits from `profile` (rounded up to whole LSB/s and
/// LSB/s^2), sends batches of spans with sequence numbers (FC23: batch + status in one
/// transaction) keeping options.lead_seconds queued, starts it, resumes it after an underrun,
/// and returns when the last span has executed. Throws StreamError (device refused a batch,
/// restarted, faulted, or the link stayed dead past link_timeout_seconds) and
/// std::invalid_argument (bad target URL, plan not streamable).
/// Connects to options.target, checks the device's identity (magic, version, axis count =
/// the profile's) and that it is idle, and returns where it rests (LSB per axis): the start
/// of a lead-in move. Throws StreamError like stream_modbus.
std::vector<Lsb> modbus_rest_position(const MachineProfile& profile, const StreamOptions& options);

StreamReport stream_modbus(const Plan& plan, const MachineProfile& profile, const StreamOptions& options,
                           const StreamProgress& progress = {});

/// stream_modbus for spans that are still being planned: sends what `supply` has as the
/// device's queue drains, waits (polling the device) while it has nothing yet, and marks the
/// job's end on the last span once the supply ends. The device starts once the lead is queued
/// or the whole job is. An exception from the supply (the planning error) while the device
/// runs brings it to a controlled stop first (a hold, at rest, then a stop that drops the
/// queue), then is rethrown. Memory: the spans the device has not acknowledged, not the job.
StreamReport stream_modbus(SpanSupply& supply, const MachineProfile& profile, const StreamOptions& options,
                           const SupplyProgress& progress = {});

}  // namespace pathstream::host
