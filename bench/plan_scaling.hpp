// bench_plan --scaling: how planning time and memory grow with the job. For 1k, 10k, 100k and
// 1M points (up to a cap), a smooth random-walk B-spline of that many points is made segment
// by segment and streamed through plan_stream (which checks every tick against the limits as
// it goes) in a forked child process, so that each size's peak memory is its own and a size
// that takes too long or too much memory is stopped without stopping the bench.
#pragma once

#include <array>
#include <cstddef>
#include <random>
#include <string>
#include <vector>

#include "pathstream/machine/machine.hpp"

namespace pathstream::bench {

/// The scaling table's random walk: 1.5 mm steps whose heading turns by a normal(0, 0.25) rad,
/// steered back towards the middle when it leaves a 200 mm square; the same points every time.
class RandomWalk {
public:
    /// The next point (the first is 0, 0).
    std::array<double, 2> next();

private:
    std::mt19937_64 rng_{20261122};
    std::normal_distribution<double> turn_{0, 0.25};
    double x_ = 0, y_ = 0, heading_ = 0;
};

struct ScalingOptions {
    std::size_t max_segments = 1'000'000;  ///< sizes above this are skipped
    unsigned timeout_seconds = 300;        ///< wall time a child gets (SIGALRM) before "timeout"
    std::size_t memory_limit_mb = 8192;    ///< the child's address space (RLIMIT_AS)
};

/// One size's figures. Times are measured in the child; memory from the child's
/// /proc/self/status (VmRSS after the input was built, VmHWM after planning and at the end).
struct ScalingRow {
    std::size_t points = 0, segments = 0, spans = 0;
    std::string status;    ///< "ok", "timeout", "out of memory", "plan failed: ...", ...
    bool planned = false;  ///< plan figures below are valid
    bool checked = false;  ///< check figures below are valid
    bool check_passed = false;
    double plan_seconds = 0;      ///< best wall time of the runs (several for small sizes)
    double plan_cpu_seconds = 0;  ///< the child's CPU time during that run
    int runs = 0;                 ///< plans made (best kept)
    double check_seconds = 0;
    double input_mb = 0;                  ///< resident after building the path and its segments
    double plan_peak_mb = 0;              ///< peak resident after planning (input included)
    double peak_mb = 0;                   ///< peak resident at the end (check included)
    double load_start = 0, load_end = 0;  ///< 1-minute load average before and after the child
};

/// Runs every size up to the cap, each in its own child (fork, wait4). Never throws for a
/// child's failure: it becomes the row's status.
std::vector<ScalingRow> run_scaling(const ScalingOptions& options,
                                    const host::MachineProfile& profile);

/// Prints the table: wall time, us per segment and its ratio to the smallest size's, memory,
/// load. `markdown`: a Markdown table.
void print_scaling(const std::vector<ScalingRow>& rows, const ScalingOptions& options,
                   bool markdown);

/// True when no child's plan failed or failed its check (timeouts and memory limits are not
/// failures: they depend on the machine).
bool scaling_passed(const std::vector<ScalingRow>& rows);

}  // namespace pathstream::bench
