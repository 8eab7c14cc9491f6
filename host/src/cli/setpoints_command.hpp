// `pathstream setpoints`: a path through the firmware core, tick by tick, into CSV.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <optional>
#include <string>

#include "path_options.hpp"

namespace pathstream::host {

struct SetpointsOptions {
    JobRequest path;
    std::string machine;  ///< -m: mm_per_lsb and ticks_per_span from the profile
    std::string output;
    std::optional<std::uint32_t> ticks_per_span;  ///< default: the profile's, else 32
    std::optional<double> mm_per_lsb;             ///< default: the profile's, else 0.001
};

/// Registers the subcommand and its options on `app`.
void add_setpoints_command(CLI::App& app, SetpointsOptions& options);

/// Runs it: returns 0, or throws InputError / std::runtime_error (see main.cpp's exit codes).
int run_setpoints(const SetpointsOptions& options);

}  // namespace pathstream::host
