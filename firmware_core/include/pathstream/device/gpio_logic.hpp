// What the device's discrete I/O means, as pure functions of the device state: when the drive
// enables are asserted, when the pen is down and the spindle and coolant are on, which fault a
// limit switch raises, and a fault code's name. The I/O glue (sim/gpio, the libgpiod driver)
// applies them; keeping the rules here makes them the same on every port and testable without any
// I/O.
#pragma once

#include <cstddef>
#include <cstdint>

#include "pathstream/device/motion_device.hpp"
#include "pathstream/span.hpp"

namespace pathstream::device {

/// Which end of an axis a limit switch guards.
enum class LimitSide : std::uint8_t {
    kNegative = 0,  ///< "x-": the switch hit when moving toward lower positions
    kPositive = 1,  ///< "x+"
};

/// The fault a limit switch raises: kLimitSwitchBase + axis * 2 + side. `axis` < kMaxAxes.
constexpr FaultCode limit_fault(unsigned axis, LimitSide side) {
    return static_cast<FaultCode>(static_cast<unsigned>(FaultCode::kLimitSwitchBase) + axis * 2u +
                                  static_cast<unsigned>(side));
}

/// True when `code` is a limit-switch fault; then `axis` and `side` say which switch.
constexpr bool limit_fault_switch(FaultCode code, unsigned& axis, LimitSide& side) {
    const unsigned c = static_cast<unsigned>(code);
    const unsigned base = static_cast<unsigned>(FaultCode::kLimitSwitchBase);
    if (c < base || c >= base + 2u * kMaxAxes) return false;
    axis = (c - base) / 2u;
    side = static_cast<LimitSide>((c - base) % 2u);
    return true;
}

/// Drive enables are asserted only while the device may move or must hold a position under
/// control: running, holding (a held axis is servoed, not free) and stopping. Idle (also after
/// a stop), fault and e-stop drop them: a drive without enable cannot move whatever the
/// setpoints say, which is what makes the e-stop independent of the motion code.
constexpr bool enable_asserted(DeviceState state) {
    return state == DeviceState::kRunning || state == DeviceState::kHolding ||
           state == DeviceState::kStopping;
}

/// The pen-lift output: `outputs` are those the device's last tick drove (MotionDevice::
/// outputs): the playing span's on a path tick (the planner's pen events sit at span
/// boundaries), none on any other tick (stop, re-entry except its pen-down lead, rest), so the
/// device's own stop and re-entry moves never draw. Idle, the pen is down only where the
/// operator lowered it (set_pen: the tick's idle outputs are that pen and nothing else); in
/// fault and in e-stop it is always up, so a frozen axis does not leave a blot.
constexpr bool pen_down(DeviceState state, std::uint8_t outputs) {
    return (enable_asserted(state) || state == DeviceState::kIdle) &&
           (outputs & kOutputPenDown) != 0;
}

/// How many machine functions have an output of their own (spindle, its direction, mist,
/// flood).
inline constexpr unsigned kMachineOutputCount = 4;

/// The machine functions' span output bits, in the order every wiring lists their outputs
/// (a profile's gpio lines and output coils, the firmware's pins).
inline constexpr std::uint8_t kMachineOutputBits[kMachineOutputCount] = {
    kOutputSpindle, kOutputSpindleReverse, kOutputMist, kOutputFlood};

/// A machine function's output (`bit`: kOutputSpindle, kOutputSpindleReverse, kOutputMist or
/// kOutputFlood): on only while the drives are enabled (enable_asserted) and the outputs the
/// device's last tick drove (MotionDevice::outputs) have the bit. The device already keeps
/// these bits through a hold, an underrun, a stop within a span and a re-entry, and drops them
/// when it goes idle, faults or sees the e-stop; the rule repeats the enable condition so that
/// an output is never on while the drives are not, whatever a port does with the byte (the
/// e-stop switches a spindle off with the drives). Pure, O(1), any context.
constexpr bool machine_output_on(DeviceState state, std::uint8_t outputs, std::uint8_t bit) {
    return enable_asserted(state) && (outputs & kOutputMachineMask & bit) != 0;
}

/// Every machine function's output at once: the bits of kOutputMachineMask that
/// machine_output_on() turns on (what an output module is sent). Pure, O(1), any context.
constexpr std::uint8_t machine_outputs_on(DeviceState state, std::uint8_t outputs) {
    return enable_asserted(state) ? static_cast<std::uint8_t>(outputs & kOutputMachineMask) : 0;
}

/// Writes a NUL-terminated English name of `code` into out[0..capacity): "none", "external
/// fault", "no controlled stop fits in one span", "a machine output could not be switched",
/// "limit switch x- (axis 0, negative side)"
/// (axes 0..7 named x y z a b c u v), or "fault 0x1234". Returns the length written (without
/// the NUL), truncated to capacity - 1; nothing is written when capacity is 0. No heap.
/// Any context.
std::size_t fault_name(FaultCode code, char* out, std::size_t capacity);

}  // namespace pathstream::device
