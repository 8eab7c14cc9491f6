// One discrete output line: a plotter's pen lift, a drive enable, a brake.
#pragma once

namespace pathstream::hal {

/// A digital output. `true` means active (pen down, drive enabled), whatever the electrical
/// polarity: the backend owns the inversion. Freestanding: no heap, no exceptions.
class DigitalOutput {
public:
    virtual ~DigitalOutput() = default;

    /// Drives the line. Bounded and non-blocking: a register write on an MCU, one ioctl
    /// (libgpiod) on Linux, a vector append in the simulator (only when the state changes).
    /// Setting the current state again is allowed and changes nothing. Callable from the tick
    /// context: the device loop calls it right after each tick() with the stream's outputs.
    virtual void set(bool active) = 0;
};

}  // namespace pathstream::hal
