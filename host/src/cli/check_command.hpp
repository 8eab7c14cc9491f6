// `pathstream check`: validate a path file and summarise it.
#pragma once

#include <CLI/CLI.hpp>

#include "path_options.hpp"

namespace pathstream::host {

struct CheckOptions {
    JobRequest path;
    bool json = false;    ///< --json: one JSON document on standard output instead of text
    std::string machine;  ///< optional profile: its work area serves --fit area
};

void add_check_command(CLI::App& app, CheckOptions& options);
int run_check(const CheckOptions& options);

}  // namespace pathstream::host
