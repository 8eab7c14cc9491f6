// Discrete inputs with edge events (e-stop, limit switches, a drive-fault line) next to
// hal/digital_output.hpp's outputs (pen lift, drive enable). "Active" is the logical level:
// an active-low switch that pulls its line to ground reads active; the backend owns the
// inversion and the bias, so the device logic never sees electrical polarity.
#pragma once

#include <cstdint>

#include "pathstream/hal/digital_output.hpp"

namespace pathstream::hal {

/// One change of a DigitalInput, in the order they happened.
struct InputEdge {
    bool active = false;             ///< the level after the edge (true: became active)
    std::uint64_t timestamp_ns = 0;  ///< when the edge happened (backend's clock; 0 if unknown)
};

/// A digital input that reports its level and queues its edges. Freestanding: no heap, no
/// exceptions. Implementations: hal/gpio_gpiod.hpp (libgpiod, Linux), sim::SimulatedInput
/// (tests), an MCU's pin with an edge interrupt.
class DigitalInput {
public:
    virtual ~DigitalInput() = default;

    /// The level now (true: active). Bounded: one ioctl on Linux, a load in the simulator.
    /// Task context.
    virtual bool active() = 0;

    /// Takes the oldest queued edge without blocking: true and `edge` set, or false when none
    /// is queued. Edges are kept in order; a backend that loses edges (kernel buffer full)
    /// still ends on the right level because active() is read after draining. Task context.
    virtual bool next_edge(InputEdge& edge) = 0;

    /// A file descriptor that becomes readable when an edge is queued (poll(2) it, then call
    /// next_edge), or -1 when the backend has none (then poll next_edge periodically).
    virtual int event_fd() const { return -1; }
};

/// Electrical bias a backend asks the line for (what the switch's wiring needs).
enum class Bias : std::uint8_t {
    kAsIs,     ///< leave the line's configuration alone
    kDisable,  ///< no pull (an external resistor is fitted)
    kPullUp,   ///< typical for an active-low switch to ground
    kPullDown,
};

}  // namespace pathstream::hal
