// One message and one exit code for a failure the commands share (docs/cli.md, "Exit codes"): a
// bad input file, a bus or line that cannot be used, a bad argument, output that cannot be
// written. Both programs (pathstream, pathstream-device) end their commands with it.
#pragma once

#include <CLI/CLI.hpp>
#include <exception>
#include <functional>

namespace pathstream::device_cli {

/// Prints `failure`'s message to standard error and returns its exit code: InputError 1 (the
/// message alone: it names the file), hal::ModbusError 6 ("pathstream: device: ..."),
/// hal::GpioError and std::system_error 6, std::invalid_argument 2, another std::runtime_error 3,
/// anything else 4 ("internal error"). Main thread.
int failure_exit(const std::exception_ptr& failure);

/// A program's main after its options are declared on `app`: parses the command line (help
/// and --version print and return 0; a bad command line prints CLI11's message and returns
/// kExitUsage), then returns `run()`, whose exceptions end as failure_exit says. Main thread.
int parse_and_run(CLI::App& app, int argc, char** argv, const std::function<int()>& run);

}  // namespace pathstream::device_cli
