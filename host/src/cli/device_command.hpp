// `pathstream device`: the simulated device (the firmware core) serving Modbus TCP or RTU or
// the native CAN protocol; with --machine configured from a profile and wired to its GPIO
// lines (e-stop, limit switches, enable, pen), with --home homed before it serves.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <string>
#include <vector>

namespace pathstream::host {

struct DeviceCommandOptions {
    unsigned axes = 2;
    std::vector<std::string> position;  ///< per axis: mm, or LSB with the suffix "lsb"; default all zero
    std::string tcp = "127.0.0.1:1502";
    bool rtu_pty = false;
    std::string rtu_device;
    int baud = 115200;
    std::string parity = "N";
    int unit = 1;
    std::string can_interface;  ///< native CAN on this SocketCAN interface instead of Modbus
    unsigned node = 1;          ///< CAN node id
    std::string machine;        ///< profile: configuration, GPIO lines and homing
    bool no_gpio = false;       ///< with --machine: do not open the profile's GPIO lines
    bool home = false;          ///< home the profile's gpio.home axes before serving
    double time_scale = 1.0;
    std::string record;
    double exit_after = 0;  ///< seconds of wall time; 0 = until SIGINT/SIGTERM
    bool log_json = false;  ///< --log-json: the log as NDJSON instead of text
    /// --sim-switch NAME=POSITION: the profile's limit switch NAME played by its axis on a
    /// gpio-sim chip, closed at POSITION (mm, or LSB with the suffix lsb) and beyond.
    std::vector<std::string> sim_switches;
    double switch_hysteresis = 0.02;  ///< mm the axis moves back past the trigger to open it
    unsigned switch_bounces = 0;      ///< extra openings and closings after every change
    unsigned switch_bounce_ticks = 0; ///< ticks they fall within (0: 4 x bounces)
    std::uint64_t switch_seed = 1;    ///< the bounces' ticks are drawn from this seed
};

void add_device_command(CLI::App& app, DeviceCommandOptions& options);
int run_device(const DeviceCommandOptions& options);

}  // namespace pathstream::host
