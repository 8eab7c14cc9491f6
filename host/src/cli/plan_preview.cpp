// `pathstream plan --preview`: what `pathstream serve` runs in a child process to preview a
// drawing, so that a preview can be cancelled (the child killed) and its memory is returned
// when it ends.
#include <chrono>
#include <iostream>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "pathstream/host/job_estimate.hpp"
#include "pathstream/host/planner.hpp"
#include "pathstream/host/work_area.hpp"
#include "plan_command.hpp"
#include "serve/preview.hpp"

namespace pathstream::host {

int run_plan_preview(const PlanCommandOptions& o) {
    if (o.json || !o.output.empty())
        throw std::invalid_argument("--preview prints its own document: not with --json or --out");
    PlannedJob job = prepare_job(o.path, o.machine, nullptr);
    refuse_long_motion(job, o.max_motion);
    const double estimated =
        job.segments.empty() ? 0.0 : JobEstimate(job.segments, job.machine).model_seconds();
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
    job.plan = plan_path(job.segments, job.machine, progress);
    job.check = check_plan(job.plan, job.segments, job.machine);
    check_plan_travel(job.plan, job.path, job.machine, o.path.file);
    if (!job.check.within_limits || job.check.drawing_while_pen_moves) {
        throw PlanError("the plan failed its per-tick check (a planner bug)");
    }
    std::cout << serve::preview_json(job.plan, job.path, job.machine).dump() << std::endl;
    return 0;
}

}  // namespace pathstream::host
