// Machine-readable events (docs/events.md): NDJSON, one JSON object per line, flushed per
// line. `stream` and `sim` describe a job's run with them (--events); `device` stamps its log
// with iso8601_utc (--log-json: NDJSON too).
#pragma once

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <deque>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "pathstream/device/device_state.hpp"
#include "pathstream/host/plan.hpp"
#include "pathstream/host/stream_types.hpp"
#include "pathstream/machine/event_json.hpp"
#include "pathstream/machine/machine.hpp"
#include "pathstream/units.hpp"

namespace pathstream::host {

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
    /// Also given every event's line (stream --mqtt); called on the thread that emits.
    std::function<void(const std::string& line)> tap;
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
    std::optional<double> sim_seconds;         ///< sim: simulated time (progress is paced by it)
    std::optional<device::DeviceState> state;  ///< device state; sim: none
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
    std::optional<bool> pen_output;        ///< the device's pen output now; sim: none
};

/// Turns samples of one job into events (docs/events.md) and keeps what the stream's progress
/// bar shows. Written from one thread. Learns the job's spans as they are planned (add_span)
/// and its totals once planning ends (set_totals); keeps only the spans not yet entered.
class JobEvents {
public:
    /// A job whose spans come later (add_span); `channel` and `machine` must outlive this.
    JobEvents(const EventChannel& channel, const MachineProfile& machine, JobInfo info);
    /// A planned job: every span of `plan` added and its totals set.
    JobEvents(const EventChannel& channel, const Plan& plan, const MachineProfile& machine,
              JobInfo info);

    /// The job's next span, in order (before the samples that show it executing). O(1).
    void add_span(const CoreSpan& span);
    /// The job's totals, once known: its ticks, spans and programmed pauses. Until then the
    /// events carry null for them (and for a progress event's fraction and ETA).
    void set_totals(std::uint64_t ticks, std::size_t spans, std::size_t pauses);
    /// The job's ticks, when known.
    std::optional<std::uint64_t> total_ticks() const { return total_ticks_; }

    /// What a progress event's fraction and ETA count. `before`: the drawing's ticks run
    /// before this stream (a resume: the fraction is of the whole drawing, `before` plus this
    /// job). `estimate`: the job's ticks estimated while they are not known (called from this
    /// object's thread at each progress event; nullopt or an empty function: none), marked
    /// `"estimated": true`.
    void set_progress_basis(std::uint64_t before,
                            std::function<std::optional<std::uint64_t>()> estimate);
    /// The fraction of the whole drawing done after `ticks` of this job, the job's ticks left and
    /// whether they are estimated; nullopt while nothing is known. For the progress bar too.
    struct Progress {
        double fraction = 0;
        std::uint64_t ticks_left = 0;
        bool estimated = false;
    };
    std::optional<Progress> progress(std::uint64_t ticks) const;

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

    /// "subpath 2/5, pen down, running": the progress bar's detail (empty parts left out). The
    /// pen is the device's output when its status says (at a pause it rests pen up inside a
    /// pen-down job), else that of the span executing.
    std::string status_text() const;

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
    std::uint64_t ticks_before(std::size_t span) const;
    EventJson total_json(const std::optional<std::uint64_t>& value) const;

    // What events need of a span not yet entered.
    struct SpanMark {
        std::uint64_t ticks_before = 0;
        std::size_t subpath = 0;
        bool pen_down = false;
    };
    const EventChannel& channel_;
    const MachineProfile& machine_;
    JobInfo info_;
    std::deque<SpanMark> marks_;  ///< spans marks_base_ .. spans_added_ - 1
    std::size_t marks_base_ = 0;
    std::size_t spans_added_ = 0;
    std::uint64_t ticks_added_ = 0;
    std::optional<std::uint64_t> total_ticks_;
    std::optional<std::uint64_t> total_spans_, total_pauses_;
    std::uint64_t ticks_before_job_ = 0;
    std::function<std::optional<std::uint64_t>()> estimate_;
    std::optional<bool> pen_output_;     ///< of the last sample: what status_text() says
    std::optional<double> sim_seconds_;  ///< of the last sample (sim events carry it)
    bool started_event_ = false, ended_ = false;
    double start_t_ = 0;
    std::optional<std::uint32_t> job_;
    // The last sample's view.
    bool first_sample_ = true;
    bool running_seen_ = false;
    std::optional<device::DeviceState> state_;
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
