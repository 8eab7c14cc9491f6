// `pathstream stream`: plan a path and stream it to a device over Modbus (docs/modbus.md).
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "path_options.hpp"
#include "pathstream/host/modbus_stream.hpp"

namespace pathstream::host {

struct StreamCommandOptions {
    PathOptions path;
    std::string machine;
    StreamOptions stream;
    bool lead_in = false;  ///< plan a pen-up move from where the device rests (Modbus targets)
};

void add_stream_command(CLI::App& app, StreamCommandOptions& options);
int run_stream(const StreamCommandOptions& options);

}  // namespace pathstream::host
