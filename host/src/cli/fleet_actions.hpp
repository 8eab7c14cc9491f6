// The subcommands of `pathstream fleet` that act: submit, command and the page's server.
#pragma once

#include "fleet_command.hpp"
#include "fleet_link.hpp"
#include "pathstream/host/fleet_job.hpp"

namespace pathstream::host {

/// `fleet submit`'s job from its file and options, checked: before connecting, so that a bad
/// value is exit 2 whether the broker is reachable or not. Throws std::invalid_argument.
FleetJobMessages prepare_fleet_job(const FleetCommandOptions& options);

/// `fleet submit`: publishes `job` (its queued state first); with --wait, follows it to a
/// final state. Returns 0, or 1 when the job ended other than done.
int run_fleet_submit(FleetLink& link, const FleetCommandOptions& options,
                     const FleetJobMessages& job);

/// Checks `fleet command`'s machine name (before connecting). Throws std::invalid_argument.
void check_command(const FleetCommandOptions& options);

/// `fleet command`: one command to one machine, its reply printed. Returns 0 for status
/// 200, else 6.
int run_fleet_command(FleetLink& link, const FleetCommandOptions& options);

/// `fleet serve`: the fleet page and its API until SIGINT or SIGTERM. Returns 0.
int run_fleet_serve(FleetLink& link, const FleetCommandOptions& options);

/// Why a job cannot go to machine `name` ("no machine named NAME on the broker", "machine
/// NAME is offline: ..."), or "" when it can.
std::string machine_refusal(const FleetLink& link, const std::string& name);

/// The file's text for a job. Throws std::invalid_argument when it cannot be read or is
/// larger than `max_bytes` (read no further than that).
std::string read_job_file(const std::string& path, std::size_t max_bytes);

}  // namespace pathstream::host
