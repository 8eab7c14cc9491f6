// Every command a host sends the device, numbered once for every bus: the five state commands
// a plain write of the command register carries, and the operator commands that carry an axis,
// a value and a feed (docs/device.md, "Commands"; "Jog and set position").
#pragma once

#include <cstdint>

namespace pathstream::device {

/// Command values. 1..5 are state commands (the command register, the mailbox); 6..9 are
/// operator commands (OperatorCommand: a plain command write of them is kUnknownCommand).
/// Any other value is refused (Status::kUnknownCommand) before it reaches the tick.
enum class Command : std::uint16_t {
    kStart = 1,        ///< idle with spans queued: run them
    kHold = 2,         ///< running: controlled stop at the next span boundary, keep the queue
    kResume = 3,       ///< holding: move back onto the path and continue
    kStop = 4,         ///< controlled stop, then drop the queue (idle: drop the queue at once)
    kReset = 5,        ///< leaves fault or e-stop for idle
    kJog = 6,          ///< move one axis by a distance at up to a feed (jog.hpp)
    kSetPosition = 7,  ///< redefine one axis's coordinate at rest (jog.hpp)
    kHome = 8,         ///< home the axes of a mask against their switches (HomingPort)
    kPen = 9,          ///< raise or lower the pen at rest (operator_commands.hpp)
};

/// True for the five state commands (kStart..kReset). Constant, any context.
constexpr bool is_command(std::uint32_t value) {
    return value >= static_cast<std::uint32_t>(Command::kStart) &&
           value <= static_cast<std::uint32_t>(Command::kReset);
}

/// True for the operator commands (kJog..kPen). Constant, any context.
constexpr bool is_operator_command(std::uint32_t value) {
    return value >= static_cast<std::uint32_t>(Command::kJog) &&
           value <= static_cast<std::uint32_t>(Command::kPen);
}

/// The operator commands as OperatorCommand::command holds them (one byte on both buses).
inline constexpr std::uint8_t kCommandJog = static_cast<std::uint8_t>(Command::kJog);
inline constexpr std::uint8_t kCommandSetPosition =
    static_cast<std::uint8_t>(Command::kSetPosition);
inline constexpr std::uint8_t kCommandHome = static_cast<std::uint8_t>(Command::kHome);
inline constexpr std::uint8_t kCommandPen = static_cast<std::uint8_t>(Command::kPen);

}  // namespace pathstream::device
