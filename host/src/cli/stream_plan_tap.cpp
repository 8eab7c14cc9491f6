#include "stream_plan_tap.hpp"

#include <algorithm>

#include "pathstream/host/work_area.hpp"

namespace pathstream::host {

StreamPlanTap::StreamPlanTap(const PlannedJob& job, const std::string& file, const std::string& spans_file)
    : job_(job), file_(file), checker_(job.segments, job.machine) {
    if (!spans_file.empty()) writer_ = std::make_unique<JobSpansWriter>(spans_file);
}

void StreamPlanTap::span(const CoreSpan& s) {
    const std::size_t index = checker_.spans();
    check_span_travel(s, index, job_.path, job_.machine, file_);
    // A first job: every span its own origin, at the drawing's tick where it starts.
    if (writer_) writer_->add(s, static_cast<std::int64_t>(index), ticks_);
    checker_.span(s);
    ticks_ += s.ticks;
    subpaths_ = std::max(subpaths_, s.subpath + 1);
}

void StreamPlanTap::finish(const PlanTotals& totals) {
    check_ = checker_.finish();
    if (!check_.within_limits || check_.drawing_while_pen_moves) {
        throw PlanError(std::string("the plan failed its per-tick check (a planner bug): ") +
                        (check_.within_limits ? "motion while the pen moves" : "a limit is exceeded") +
                        "; run pathstream plan on the same drawing for the figures");
    }
    if (writer_) hash_ = writer_->finish(totals.spans, totals.total_ticks, subpaths_);
}

}  // namespace pathstream::host
