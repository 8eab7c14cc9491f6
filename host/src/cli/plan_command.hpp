// `pathstream plan`: time a path for a machine and write the setpoints the device executes.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "path_options.hpp"
#include "pathstream/host/geometry.hpp"
#include "pathstream/machine/machine.hpp"
#include "pathstream/host/plan.hpp"

namespace pathstream::host {

struct PlanCommandOptions {
    PathOptions path;
    std::string machine;
    std::string output;
    bool json = false;  ///< --json: one JSON document on standard output instead of text
    bool preview = false;   ///< --preview: the web page's preview document (plan_preview.cpp)
    double max_motion = 0;  ///< --max-motion: s; a job estimated to move longer is refused; 0: no limit
};

void add_plan_command(CLI::App& app, PlanCommandOptions& options);
int run_plan(const PlanCommandOptions& options);
/// `plan --preview`: planning progress as JSON lines, then the preview document `pathstream
/// serve` shows, one line, on standard output.
int run_plan_preview(const PlanCommandOptions& options);


/// What plan and sim share: the path, the machine, the geometry, the plan and its check.
struct PlannedJob {
    Path path;
    MachineProfile machine;
    std::vector<BezierSegment> segments;
    Plan plan;  ///< empty when the plan was streamed (run_plan): the counts below hold
    PlanCheck check;
    double planning_seconds = 0;
    std::size_t span_count = 0, pen_count = 0, pause_count = 0;
};

/// Loads both files, checks they agree (axis count) and makes the segments, the lead-in's
/// included: a job ready to plan (its plan empty). Throws InputError for bad files.
PlannedJob prepare_job(const PathOptions& path, const std::string& machine_file,
                       const std::vector<double>* lead_in_from = nullptr);

/// Loads both files, checks they agree (axis count), plans with a progress bar and checks
/// every tick. Throws InputError for bad files, PlanError when planning fails.
/// `lead_in_from` (mm per axis, optional): the machine's position; when it is not the path's
/// first point, a straight pen-up move from it to there is planned first.
PlannedJob plan_job(const PathOptions& path, const std::string& machine_file,
                    const std::vector<double>* lead_in_from = nullptr);

/// The summary lines both commands print (duration, lengths, deviation, limit fractions).
void print_plan_summary(const PlannedJob& job, std::ostream& out);
/// Throws PlanError when the job's estimated motion time passes `max_motion_s` (> 0), naming
/// both; before any planning.
void refuse_long_motion(const PlannedJob& job, double max_motion_s);

/// Millimetres of an LSB count, as the shortest exact decimal (one division, see eval).
std::string lsb_to_mm_text(Lsb value, double mm_per_lsb);

}  // namespace pathstream::host
