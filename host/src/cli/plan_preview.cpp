// `pathstream plan --preview`: what `pathstream serve` runs in a child process to preview a
// drawing, so that a preview can be cancelled (the child killed) and its memory is returned
// when it ends. The plan is streamed: memory holds the path and the preview, not the plan.
#include <chrono>
#include <iostream>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "pathstream/host/job_estimate.hpp"
#include "pathstream/host/planned_job.hpp"
#include "pathstream/host/planner.hpp"
#include "pathstream/host/segment_source.hpp"
#include "pathstream/host/work_area.hpp"
#include "plan_command.hpp"
#include "serve/preview.hpp"

namespace pathstream::host {

namespace {

/// The streamed plan into the preview's record, through the device's travel check.
class PreviewSink : public PlanSink {
public:
    PreviewSink(const PlannedJob& job, const std::string& file)
        : job_(job), file_(file), recorder_(job.path, job.machine) {}
    void span(const CoreSpan& s) override {
        check_span_travel(s, spans_++, job_.path, job_.machine, file_);
        ticks_ += s.ticks;
        recorder_.span(s);
    }
    void pen(const PenEvent&) override {}
    void pause(const PlanPause& p) override { recorder_.pause(p.tick); }
    serve::PreviewRecorder& recorder() { return recorder_; }

private:
    const PlannedJob& job_;
    const std::string& file_;
    serve::PreviewRecorder recorder_;
    std::size_t spans_ = 0;
    std::uint64_t ticks_ = 0;
};

}  // namespace

int run_plan_preview(const PlanCommandOptions& o) {
    if (o.json || !o.output.empty())
        throw std::invalid_argument("--preview prints its own document: not with --json or --out");
    PlannedJob job = prepare_streamed_job(o.path, o.machine);
    refuse_long_motion(job, o.max_motion);
    PathSegmentSource estimated_path(job.path);
    const double estimated = JobEstimate(estimated_path, job.machine).model_seconds();
    // Progress at most 5 times a second: the server passes each line on to every page.
    auto last = std::chrono::steady_clock::now() - std::chrono::seconds(1);
    const auto progress = [&](double fraction) {
        const auto now = std::chrono::steady_clock::now();
        if (now - last < std::chrono::milliseconds(200) && fraction < 1) return;
        last = now;
        std::cout << nlohmann::ordered_json{{"event", "planning"},
                                            {"file", path_display_name(o.path.file)},
                                            {"fraction", fraction},
                                            {"estimated_s", estimated}}
                         .dump()
                  << std::endl;
    };
    progress(0);
    // Planned as a stream: the preview keeps its simplified path and speed bins, not the plan.
    PathSegmentSource source(job.path), checked(job.path);
    StreamCheck check;
    check.path = &checked;
    PreviewSink sink(job, o.path.file);
    const PlanTotals totals =
        plan_stream(source, job.machine, PlanOptions{}, sink, &check, nullptr, progress);
    if (!check.result.within_limits || check.result.drawing_while_pen_moves) {
        throw PlanError("the plan failed its per-tick check (a planner bug)");
    }
    std::cout << sink.recorder()
                     .finish(totals.duration, totals.total_ticks, totals.pen_changes,
                             totals.path_length, totals.travel_length)
                     .dump()
              << std::endl;
    return 0;
}

}  // namespace pathstream::host
