// What `stream` does with each span on the planning thread before the streamer sees it: the
// device's travel check and the job journal's spans file.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>

#include "pathstream/host/job_journal.hpp"
#include "pathstream/host/planner.hpp"
#include "plan_command.hpp"

namespace pathstream::host {

/// A PlanSink for PlanningThread::Hooks::tap, used from the planning thread only: checks every
/// span's travel (check_span_travel) and writes the spans file of the job journal as they come
/// (JobSpansWriter). Every tick was checked against the limits by plan_stream before it gets
/// here; the deviation figures are `plan`'s: their index over the whole path (PlanChecker)
/// would make memory grow with the job. `job` (path, machine) and `file` must outlive it.
class StreamPlanTap : public PlanSink {
public:
    /// `spans_file`: where the journal's spans go; empty: none (--no-journal).
    StreamPlanTap(const PlannedJob& job, const std::string& file, const std::string& spans_file);
    void span(const CoreSpan& span) override;
    void pen(const PenEvent&) override {}
    void pause(const PlanPause&) override {}

    /// PlanningThread::Hooks::finish: writes the spans file (the drawing's totals in its
    /// header) and keeps its hash for spans_hash().
    void finish(const PlanTotals& totals);
    /// After finish() (read once the planning thread is finished): the spans file's hash,
    /// empty without a file.
    const std::string& spans_hash() const { return hash_; }

    /// What planning has made so far, for the job's estimate: its ticks and the mm of path
    /// (each span's chord) they cover. Any thread: one atomic word written by the planning
    /// thread per span and read whole (ticks below 2^32, mm below 4,294 m; beyond, saturated).
    struct Planned {
        std::uint64_t ticks = 0;
        double mm = 0;
    };
    Planned planned() const;

private:
    const PlannedJob& job_;
    const std::string& file_;
    std::unique_ptr<JobSpansWriter> writer_;
    std::size_t spans_ = 0;
    std::uint64_t ticks_ = 0;
    double mm_ = 0;
    std::atomic<std::uint64_t> planned_{0};  ///< ticks << 32 | micrometres: planned()
    std::size_t subpaths_ = 0;
    std::string hash_;
};

}  // namespace pathstream::host
