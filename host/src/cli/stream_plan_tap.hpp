// What `stream` does with each span on the planning thread before the streamer sees it: the
// per-tick check, the device's travel check and the job journal's spans file.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "pathstream/host/job_journal.hpp"
#include "pathstream/host/planner.hpp"
#include "plan_command.hpp"

namespace pathstream::host {

/// A PlanSink for PlanningThread::Hooks::tap, used from the planning thread only: checks every
/// tick (PlanChecker) and every span's travel (check_span_travel), and writes the spans file
/// of the job journal as they come (JobSpansWriter). `job` (path, segments, machine) and `file`
/// must outlive it.
class StreamPlanTap : public PlanSink {
public:
    /// `spans_file`: where the journal's spans go; empty: none (--no-journal).
    StreamPlanTap(const PlannedJob& job, const std::string& file, const std::string& spans_file);
    void span(const CoreSpan& span) override;
    void pen(const PenEvent& event) override { checker_.pen(event); }
    void pause(const PlanPause& pause) override { checker_.pause(pause); }

    /// PlanningThread::Hooks::finish: the check's figures over the whole plan (throws
    /// PlanError when they are over a limit or the pen moves while drawing) and the spans
    /// file written, its hash kept for spans_hash().
    void finish(const PlanTotals& totals);
    /// After finish() (read once the planning thread is finished): the spans file's hash,
    /// empty without a file.
    const std::string& spans_hash() const { return hash_; }
    /// After finish(): the plan's per-tick check.
    const PlanCheck& check() const { return check_; }

private:
    const PlannedJob& job_;
    const std::string& file_;
    PlanChecker checker_;
    std::unique_ptr<JobSpansWriter> writer_;
    std::uint64_t ticks_ = 0;
    std::size_t subpaths_ = 0;
    std::string hash_;
    PlanCheck check_;
};

}  // namespace pathstream::host
