// `pathstream serve`: the web page that loads, places, previews, simulates and streams a
// drawing and steers the machine (docs/serve.md).
#pragma once

#include <CLI/CLI.hpp>
#include <string>

namespace pathstream::host {

/// The command line of `serve`, as parsed.
struct ServeCommandOptions {
    std::string machine;  ///< --machine: the profile every job is planned for
    std::string target;   ///< --target: the device's URL
    std::string listen = "127.0.0.1:8080";
    std::string token;       ///< --token: required by every request (not on loopback: required)
    std::string token_file;  ///< --token-file: the token's first line
    std::string state_dir;   ///< --state-dir: drawing and journal ("": a new temporary directory)
    double max_upload_mb = 16;
    double events_rate = 10;       ///< progress updates per second to the page
    double plan_timeout = 60;      ///< s a preview, run or simulation may plan
    double max_motion_hours = 24;  ///< a longer job (estimated) is refused before planning
    std::size_t max_connections = 512;
    std::size_t max_connections_per_client = 256;
    std::string mqtt;  ///< --mqtt: the broker's URL ("": no broker)
    std::string name;  ///< --name: the machine's name on the broker
    std::string kind;  ///< --kind: its job queue (default: the profile's file name stem)
};

/// Adds the `serve` subcommand and its options, parsed into `options` (which must outlive
/// the parse).
void add_serve_command(CLI::App& app, ServeCommandOptions& options);
/// Serves until SIGINT or SIGTERM (a job still streaming is held first); returns the exit
/// status. Throws std::invalid_argument for bad options (a listen address beyond loopback
/// without a token), InputError for a bad profile, std::runtime_error when it cannot listen.
int run_serve(const ServeCommandOptions& options);

}  // namespace pathstream::host
