#include "stream_plan_tap.hpp"

#include <algorithm>

#include "pathstream/host/work_area.hpp"

namespace pathstream::host {

StreamPlanTap::StreamPlanTap(const PlannedJob& job, const std::string& file, const std::string& spans_file)
    : job_(job), file_(file) {
    if (!spans_file.empty()) writer_ = std::make_unique<JobSpansWriter>(spans_file, true);
}

void StreamPlanTap::span(const CoreSpan& s) {
    check_span_travel(s, spans_, job_.path, job_.machine, file_);
    // A first job: every span its own origin, at the drawing's tick where it starts.
    if (writer_) writer_->add(s, static_cast<std::int64_t>(spans_), ticks_);
    ++spans_;
    ticks_ += s.ticks;
    subpaths_ = std::max(subpaths_, s.subpath + 1);
}

void StreamPlanTap::finish(const PlanTotals& totals) {
    if (writer_) hash_ = writer_->finish(totals.spans, totals.total_ticks, subpaths_);
}

}  // namespace pathstream::host
