// `pathstream ctl TARGET VERB`: an operator's control of a device that runs the core, over
// Modbus TCP/RTU or native CAN: its status, hold, resume, stop, reset, jog and set position
// (docs/cli.md).
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "pathstream/host/device_link.hpp"

namespace pathstream::host {

struct CtlCommandOptions {
    std::string target;
    std::string verb;
    std::vector<std::string> arguments;  ///< jog AXIS DISTANCE, position AXIS VALUE
    std::string machine;  ///< optional profile: positions in mm and axis names
    bool json = false;
    double watch_seconds = 0;  ///< status: repeat every this many seconds (0: once)
    unsigned count = 0;        ///< status --watch: stop after this many reads (0: until Ctrl-C)
    double wait_seconds = 5;   ///< commands: how long to wait for the state the command leads to
    double feed = 0;           ///< jog: mm/s (0: the axis's max velocity)
    LinkOptions link;
};

void add_ctl_command(CLI::App& app, CtlCommandOptions& options);
int run_ctl(const CtlCommandOptions& options);

}  // namespace pathstream::host
