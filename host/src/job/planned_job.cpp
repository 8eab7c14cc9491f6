#include "pathstream/host/planned_job.hpp"

#include <chrono>
#include <cmath>
#include <stdexcept>

#include "pathstream/host/job_estimate.hpp"
#include "pathstream/host/planner.hpp"
#include "pathstream/host/progress.hpp"
#include "pathstream/host/segment_source.hpp"
#include "pathstream/host/work_area.hpp"
#include "pathstream/machine/input_error.hpp"

namespace pathstream::host {

void refuse_long_motion(const PlannedJob& job, double max_motion_s) {
    if (max_motion_s <= 0) return;
    PathSegmentSource path(job.path, job.lead_in);
    const double estimate = job.segments.empty()
                                ? JobEstimate(path, job.machine).model_seconds()
                                : JobEstimate(job.segments, job.machine).model_seconds();
    if (estimate > max_motion_s) {
        throw PlanError("the job moves for about " + duration_text(estimate) +
                        " (estimated before planning), longer than " + duration_text(max_motion_s) +
                        " (--max-motion)");
    }
}

namespace {

/// Both files loaded and checked to agree (axis count); no segments made yet.
PlannedJob load_job(const JobRequest& path_options, const std::string& machine_file,
                    const std::vector<double>* lead_in_from) {
    PlannedJob job;
    job.machine = load_machine_profile(machine_file);
    // The work area serves --fit area; the lead-in's origin is where the order starts from.
    job.path = load_path(path_options, &job.machine, lead_in_from);
    if (job.machine.axes.size() != job.path.axes) {
        throw InputError(machine_file, {},
                         "the machine has " + std::to_string(job.machine.axes.size()) +
                             " axes but " + path_options.file + " has " +
                             std::to_string(job.path.axes));
    }
    return job;
}

}  // namespace

/// Whether the machine resting at `from` (mm) is at `start` on the LSB grid: the device rests
/// on the grid, and a travel shorter than an LSB would be a span that goes nowhere.
bool rests_at(const std::vector<double>& from, const PathPoint& start, double mm_per_lsb) {
    bool at = from.size() == start.size();
    for (std::size_t a = 0; at && a < start.size(); ++a)
        at = std::llround(from[a] / mm_per_lsb) == std::llround(start[a] / mm_per_lsb);
    return at;
}

PlannedJob prepare_streamed_job(const JobRequest& path_options, const std::string& machine_file,
                                const std::vector<double>* lead_in_from) {
    PlannedJob job = load_job(path_options, machine_file, lead_in_from);
    bool first = true;
    for_each_bezier_segment(job.path, [&](const BezierSegment& s) {
        if (first && lead_in_from != nullptr &&
            !rests_at(*lead_in_from, s.p[0], job.machine.mm_per_lsb))
            job.lead_in = PathPoint(lead_in_from->begin(), lead_in_from->end());
        first = false;
        check_segment_work_area(s, job.path, job.machine, path_options.file);
    });
    if (job.lead_in && job.lead_in->size() != job.path.axes) {
        throw std::invalid_argument("lead-in: the machine has " +
                                    std::to_string(job.lead_in->size()) + " axes, the path " +
                                    std::to_string(job.path.axes));
    }
    return job;
}

PlannedJob prepare_job(const JobRequest& path_options, const std::string& machine_file,
                       const std::vector<double>* lead_in_from) {
    PlannedJob job = load_job(path_options, machine_file, lead_in_from);
    job.segments = to_bezier_segments(job.path);
    check_work_area(job.segments, job.path, job.machine, path_options.file);
    if (lead_in_from != nullptr && !job.segments.empty() &&
        !rests_at(*lead_in_from, job.segments.front().p[0], job.machine.mm_per_lsb))
        prepend_lead_in(job.segments, *lead_in_from);
    return job;
}

PlannedJob plan_job(const JobRequest& path_options, const std::string& machine_file,
                    const std::vector<double>* lead_in_from) {
    PlannedJob job = prepare_job(path_options, machine_file, lead_in_from);
    const auto t0 = std::chrono::steady_clock::now();
    {
        ProgressBar bar("planning");
        job.plan = plan_path(job.segments, job.machine, [&](double f) { bar.update(f); });
    }
    job.planning_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    job.check = check_plan(job.plan, job.segments, job.machine);
    check_plan_travel(job.plan, job.path, job.machine, path_options.file);
    job.span_count = job.plan.spans.size();
    for (const CoreSpan& s : job.plan.spans) job.outputs.add(s);
    job.pen_count = job.plan.pen.size();
    job.pause_count = job.plan.pauses.size();
    return job;
}

}  // namespace pathstream::host
