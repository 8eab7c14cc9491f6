// What a device is told from a machine profile: its tick rate and limits in LSB, and homing
// in LSB. One conversion for every transport (Modbus and CAN streamers, `pathstream device
// --machine`), so a device configured by a host and one configured from the same profile
// hold the same numbers.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "pathstream/device/device_state.hpp"
#include "pathstream/device/gpio_logic.hpp"
#include "pathstream/device/homing.hpp"
#include "pathstream/machine/machine.hpp"

namespace pathstream::host {

/// The device's configuration: tick rate (Hz), per-axis limits (LSB/s, LSB/s^2) and the
/// pen-down delay in ticks (the lead a re-entry gives the pen).
struct DeviceLimitsLsb {
    std::uint32_t tick_hz = 0;
    std::vector<std::uint32_t> max_velocity;
    std::vector<std::uint32_t> max_acceleration;
    std::uint32_t pen_down_ticks = 0;
    /// Per axis, the travel (soft limits) in LSB: the profile's "travel" rounded inward, or
    /// the whole position range (+-2^27) without one.
    std::vector<std::int32_t> min_position;
    std::vector<std::int32_t> max_position;
    /// Per axis, the jerk limit in units of 100 LSB/s^3 (device::kJerkUnitLsb), 0: none.
    std::vector<std::uint32_t> max_jerk;
};

/// The profile's limits rounded up to whole LSB (the planner works to the profile's limits
/// exactly, so the device must allow them), its max_jerk rounded up to whole units of
/// 100 LSB/s^3 (0 without one), its pen_down_delay in ticks as the planner counts it
/// (delay_ticks), and each axis's travel rounded inward to whole LSB. Throws std::range_error
/// naming the axis when a limit does not fit 32 bits, a travel leaves the position range
/// (+-2^27 LSB), or the pen-down delay exceeds 65535 ticks.
DeviceLimitsLsb device_limits(const MachineProfile& profile);

/// Index of the axis called `name` in the profile. Throws std::invalid_argument if none.
unsigned axis_index(const MachineProfile& profile, const std::string& name);

/// "idle", "running", "holding", "stopping", "fault", "e-stop", else "unknown".
const char* device_state_name(device::DeviceState state);

/// A state as a bus carries it (a Modbus register, a CAN byte), typed. A number no state has
/// stays what it is (up to 255, larger ones become 255): device_state_name calls it
/// "unknown" and no comparison with a known state holds.
device::DeviceState device_state_of_wire(unsigned raw);

/// A device's fault code as its name: "limit switch x- (axis 0, negative side)",
/// "external fault", "fault 0x1234" (device::fault_name).
std::string fault_text(std::uint16_t fault_code);
/// " (<fault_text>)" for the fault state, "" for any other state.
std::string fault_suffix(device::DeviceState state, std::uint16_t fault_code);

/// A device position as the operator reads it: "x 12.3450 y 0.0000 mm (12345 0 LSB)", each
/// axis by its profile name; `count` values of `lsb` (at most the profile's axes).
std::string position_text(const MachineProfile& profile, const std::int32_t* lsb,
                          std::size_t count);

/// One axis's homing in the device's units, and which switch ends it.
struct HomingSetup {
    std::string axis_name;        ///< "x"
    std::string switch_name;      ///< "x-"
    device::HomingConfig config;  ///< axis, direction, velocities and distances in LSB
    device::LimitSide side = device::LimitSide::kNegative;
};

/// The profile's gpio.home entries (profile order) in LSB: velocities and distances rounded
/// to the nearest LSB (at least 1), `pull_off` = the profile's pull_off. Throws
/// std::range_error when a value does not fit the device's 32-bit fields.
std::vector<HomingSetup> homing_setups(const MachineProfile& profile);

}  // namespace pathstream::host
