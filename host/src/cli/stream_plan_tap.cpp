#include "stream_plan_tap.hpp"

#include <algorithm>
#include <cmath>

#include "pathstream/host/work_area.hpp"

namespace pathstream::host {

StreamPlanTap::StreamPlanTap(const PlannedJob& job, const std::string& file,
                             const std::string& spans_file)
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
    double chord = 0;
    for (const auto& axis : s.control) {
        const double d = static_cast<double>(axis[1]) - static_cast<double>(axis[0]);
        chord += d * d;
    }
    mm_ += std::sqrt(chord) * job_.machine.mm_per_lsb;
    const std::uint64_t ticks = std::min<std::uint64_t>(ticks_, 0xFFFFFFFFu);
    const std::uint64_t um = static_cast<std::uint64_t>(std::min(mm_ * 1000.0, 4294967295.0));
    planned_.store(ticks << 32 | um, std::memory_order_relaxed);
}

StreamPlanTap::Planned StreamPlanTap::planned() const {
    const std::uint64_t word = planned_.load(std::memory_order_relaxed);
    return {word >> 32, static_cast<double>(word & 0xFFFFFFFFu) / 1000.0};
}

void StreamPlanTap::finish(const PlanTotals& totals) {
    if (writer_) hash_ = writer_->finish(totals.spans, totals.total_ticks, subpaths_);
}

}  // namespace pathstream::host
