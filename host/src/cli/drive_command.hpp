// `pathstream drive`: the simulated CiA 402 drive (sim/cia402) on a SocketCAN interface.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <string>

namespace pathstream::host {

struct DriveCommandOptions {
    std::string can;                        ///< interface, e.g. vcan0
    unsigned node = 1;                      ///< 1..127
    std::int32_t position = 0;              ///< LSB at power-up
    double bandwidth_hz = 100;              ///< servo plant
    std::uint32_t following_window = 5000;  ///< LSB (0x6065 default)
    double inertia = 0;     ///< torque offset per mille per LSB/s^2; 0: 0x60B2 not mappable
    double exit_after = 0;  ///< seconds of wall time; 0 = until SIGINT/SIGTERM
};

void add_drive_command(CLI::App& app, DriveCommandOptions& options);
int run_drive(const DriveCommandOptions& options);

}  // namespace pathstream::host
