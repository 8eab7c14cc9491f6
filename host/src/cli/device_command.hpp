// `pathstream device`: the simulated device (the firmware core) serving Modbus TCP or RTU.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <string>
#include <vector>

namespace pathstream::host {

struct DeviceCommandOptions {
    unsigned axes = 2;
    std::vector<std::int32_t> position;  ///< LSB per axis; default all zero
    std::string tcp = "127.0.0.1:1502";
    bool rtu_pty = false;
    std::string rtu_device;
    int baud = 115200;
    std::string parity = "N";
    int unit = 1;
    double time_scale = 1.0;
    std::string record;
    double exit_after = 0;  ///< seconds of wall time; 0 = until SIGINT/SIGTERM
};

void add_device_command(CLI::App& app, DeviceCommandOptions& options);
int run_device(const DeviceCommandOptions& options);

}  // namespace pathstream::host
