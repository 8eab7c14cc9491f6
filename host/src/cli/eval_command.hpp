// `pathstream eval`: the path through the core's Horner evaluator at fixed parameter steps.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <string>

#include "path_options.hpp"

namespace pathstream::host {

struct EvalOptions {
    JobRequest path;
    std::string output;
    std::uint32_t samples_per_span = 8;
    double mm_per_lsb = 0.001;
    std::string machine;  ///< optional: takes mm_per_lsb from the profile
};

void add_eval_command(CLI::App& app, EvalOptions& options);
int run_eval(const EvalOptions& options);

}  // namespace pathstream::host
