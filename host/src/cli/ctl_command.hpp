// `pathstream ctl TARGET VERB`: an operator's control of a device that runs the core, over
// Modbus TCP/RTU or native CAN: its status, hold, resume, stop, reset, home, jog, pen and set
// position (docs/cli.md).
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "pathstream/host/device_link.hpp"

namespace pathstream::host {

struct CtlCommandOptions {
    std::string target;
    std::string verb;
    std::vector<std::string>
        arguments;        ///< jog AXIS DISTANCE, position AXIS VALUE, home [AXES], pen up|down
    std::string machine;  ///< optional profile: positions in mm and axis names
    bool json = false;
    double watch_seconds = 0;  ///< status: repeat every this many seconds (0: once)
    unsigned count = 0;        ///< status --watch: stop after this many reads (0: until Ctrl-C)
    /// Commands: how long to wait for the state the command leads to (< 0: 5 s, home 300 s).
    double wait_seconds = -1;
    double feed = 0;  ///< jog: mm/s (0: the axis's max velocity)
    LinkOptions link;
};

void add_ctl_command(CLI::App& app, CtlCommandOptions& options);
int run_ctl(const CtlCommandOptions& options);

}  // namespace pathstream::host
