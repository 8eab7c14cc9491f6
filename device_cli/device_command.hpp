// `pathstream device` (and `pathstream-device`): the device runtime (the firmware core) serving
// Modbus TCP or RTU or the native CAN protocol; with --machine configured from a profile and
// wired to its GPIO lines (e-stop, limit switches, enable, pen), with --home homed before it
// serves; with --sim-switch the profile's limit switches played by a simulated machine.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <string>
#include <vector>

#include "pathstream/linux_device/device_runtime.hpp"

namespace pathstream::device_cli {

struct DeviceCommandOptions {
    unsigned axes = 2;
    std::vector<std::string>
        position;         ///< per axis: mm, or LSB with the suffix "lsb"; default all zero
    std::string machine;  ///< profile: configuration, GPIO lines and homing
    linux_device::DeviceRunOptions run;  ///< what to serve and how
    /// --sim-switch NAME=POSITION: the profile's limit switch NAME played by its axis on a
    /// gpio-sim chip, closed at POSITION (mm, or LSB with the suffix lsb) and beyond.
    std::vector<std::string> sim_switches;
    double switch_hysteresis = 0.02;   ///< mm the axis moves back past the trigger to open it
    unsigned switch_bounces = 0;       ///< extra openings and closings after every change
    unsigned switch_bounce_ticks = 0;  ///< ticks they fall within (0: 4 x bounces)
    std::uint64_t switch_seed = 1;     ///< the bounces' ticks are drawn from this seed
};

/// Adds the `device` subcommand to `app`, its values read into `options` (which must outlive
/// the parse). Init context.
void add_device_command(CLI::App& app, DeviceCommandOptions& options);
/// Runs the device until SIGINT, SIGTERM or --exit-after; returns the exit code (docs/cli.md,
/// "Exit codes") after printing one line for any failure. Main thread; installs the signal
/// handlers.
int run_device(const DeviceCommandOptions& options);

}  // namespace pathstream::device_cli
