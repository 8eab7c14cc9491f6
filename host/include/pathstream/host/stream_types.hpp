// What every streaming client shares, whichever bus carries the spans: its errors, what it
// reports as it goes, how an operator interrupts it and how a held job goes on.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <stdexcept>

#include "pathstream/host/device_link.hpp"

namespace pathstream::host {

/// A streaming failure the user must act on (device refused, restarted, faulted, link dead).
/// The message is complete and names the target.
class StreamError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// Where a stream stands after a status read: what a job journal and the events record.
struct StreamTrace {
    std::uint32_t job = 0;  ///< the job's id: the sequence number of its first span
    std::uint32_t acknowledged =
        0;                        ///< last sequence number the device acknowledged (job - 1: none)
    DeviceSnapshot status;        ///< the status just read
    bool hold_requested = false;  ///< an interrupt asked the device to hold
    bool stop_requested = false;  ///< a second interrupt (or the hold timeout) stopped it
};
/// Called from the streaming thread after every status read.
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

/// What a stream did, whichever bus carried it; each client's report adds its link's counters.
struct StreamOutcome {
    std::uint64_t spans_sent = 0;      ///< spans the device acknowledged (each counted once)
    std::uint64_t batches = 0;         ///< batches the device acknowledged
    std::uint64_t ticks_executed = 0;  ///< path ticks of the finished job (its count at the end)
    std::uint32_t last_completed = 0;  ///< sequence number of the last span executed
    std::uint32_t job = 0;             ///< the job's id (its first span's sequence number)
    std::uint32_t duplicates = 0;      ///< batches the device acknowledged as retries
    std::uint32_t underruns = 0;       ///< this job's: the device's count since the job began
    double wall_seconds = 0;
    std::int32_t final_position[kMaxAxes] = {};  ///< where the device rests at the end, LSB
    /// 0: the job ran to its end; 1: interrupted, the device holds at rest with the rest of
    /// the job queued; 2: interrupted, the device stopped (queue dropped) and is idle.
    int interrupted = 0;
    /// With interrupted 2: the stop came from another client (`pathstream ctl stop`, the page,
    /// another host): the device dropped the job's queue (a new epoch) and went idle while this
    /// stream sent no stop.
    bool stopped_elsewhere = false;
    DeviceSnapshot final_status;  ///< the last status read
};

/// Progress: fraction of the plan's ticks executed, and the device queue's lead in seconds.
using StreamProgress = std::function<void(double fraction, double queued_seconds)>;
/// Progress of a stream whose plan may still be made: the job's path ticks executed, its
/// ticks once known (nullopt while planning goes on), the device queue's lead in seconds.
using SupplyProgress = std::function<void(
    std::uint64_t ticks, std::optional<std::uint64_t> total_ticks, double queued_seconds)>;

/// A StreamProgress fed from a SupplyProgress's figures (the total is known for a plan).
/// Cheap to copy; calls `progress` from the streaming thread.
inline SupplyProgress plan_progress(const StreamProgress& progress) {
    if (!progress) return {};
    return [progress](std::uint64_t ticks, std::optional<std::uint64_t> total, double queued) {
        progress(
            total && *total > 0 ? static_cast<double>(ticks) / static_cast<double>(*total) : 0.0,
            queued);
    };
}

}  // namespace pathstream::host
