// The job pipeline's stages after the request: prepare (load both files, check they agree, make
// the segments and the lead-in) and plan (plan, check every tick). A straight line from a
// JobRequest to a checked plan that a streamer or the simulator takes.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "pathstream/host/geometry.hpp"
#include "pathstream/host/job_request.hpp"
#include "pathstream/host/output_figures.hpp"
#include "pathstream/host/plan.hpp"
#include "pathstream/machine/machine.hpp"

namespace pathstream::host {

/// A job on its way: the path, the machine, the geometry, the plan and its check. What `plan`,
/// `sim`, `stream` and the web server's preview share.
struct PlannedJob {
    Path path;
    MachineProfile machine;
    std::vector<BezierSegment> segments;  ///< empty for a streamed job (prepare_streamed_job)
    /// A streamed job's lead-in: where the machine rests, when it is not the path's start
    /// (PathSegmentSource(path, lead_in) makes the move); prepare_job puts it in segments.
    std::optional<PathPoint> lead_in;
    Plan plan;  ///< empty when the plan was streamed (run_plan): the counts below hold
    PlanCheck check;
    double planning_seconds = 0;
    std::size_t span_count = 0, pen_count = 0, pause_count = 0;
    OutputFigures outputs;  ///< the spindle's and the coolant's share of the plan
};

/// Loads both files, checks they agree (axis count) and makes the segments, the lead-in's
/// included: a job ready to plan (its plan empty). Throws InputError for bad files.
PlannedJob prepare_job(const JobRequest& request, const std::string& machine_file,
                       const std::vector<double>* lead_in_from = nullptr);

/// prepare_job without the segment list (segments stays empty): the work area is checked
/// segment by segment and a planner or check reads the path through
/// PathSegmentSource(path, lead_in), so that memory holds the path and nothing per segment.
PlannedJob prepare_streamed_job(const JobRequest& request, const std::string& machine_file,
                                const std::vector<double>* lead_in_from = nullptr);

/// Loads both files, checks they agree (axis count), plans with a progress bar and checks
/// every tick. Throws InputError for bad files, PlanError when planning fails.
/// `lead_in_from` (mm per axis, optional): the machine's position; when it is not the path's
/// first point, a straight pen-up move from it to there is planned first.
PlannedJob plan_job(const JobRequest& request, const std::string& machine_file,
                    const std::vector<double>* lead_in_from = nullptr);

/// Throws PlanError when the job's estimated motion time passes `max_motion_s` (> 0), naming
/// both; before any planning. From the segments, or from the path when there are none.
void refuse_long_motion(const PlannedJob& job, double max_motion_s);

}  // namespace pathstream::host
