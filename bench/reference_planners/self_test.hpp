// bench_plan --self-test: the reference planners against closed-form answers (a straight line's
// trapezoid and triangle, a diagonal at both axes' limits, the junction speeds of a 90 degree
// corner and a reversal, the held junction speeds of a square and a diamond and their sampled
// velocity steps), their tick sampling, the flattening, and self-consistency on seeded
// random polylines. Runs in well under a second; ctest runs it (bench_plan_self_test).
#pragma once

namespace pathstream::bench {

/// Runs every check, printing one line per failure to stderr and a summary to stdout.
/// Returns the number of failed checks (0: all passed).
int run_reference_self_test();

}  // namespace pathstream::bench
