// The device runtime as a program runs it: a Modbus (TCP, RTU) or native CAN device configured
// from a machine profile, wired to its GPIO lines and output coils, homed when asked, then served
// and ticked on the steady clock until stopped, its events logged (docs/cli.md, "device").
#pragma once

#include <atomic>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "pathstream/linux_device/any_motion_device.hpp"
#include "pathstream/linux_device/device_log.hpp"
#include "pathstream/machine/machine.hpp"
#include "pathstream/units.hpp"

namespace pathstream::linux_device {

/// What to serve and how: plain values, checked by whoever fills them (the device command).
struct DeviceRunOptions {
    std::string tcp = "127.0.0.1:1502";  ///< Modbus TCP HOST:PORT (port 0: any free port)
    bool rtu_pty = false;                ///< Modbus RTU on a new pseudo-terminal
    std::string rtu_device;              ///< Modbus RTU on this serial device
    int baud = 115200;
    std::string parity = "N";
    int unit = 1;
    std::string can_interface;  ///< native CAN on this SocketCAN interface instead of Modbus
    unsigned node = 1;          ///< CAN node id
    bool no_gpio = false;       ///< with a profile: do not open its GPIO lines
    bool home = false;          ///< home the profile's gpio.home axes before serving
    double time_scale = 1.0;    ///< ticks this many times faster than real time
    std::string record;         ///< CSV of every executed path tick, written at the end
    double exit_after = 0;      ///< seconds of wall time; 0 = until `stop`
    bool log_json = false;      ///< the log as NDJSON instead of text
};

/// Called once the device is configured and its lines are open, before homing: where a rig
/// attaches what stands in for the machine (sim/'s switches, through observe_ticks). What it
/// attaches must outlive run_device_runtime.
using AttachMachine = std::function<void(AnyMotionDevice& device, const DeviceLog& log)>;

/// Runs the device from `start` (LSB, one per axis) until `stop` becomes true or
/// options.exit_after passes, and returns 0. With `profile`: configured from it, its GPIO lines
/// opened (unless no_gpio), its output_coils module connected and every coil written off (a
/// writer thread then follows the machine outputs; a write the module does not confirm raises
/// FaultCode::kOutputFailed; the coils are written off again when it stops), homed (with
/// home). Throws std::invalid_argument for options or a profile the device cannot use,
/// HomingFailed when homing fails or is stopped, hal::ModbusError, hal::GpioError or
/// std::system_error when a bus, line or output module cannot be opened or written. Main
/// thread; blocks.
int run_device_runtime(const DeviceRunOptions& options, const std::vector<Lsb>& start,
                       const std::optional<host::MachineProfile>& profile,
                       const AttachMachine& attach, const std::atomic<bool>& stop);

}  // namespace pathstream::linux_device
