// How every command reads its path file: the FILE argument and the per-format, placement and
// order options, filled into a JobRequest (pathstream/host/job_request.hpp).
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "pathstream/host/job_request.hpp"

namespace pathstream::host {

/// Adds the FILE argument and the format options to a subcommand. Init context.
void add_path_options(CLI::App& command, JobRequest& request);

/// Column names of the axes in CSV output: x y z a b c v w (u is taken by the parameter).
const char* axis_column_name(std::size_t axis);

/// Shortest decimal text that reads back as exactly `value` (round-trip), for CSV output.
std::string exact_decimal(double value);

}  // namespace pathstream::host
