// Machine-readable events (docs/events.md): NDJSON, one JSON object per line, flushed per
// line. `stream` and `sim` describe a job's run with them (--events); `device` stamps its log
// with iso8601_utc (--log-json: NDJSON too).
#pragma once

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "pathstream/host/machine.hpp"
#include "pathstream/host/modbus_stream.hpp"
#include "pathstream/host/plan.hpp"
#include "pathstream/units.hpp"

namespace pathstream::host {

using EventJson = nlohmann::ordered_json;

/// `t` as ISO-8601 UTC with milliseconds: "2025-01-31T12:34:56.789Z".
std::string iso8601_utc(std::chrono::system_clock::time_point t);

/// Writes NDJSON lines, each flushed at once so that a reader sees every event as it happens.
class NdjsonWriter {
public:
    /// Writes to `file`, which the caller keeps open.
    explicit NdjsonWriter(std::FILE* file);
    /// Opens `path` for writing. "-" is the standard output: the writer takes it over and file
    /// descriptor 1 then points at standard error, so that everything else the command prints
    /// goes there and the standard output carries nothing but events. Throws
    /// std::runtime_error naming the file when it cannot be opened.
    static std::unique_ptr<NdjsonWriter> open(const std::string& path);
    ~NdjsonWriter();
    NdjsonWriter(const NdjsonWriter&) = delete;
    NdjsonWriter& operator=(const NdjsonWriter&) = delete;

    /// One line: `object` dumped compactly, then a newline and a flush.
    void write(const EventJson& object);

private:
    NdjsonWriter(std::FILE* file, bool owned);
    std::FILE* file_;
    bool owned_;
};

/// Where a command's events go, and when the command started (every `t` counts from there).
struct EventChannel {
    std::unique_ptr<NdjsonWriter> writer;  ///< null: no --events (events only kept, not written)
    std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
    double progress_hz = 5;  ///< at most this many progress events per second
};

/// What job_start says about a job.
struct JobInfo {
    std::string command;       ///< "stream" or "sim"
    std::string drawing;       ///< the drawing's file
    std::string target;        ///< the device's URL; "sim" for the simulated plotter
    std::size_t subpaths = 0;  ///< subpaths of the whole drawing (a span's subpath + 1 <= this)
};

/// One look at a job executing: a status read of a device, or a simulated tick.
struct JobSample {
    std::optional<double> sim_seconds;  ///< sim: simulated time (progress is paced by it)
    std::optional<unsigned> state;      ///< device state (a DeviceState number); sim: none
    std::uint16_t fault_code = 0;
    bool started = false;                  ///< the device has begun executing the job
    std::size_t next_span = 0;             ///< the span executing or next to; spans(): all executed
    std::uint64_t ticks = 0;               ///< the job's path ticks executed
    std::uint64_t queued_ticks = 0;        ///< ticks sent or queued, not executed yet
    std::optional<unsigned> queued_spans;  ///< spans in the device's queue
    std::optional<unsigned> underruns;     ///< the device's underrun counter
    Lsb position[kMaxAxes] = {};           ///< setpoints, LSB per axis
    bool hold_requested = false;           ///< an interrupt asked for a hold
    bool stop_requested = false;           ///< an interrupt (or the hold timeout) for a stop
};

/// Turns samples of one job into events (docs/events.md) and keeps what the stream's progress
/// bar shows. Written from one thread.
class JobEvents {
public:
    /// `plan`: the job's spans; both must outlive this object.
    JobEvents(const EventChannel& channel, const Plan& plan, const MachineProfile& machine,
              JobInfo info);

    /// job_start, once (later calls do nothing); `job`: the device's job id when known.
    void start(std::optional<std::uint32_t> job);
    /// The events a sample shows: hold, stop, state, fault, underrun, subpath, pen, progress.
    void sample(const JobSample& s);
    /// A stream's status read (StreamObserver): job_start at the first, then its sample.
    void trace(const StreamTrace& t);
    /// `pause`: the device came to programmed pause `index` (Plan::pauses) and holds, pen up,
    /// for the operator; `next` says what comes after it (e.g. `layer "blue"`).
    void pause(std::size_t index, const std::string& next);
    /// job_end, once: `outcome` "finished", "held", "stopped" or "failed" (with `error`);
    /// job_start first if it has not been written. `ticks`: the job's path ticks executed, when
    /// known better than from the last sample.
    void end(const std::string& outcome, const std::string& error = "",
             std::optional<std::uint64_t> ticks = std::nullopt);

    /// "subpath 2/5, pen down, running": the progress bar's detail (empty parts left out).
    std::string status_text() const;
    /// Ticks before span i (prefix sums; size spans + 1).
    const std::vector<std::uint64_t>& prefix_ticks() const { return prefix_; }

private:
    double now() const;
    EventJson event(const char* type) const;
    void emit(const EventJson& e) const;
    void on_state(const JobSample& s);
    void on_requests(const JobSample& s);
    void on_underruns(const JobSample& s);
    void enter_spans(const JobSample& s);
    void on_progress(const JobSample& s);
    EventJson position_json(const Lsb* position) const;

    const EventChannel& channel_;
    const Plan& plan_;
    const MachineProfile& machine_;
    JobInfo info_;
    std::vector<std::uint64_t> prefix_;
    std::optional<double> sim_seconds_;  ///< of the last sample (sim events carry it)
    bool started_event_ = false, ended_ = false;
    double start_t_ = 0;
    std::optional<std::uint32_t> job_;
    // The last sample's view.
    bool first_sample_ = true;
    bool running_seen_ = false;
    std::optional<unsigned> state_;
    std::uint16_t fault_code_ = 0;
    bool hold_ = false, stop_ = false;
    unsigned underruns_base_ = 0, underruns_ = 0;
    long long entered_ = -1;  ///< last span entered (subpath and pen events written up to it)
    std::optional<std::size_t> subpath_;
    bool pen_down_ = false;
    std::uint64_t ticks_ = 0;
    std::optional<double> last_progress_;  ///< clock of the last progress event
    // A stream's baseline: the device's tick counter at the job's tick 0.
    bool have_base_ = false;
    std::uint32_t tick_base_ = 0;
    std::uint64_t first_ticks_ = 0;  ///< the job's ticks at the first read
};

}  // namespace pathstream::host
