// The discrete lines of a machine, as a firmware image drives them: step and direction per
// axis, outputs (drive enable, pen lift) and inputs read as levels (e-stop, limit switches).
// Concepts rather than virtual classes, so that an image links no vtable and no deleting
// destructor; the Linux side's virtual DigitalOutput and DigitalInput have the same shape
// (tests/hal/test_machine_lines.cpp checks it). Freestanding, header-only.
#pragma once

#include <concepts>
#include <cstdint>

namespace pathstream::hal {

/// Step and direction lines of up to 32 axes; every mask has bit a for axis a. All three calls
/// are bounded and non-blocking (one register write on a microcontroller) and may be called
/// from the tick and step interrupts.
template <typename L>
concept StepDirLines = requires(L& lines, std::uint32_t mask) {
    /// Direction levels of every axis at once: bit set, the axis moves forward.
    lines.set_directions(mask);
    /// Raises the step lines of the axes in `mask` (the drivers step on this edge).
    lines.raise_steps(mask);
    /// Lowers them again (after the drivers' minimum pulse width).
    lines.lower_steps(mask);
};

/// One discrete output: `set(true)` asserts it (whatever its electrical polarity). Bounded,
/// non-blocking; setting the current state again changes nothing.
template <typename L>
concept OutputLine = requires(L& line, bool active) {
    line.set(active);
};

/// One discrete input read as a level: `active()` is true while it is asserted (after its
/// polarity: an active-low switch reads true when pulled low). Bounded, non-blocking.
template <typename L>
concept InputLevel = requires(L& line) {
    { line.active() } -> std::convertible_to<bool>;
};

}  // namespace pathstream::hal
