// What `pathstream stream` and `stream --resume` share inside the CLI: streaming one job with
// its journal and events, and what a stream prints of itself.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "pathstream/host/events.hpp"
#include "pathstream/host/job_journal.hpp"
#include "pathstream/host/path.hpp"
#include "pathstream/host/planned_job.hpp"
#include "pathstream/host/planning_thread.hpp"
#include "pathstream/host/span_supply.hpp"
#include "pathstream/host/stream_types.hpp"
#include "stream_command.hpp"
#include "stream_plan_tap.hpp"

namespace pathstream::host {

// What a stream ended with, whichever bus carried it.
struct StreamEnd {
    int interrupted = 0;
    DeviceSnapshot status;
    std::uint32_t job = 0;
    bool stopped_elsewhere = false;  // interrupted 2 by another client's stop
};

// Where a span sits in the drawing: for the report of where an interrupted job stopped.
struct SpanPlace {
    std::int64_t origin = 0;  // index in the drawing's plan; -1: a re-entry span
    std::size_t subpath = 0;
    std::uint64_t drawing_tick = 0;  // the drawing's tick at its start
};

// The whole drawing's counts, known once planning ended.
struct DrawingTotals {
    std::size_t spans = 0;
    std::size_t subpaths = 0;
    std::uint64_t ticks = 0;
};

// What stream_job streams: the spans and what is known of the whole job.
struct JobToStream {
    SpanSupply& supply;
    // The job held in memory (a resume, --plan-first): its spans file is written before the
    // stream, its totals known. Null: a first job planned as it streams.
    const JobSpans* spans = nullptr;
    // The planner feeding `supply` and its tap (the spans file), for a job planned as it
    // streams; `path` describes its pauses.
    PlanningThread* planning = nullptr;
    const StreamPlanTap* tap = nullptr;
    const Path* path = nullptr;
    std::size_t subpaths = 0;  // of the whole drawing
    // The job's ticks estimated while planning goes on (JobEvents::set_progress_basis).
    std::function<std::optional<std::uint64_t>()> estimate;
};

/// Streams `job`, keeping the journal at `journal_path` (none when empty) and writing the
/// events; `held`: the device holds this job (a resume goes on with it). Returns the exit
/// status; a stream failure is thrown after the journal and events record it.
int stream_job(const JobToStream& job, const MachineProfile& machine, StreamCommandOptions o,
               JobJournal journal, const std::string& journal_path, const HeldJob* held,
               const EventChannel& channel);

/// `stream --resume JOURNAL` (docs/cli.md, "Interrupt and resume").
int run_resume(StreamCommandOptions o, const EventChannel& channel);

/// What comes after a programmed pause that subpath `subpath` follows.
std::string pause_description(const Path& path, std::size_t subpath);
/// pause_description of each programmed pause of a plan in memory.
std::vector<std::string> pause_descriptions(const Path& path, const Plan& plan);

/// Streams over can://, with a progress bar; prints what the device executed and what the bus
/// carried when the job ran to its end.
StreamEnd stream_over_can(SpanSupply& supply, const MachineProfile& machine,
                          const StreamCommandOptions& o, const StreamObserver& observer,
                          const HeldJob* held, const JobEvents& events,
                          const PlanningThread* planning);
/// The same over modbus-tcp:// or modbus-rtu://.
StreamEnd stream_over_modbus(SpanSupply& supply, const MachineProfile& machine,
                             const StreamCommandOptions& o, const StreamObserver& observer,
                             const HeldJob* held, const JobEvents& events,
                             const PlanningThread* planning);
/// Where an interrupted job stopped, in the drawing's terms, and how to go on.
void print_interrupted(const StreamEnd& end, std::optional<SpanPlace> next,
                       std::optional<DrawingTotals> totals, const MachineProfile& machine,
                       const std::string& journal, bool resumable);
/// Where the job starts: at the device's rest position, or after a pen-up lead-in from it.
void print_lead_in(const PlannedJob& job, const std::vector<double>& rest_mm);

}  // namespace pathstream::host
