// The operator's commands with arguments, the same on every bus: jog, set position, home and
// pen. Modbus (FC16 at the command register) and CAN (the CommandArgs frame) decode their
// frame into an OperatorCommand and hand it here; the device carries each out itself within
// its configured limits (docs/device.md, "Operator commands").
#pragma once

#include <cstdint>

#include "pathstream/device/command.hpp"
#include "pathstream/device/homing.hpp"
#include "pathstream/device/jog.hpp"
#include "pathstream/device/motion_device.hpp"

namespace pathstream::device {

/// A command with its arguments as both buses carry it.
struct OperatorCommand {
    std::uint8_t command = 0;  ///< kCommandJog .. kCommandPen
    std::uint16_t axis = 0;    ///< jog, set position: axis index; home: axis bit mask (0: all)
    std::int32_t value = 0;    ///< jog: distance; set position: position (LSB); pen: 1 down, 0 up
    std::uint16_t feed = 0;    ///< jog: per mille of the axis's max velocity; others: 0
};

/// Homing on command, provided by the port that owns the switches (its I/O glue runs the
/// HomingSequencer axis by axis against them). Plain function pointers so the core needs no
/// virtual call; `start` null means the device has no switches (home is kNoHoming).
struct HomingPort {
    void* context = nullptr;
    /// Starts homing the axes in `axes` (bit a: axis a; 0: every axis the port can home), one
    /// after another in the port's order. kNoHoming when one has no switch, kWrongState unless
    /// idle with nothing queued and no homing running, a sequencer refusal otherwise. Task.
    Status (*start)(void* context, std::uint8_t axes) = nullptr;
    /// True while a homing run goes on. Task.
    bool (*busy)(const void* context) = nullptr;
    /// Axis `axis`'s homing state. Task.
    HomingReport (*report)(const void* context, unsigned axis) = nullptr;
};

/// The commands with arguments of one device. Task context only (the bus task), the task
/// that owns the device's producer side; service() from its loop. Storage inline.
template <unsigned Axes, std::uint32_t Capacity>
class OperatorCommands {
public:
    explicit OperatorCommands(MotionDevice<Axes, Capacity>& device)
        : device_(device), jog_(device) {}

    /// Connects the port's homing (init, or whenever the port's switches are set up).
    void set_homing(const HomingPort& port) { homing_ = port; }

    /// Carries out `c`: kOk once started (a jog and a homing run go on in service() and the
    /// port's loop), else the refusal: kUnknownCommand for a value that is none of the four;
    /// kControlValueOutOfRange for an argument a command does not take (a feed on set
    /// position, an axis or feed on pen, a value or feed on home, a pen value other than 0 or
    /// 1, a home mask with a bit at or above Axes); kWrongState for any of them while homing
    /// runs; the command's own refusals otherwise.
    [[nodiscard]] Status execute(const OperatorCommand& c) {
        // Homing moves the device between its own idle moments: nothing else may move it or
        // redefine its position then.
        if (c.command >= kCommandJog && c.command <= kCommandPen && homing())
            return Status::kWrongState;
        switch (c.command) {
            case kCommandJog:
                return jog_.start(c.axis, c.value, c.feed);
            case kCommandSetPosition:
                if (c.feed != 0) return Status::kControlValueOutOfRange;
                return set_axis_position(device_, c.axis, c.value);
            case kCommandHome:
                if (c.value != 0 || c.feed != 0 || c.axis >= (1u << Axes))
                    return Status::kControlValueOutOfRange;
                if (homing_.start == nullptr) return Status::kNoHoming;
                return homing_.start(homing_.context, static_cast<std::uint8_t>(c.axis));
            case kCommandPen:
                if (c.axis != 0 || c.feed != 0 || (c.value != 0 && c.value != 1))
                    return Status::kControlValueOutOfRange;
                return device_.set_pen(c.value == 1);
            default:
                return Status::kUnknownCommand;
        }
    }

    /// Task loop: feeds a jog in progress (at least once per span period).
    void service() { jog_.service(); }

    /// True while a homing run goes on.
    bool homing() const { return homing_.busy != nullptr && homing_.busy(homing_.context); }

    /// Axis `axis`'s homing state (kNotHomed on a device without switches).
    HomingReport homing_report(unsigned axis) const {
        if (homing_.report == nullptr) return HomingReport{};
        return homing_.report(homing_.context, axis);
    }

private:
    MotionDevice<Axes, Capacity>& device_;
    Jog<Axes, Capacity> jog_;
    HomingPort homing_{};
};

}  // namespace pathstream::device
