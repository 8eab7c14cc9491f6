// `pathstream plan`: time a path for a machine and write the setpoints the device executes.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "path_options.hpp"
#include "pathstream/host/geometry.hpp"
#include "pathstream/host/plan.hpp"
#include "pathstream/host/planned_job.hpp"
#include "pathstream/machine/machine.hpp"

namespace pathstream::host {

struct PlanCommandOptions {
    JobRequest path;
    std::string machine;
    std::string output;
    bool json = false;     ///< --json: one JSON document on standard output instead of text
    bool preview = false;  ///< --preview: the web page's preview document (plan_preview.cpp)
    double max_motion =
        0;  ///< --max-motion: s; a job estimated to move longer is refused; 0: no limit
};

void add_plan_command(CLI::App& app, PlanCommandOptions& options);
int run_plan(const PlanCommandOptions& options);
/// `plan --preview`: planning progress as JSON lines, then the preview document `pathstream
/// serve` shows, one line, on standard output.
int run_plan_preview(const PlanCommandOptions& options);

/// The summary lines both commands print (duration, lengths, deviation, limit fractions).
void print_plan_summary(const PlannedJob& job, std::ostream& out);
/// Millimetres of an LSB count, as the shortest exact decimal (one division, see eval).
std::string lsb_to_mm_text(Lsb value, double mm_per_lsb);

}  // namespace pathstream::host
