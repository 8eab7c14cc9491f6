// One message and one exit code for a failure the commands share (docs/cli.md, "Exit codes"): a
// bad input file, a bus or line that cannot be used, a bad argument, output that cannot be
// written. Both programs (pathstream, pathstream-device) end their commands with it.
#pragma once

#include <exception>

namespace pathstream::device_cli {

/// Prints `failure`'s message to standard error and returns its exit code: InputError 1 (the
/// message alone: it names the file), hal::ModbusError 6 ("pathstream: device: ..."),
/// hal::GpioError and std::system_error 6, std::invalid_argument 2, another std::runtime_error 3,
/// anything else 4 ("internal error"). Main thread.
int failure_exit(const std::exception_ptr& failure);

}  // namespace pathstream::device_cli
