// `pathstream setpoints`: a path through the firmware core, tick by tick, into CSV.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <string>

namespace pathstream::host {

struct SetpointsOptions {
    std::string input;
    std::string output;
    std::uint32_t ticks_per_span = 32;
    double mm_per_lsb = 0.001;
};

/// Registers the subcommand and its options on `app`.
void add_setpoints_command(CLI::App& app, SetpointsOptions& options);

/// Runs it: returns 0, or throws InputError / std::runtime_error (see main.cpp's exit codes).
int run_setpoints(const SetpointsOptions& options);

}  // namespace pathstream::host
