// `pathstream fleet --mqtt URL SUBCOMMAND`: the machines and jobs on a broker, jobs submitted
// to its queues, commands to one machine, and the fleet page (docs/mqtt.md, "pathstream
// fleet"; docs/cli.md).
#pragma once

#include <CLI/CLI.hpp>
#include <string>

namespace pathstream::host {

/// The command line of `fleet` and its subcommands, as parsed.
struct FleetCommandOptions {
    std::string mqtt;     ///< --mqtt: the broker's URL, as `serve --mqtt` takes it
    double settle = 0.5;  ///< s of quiet after which the retained topics are taken as read
    bool json = false;    ///< status, jobs: JSON instead of a table

    // submit
    std::string file;
    std::string kind;     ///< a queue ("": any, unless machine)
    std::string machine;  ///< one machine
    std::string id;       ///< "": generated
    std::string fit;      ///< placement: a paper ("a4") or "area"
    double margin = -1;   ///< mm; < 0: not given
    bool wait = false;    ///< wait for a final state
    double max_upload_mb = 16;

    // command
    std::string name;  ///< the machine
    std::string verb;
    std::string axis;     ///< jog
    double distance = 0;  ///< jog, mm
    std::string pen;      ///< pen: up or down
    double timeout = 10;  ///< s to wait for the reply

    // serve
    std::string listen = "127.0.0.1:8090";
    std::string token;
    std::string token_file;

    CLI::App* command = nullptr;  ///< the `fleet` subcommand, to see which of its own ran
};

/// Adds the `fleet` subcommand and its subcommands, parsed into `options` (which must outlive
/// the parse).
void add_fleet_command(CLI::App& app, FleetCommandOptions& options);

/// Runs the subcommand given; returns the exit status: 0, 1 (a job that did not end done),
/// 6 (a command the machine refused or did not answer). Throws std::invalid_argument for bad
/// values (exit 2) and MqttError when the broker cannot be reached or refuses (exit 3).
int run_fleet(const FleetCommandOptions& options);

}  // namespace pathstream::host
