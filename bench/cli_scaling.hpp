// bench_plan --scaling's command rows: the scaling table's random walks written as JSON files
// and run through `pathstream plan` and `pathstream sim` in child processes, so that what
// users run is measured next to plan_stream alone (CPU time and peak RSS from wait4).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "plan_scaling.hpp"

namespace pathstream::bench {

/// One command on one size.
struct CliRow {
    std::size_t points = 0;
    std::string command;  ///< "plan" or "sim"
    double file_mb = 0;   ///< the JSON file's size
    double wall_seconds = 0, cpu_seconds = 0, peak_mb = 0;
    double load_start = 0, load_end = 0;
    std::string status;  ///< "ok", "timeout", "exit N", "killed by signal N"
};

/// For each scaling size up to the cap: writes the walk to a file in a fresh temporary
/// directory (removed after), then runs `binary plan FILE -m machine` and `binary sim FILE -m
/// machine`, each under the options' timeout and address-space limit, output discarded.
std::vector<CliRow> run_cli_scaling(const ScalingOptions& options, const std::string& binary,
                                    const std::string& machine);

/// Prints the rows with CPU per point, its ratio to the smallest size's and, for plan, to
/// plan_stream's CPU time for the same size in `stream_rows` (measured in the same run).
void print_cli_scaling(const std::vector<CliRow>& rows, const std::vector<ScalingRow>& stream_rows,
                       bool markdown);

/// False when a command failed on a size (a timeout or the memory limit is not a failure).
bool cli_scaling_passed(const std::vector<CliRow>& rows);

}  // namespace pathstream::bench
