// The Modbus register map, declared once for both ends: the device serves it
// (modbus_register_map.hpp), the host's streaming client addresses it. docs/modbus.md has the
// table; this header is its source.
#pragma once

#include <cstdint>

namespace pathstream::device::modbus {

inline constexpr std::uint16_t kMagic = 0x5053;  ///< "PS"
/// 2: job ends (wire flag kWireJobEnd, registers 36-39), the queue epoch (40-41), the
/// pen-down delay in the configuration (+3), continuity checked at every join.
/// 3: operator commands with arguments (jog, set position, home, pen), the homing flag and
/// per-axis homing registers (42-49).
/// 4: programmed pauses (wire flag kWirePause) and the paused flag (bit 6).
/// 5: per-axis jerk limits at the end of the configuration block (config_jerk_register).
/// 6: machine-function outputs (spindle, direction, mist, flood: kOutputMachineMask), kept
/// through holds; spans with an undefined output bit are refused.
inline constexpr std::uint16_t kProtocolVersion = 6;

/// Status block: input registers (FC4) from 0, mirrored read-only in holding registers
/// (FC3/FC23) at the same addresses so one FC23 can write spans and read the status.
/// 32-bit values take two registers, high word first. Every read takes the whole block from
/// one tick's status (never a mix of two ticks).
namespace status {
inline constexpr std::uint16_t kMagic = 0;
inline constexpr std::uint16_t kVersion = 1;
inline constexpr std::uint16_t kState = 2;  ///< DeviceState
inline constexpr std::uint16_t kFaultCode = 3;
inline constexpr std::uint16_t kFreeSlots = 4;
inline constexpr std::uint16_t kCapacity = 5;
inline constexpr std::uint16_t kLastAcceptedSequence = 6;  ///< u32
inline constexpr std::uint16_t kTicksExecuted = 8;         ///< u32 (low 32 bits)
inline constexpr std::uint16_t kPositions = 10;            ///< i32 per axis, up to 8 axes
inline constexpr std::uint16_t kAxes = 26;
inline constexpr std::uint16_t kUnderruns = 27;
inline constexpr std::uint16_t kLastCompletedSequence = 28;  ///< u32
inline constexpr std::uint16_t kLastRefusal = 30;  ///< core Status of the last refused write
inline constexpr std::uint16_t kRefusals = 31;     ///< refused writes (wraps)
inline constexpr std::uint16_t kDuplicates = 32;   ///< batches acknowledged as retries (wraps)
inline constexpr std::uint16_t kOutputs = 33;      ///< discrete outputs in force
inline constexpr std::uint16_t kQueuedSpans = 34;
/// bit 0: configured, bit 1: held by underrun, bit 3: the device's own stop or re-entry
/// move, bit 4: homing runs, bit 6: paused at a programmed pause (the bits agree with CAN status A)
inline constexpr std::uint16_t kFlags = 35;
inline constexpr std::uint16_t kFinishedJob =
    36;  ///< u32: id of the last job run to its end (0: none)
inline constexpr std::uint16_t kFinishedJobTicks = 38;  ///< u32: path ticks that job executed
inline constexpr std::uint16_t kEpoch = 40;  ///< u32: queue epoch (advanced by every queue drop)
/// One register per axis, up to 8: low byte AxisHoming (0 not homed, 1 homing, 2 homed,
/// 3 failed), high byte the HomingError of a failure.
inline constexpr std::uint16_t kHoming = 42;
inline constexpr std::uint16_t kCount = 50;  ///< registers in the block
/// Registers a streaming host polls (0 .. 41): everything but the homing registers, which are
/// for an operator. Eight fewer registers per poll keep a 2-axis 1 kHz stream under half of a
/// 115200-baud RTU line (bench_modbus).
inline constexpr std::uint16_t kStreamingCount = kHoming;
}  // namespace status

/// Status flag bits (register status::kFlags).
namespace flags {
inline constexpr std::uint16_t kConfigured = 1u << 0;
inline constexpr std::uint16_t kHeldByUnderrun = 1u << 1;
inline constexpr std::uint16_t kOwnMove = 1u << 3;
inline constexpr std::uint16_t kHoming = 1u << 4;
inline constexpr std::uint16_t kPaused = 1u << 6;  ///< holding at a programmed pause (kWirePause)
}  // namespace flags

/// Command register (holding, write-only in effect; reads return the last command written).
inline constexpr std::uint16_t kCommand = 100;  ///< Command values (1 start ... 5 reset)
/// A command with arguments (6 jog, 7 set position, 8 home, 9 pen) is one FC16 of
/// kCommandWithArguments registers at kCommand: +0 command, +1 axis (home: axis bit mask,
/// 0 = all), +2..3 value (i32: jog distance or position in LSB; pen: 1 down, 0 up), +4 feed
/// (jog: per mille of the axis's max velocity, 0 = 1000; others: 0).
inline constexpr std::uint16_t kCommandWithArguments = 5;

/// Configuration block (holding), written whole in one FC16 at kConfig:
///   +0..1 tick rate (Hz, u32), +2 axes (must equal the device's), +3 pen-down delay (ticks,
///   the re-entry's pen lead), +4..9 reserved (0),
///   +10 + 4a .. : axis a max velocity (LSB/s, u32), max acceleration (LSB/s^2, u32),
///   +10 + 4 axes + 4a .. : axis a travel (soft limits): min position, max position (LSB, i32;
///   0 and 0: no limits, the whole position range),
///   +10 + 8 axes + 2a .. : axis a max jerk (units of 100 LSB/s^3, u32; 0: no jerk limit).
/// Eight axes end at register 199, just below the span window.
/// Accepted only idle with nothing queued; read back with FC3.
inline constexpr std::uint16_t kConfig = 110;
inline constexpr std::uint16_t kConfigPenDownTicks = 3;
inline constexpr std::uint16_t kConfigAxisBase = 10;
constexpr std::uint16_t config_registers(unsigned axes) {
    return static_cast<std::uint16_t>(kConfigAxisBase + 10 * axes);
}
/// First register of axis `axis`'s travel (min, then max) in a device of `axes` axes.
constexpr std::uint16_t config_travel_register(unsigned axes, unsigned axis) {
    return static_cast<std::uint16_t>(kConfigAxisBase + 4 * axes + 4 * axis);
}
/// First register (high word) of axis `axis`'s max jerk in a device of `axes` axes.
constexpr std::uint16_t config_jerk_register(unsigned axes, unsigned axis) {
    return static_cast<std::uint16_t>(kConfigAxisBase + 8 * axes + 2 * axis);
}

/// Span window (holding): one FC16 (or the write half of an FC23) at kSpanWindow carries
///   +0..1 first sequence number (u32), +2 span count, +3 payload bytes, +4 CRC-16/MODBUS of
///   the payload, +5.. payload (wire spans, two bytes per register, big-endian, the last
///   register padded with a zero byte).
inline constexpr std::uint16_t kSpanWindow = 200;
static_assert(kConfig + config_registers(8) <= kSpanWindow,
              "the configuration block ends below the span window");
inline constexpr std::uint16_t kSpanHeaderRegisters = 5;
/// Largest FC16 write (123 registers) minus the header: payload registers per batch.
inline constexpr std::uint16_t kMaxPayloadRegistersFc16 = 123 - kSpanHeaderRegisters;
/// Largest FC23 write (121 registers) minus the header.
inline constexpr std::uint16_t kMaxPayloadRegistersFc23 = 121 - kSpanHeaderRegisters;

/// Exception codes the map answers with (Modbus values).
enum class Exception : std::uint8_t {
    kNone = 0,
    kIllegalFunction = 1,
    kIllegalDataAddress = 2,  ///< no such register, or a block written partially
    kIllegalDataValue = 3,  ///< a value refused (bad span, sequence, limits, check value, command)
    kServerDeviceFailure =
        4,  ///< refused by the state (fault, e-stop, not configured, nothing to resume)
    kServerDeviceBusy = 6,  ///< queue full: retry the same batch later
};

}  // namespace pathstream::device::modbus
