// The one streaming loop: a job's spans, encoded as they are planned, sent in sequenced
// batches through a BusSession while the device runs them, with flow control from its status,
// the operator's interrupts, programmed pauses and a planning failure brought to a stop.
// stream_modbus and stream_can are this loop over their bus.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "bus_session.hpp"
#include "pathstream/host/span_supply.hpp"
#include "pathstream/host/stream_types.hpp"
#include "pathstream/machine/machine.hpp"
#include "stream_interrupt.hpp"
#include "wire_feed.hpp"

namespace pathstream::host {

/// How a stream runs, whichever bus carries it. The referenced objects outlive the streamer.
struct StreamSettings {
    double lead_seconds = 0.25;     ///< keep this much motion queued ahead of the device
    unsigned poll_interval_ms = 2;  ///< shortest wait between status reads
    const InterruptOptions* interrupt = nullptr;  ///< required: Ctrl-C handling
    const StreamObserver* observer = nullptr;     ///< called after every status read, or null
    const HeldJob* held = nullptr;                ///< continue a held job instead of starting one
};

/// The settings of a client's options (StreamOptions, CanStreamOptions: the same names). The
/// result points into `options`, which must outlive it.
template <typename ClientOptions>
StreamSettings settings_of(const ClientOptions& options) {
    StreamSettings s;
    s.lead_seconds = options.lead_seconds;
    s.poll_interval_ms = options.poll_interval_ms;
    s.interrupt = &options.interrupt;
    s.observer = &options.observer;
    s.held = options.held;
    return s;
}

/// Streams one job through `bus`. One use: construct, then rest_position() or run() once.
/// Thread: the caller's (the streaming thread); the supply may be filled by another.
class SpanStreamer {
public:
    SpanStreamer(SpanSupply& supply, const MachineProfile& profile, BusSession& bus,
                 const StreamSettings& settings);

    /// The device's identity and state checked (idle), where it rests, LSB per axis.
    std::vector<Lsb> rest_position();

    /// Checks the device (identity, idle at the job's start, or holding the held job),
    /// configures it, streams every span keeping the lead queued, starts (or resumes) it, and
    /// returns once the job ended or an interrupt settled. Throws StreamError, and the
    /// supply's error after bringing a running device to a stop.
    StreamOutcome run(const SupplyProgress& progress);

private:
    using Clock = std::chrono::steady_clock;

    std::size_t continue_held(const DeviceSnapshot& s);
    void check_identity(const DeviceSnapshot& s, bool check_start, device::DeviceState wanted);
    void configure();
    void command(device::Command c, bool tolerate_refusal);
    std::string refusal_detail();
    std::optional<DeviceSnapshot> send_batch(std::size_t& next);
    void batch_done(std::size_t& next, std::size_t count, std::uint32_t last);
    void observe(const DeviceSnapshot& s, const StreamInterrupt& interrupt) const;
    void observe_rate(const DeviceSnapshot& s, bool started);
    std::chrono::microseconds poll_wait(std::uint64_t lead, std::uint64_t lead_target, bool started,
                                        bool& predicted) const;
    std::uint64_t queued_ticks(const DeviceSnapshot& s, std::size_t sent) const;
    std::size_t completed_count(const DeviceSnapshot& s) const;
    bool all_sent(std::size_t next) const;
    bool job_finished(const DeviceSnapshot& s) const;
    void check_restart(const DeviceSnapshot& s) const;
    void check_running(const DeviceSnapshot& s, bool started);
    void finish_after_supply_error(DeviceSnapshot& s);

    WireFeed feed_;
    const MachineProfile& profile_;
    BusSession& bus_;
    const StreamSettings& settings_;
    StreamOutcome outcome_;
    unsigned axes_ = 0;
    std::int32_t start_[kMaxAxes] = {};  // the job's first point, LSB
    std::uint32_t base_ = 1;             // the job's id: its first span's sequence number
    std::uint32_t job_epoch_ = 0;
    std::uint32_t underruns_at_start_ = 0;
    std::uint32_t acknowledged_ = 0;
    std::uint32_t start_ticks_ = 0;  // the device's tick count when the job's ticks began
    unsigned free_slots_ = 0;        // the device's free slots, as last reported
    Clock::time_point started_at_;
    bool seen_running_ = false;
    bool configured_ = false;  // the device took our configuration: it must keep it
    double rate_ = 0;          // device ticks per second, for poll_wait
    Clock::time_point rate_time_ = Clock::now();
    std::uint32_t rate_ticks_ = 0;
};

}  // namespace pathstream::host
