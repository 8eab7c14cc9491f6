// The device's vocabulary, shared by its task side (device_receiver.hpp), its tick side
// (device_executor.hpp) and every protocol on top: states, commands, fault codes, and the
// status snapshot the tick publishes once per tick.
#pragma once

#include <cstdint>

#include "pathstream/device/command.hpp"
#include "pathstream/units.hpp"

namespace pathstream::device {

/// Device state; values are the Modbus status register's (docs/modbus.md).
enum class DeviceState : std::uint8_t {
    kIdle = 0,      ///< not moving; spans may be queued; start begins execution
    kRunning = 1,   ///< executing spans (at rest when the queue is dry at a stop point)
    kHolding = 2,   ///< decelerating to, or resting at, a hold (command or underrun)
    kStopping = 3,  ///< decelerating; then the queue is dropped and the state becomes idle
    kFault = 4,     ///< stopped at once by a fault; reset leaves it
    kEstop = 5,     ///< stopped at once by the e-stop; reset (input released) leaves it
};

/// Fault codes (the status block's fault register). 0x01xx: axis limit switch, low byte =
/// axis * 2 + side (0 negative, 1 positive); reported by the GPIO layer.
enum class FaultCode : std::uint16_t {
    kNone = 0,
    kExternal = 1,       ///< raised by the integration (e.g. a drive fault input)
    kStopFailed = 2,     ///< no controlled stop fits in one span: stopped at once
    kReentryFailed = 3,  ///< resume: no move back onto the path fits in one span
    /// A machine function's output (spindle, coolant) could not be switched: its output
    /// module did not confirm a write (raised by the integration, e.g. `pathstream device`'s
    /// output coils).
    kOutputFailed = 4,
    kLimitSwitchBase = 0x100,
};

/// Maximum spans in one batch (bounded so validation needs no storage per span).
inline constexpr std::uint16_t kMaxBatchSpans = 64;

/// DeviceStatus::flags bits.
inline constexpr std::uint32_t kStatusHeldByUnderrun = 1u
                                                       << 0;  ///< holding because the queue ran dry
inline constexpr std::uint32_t kStatusPathTick = 1u << 1;     ///< the last tick was a path tick
/// The last tick was a tick of the device's own move (a controlled stop or a re-entry): a
/// holding device without it rests. Set and cleared only when the move starts and ends.
inline constexpr std::uint32_t kStatusOwnMove = 1u << 2;
/// Holding at a programmed pause (a span with kWirePause ended): the job waits for the
/// operator's resume. Cleared when the hold ends (resume, stop, fault, reset).
inline constexpr std::uint32_t kStatusPaused = 1u << 3;

/// Everything the tick side tells the task side, published whole by every tick and read whole
/// by the task (StatusBoard, a sequence lock): no field is ever seen from two different ticks.
/// Written only by the tick (DeviceExecutor::tick); read by any task. Plain 32-bit words, so
/// publishing is a word copy (no 64-bit access, which would tear on a 32-bit MCU).
template <unsigned Axes>
struct DeviceStatus {
    // Words a path tick changes: first, so that the tick publishes only these on a tick in
    // the middle of a span (StatusBoard's hot prefix, kHotWords).
    std::uint32_t tick_count = 0;  ///< ticks run since construction (wraps); == tick_check
    std::uint32_t flags = 0;       ///< kStatusHeldByUnderrun, kStatusPathTick, kStatusOwnMove
    std::uint32_t outputs = 0;     ///< discrete outputs the last tick drove (kOutputPenDown)
    Lsb position[Axes] = {};       ///< setpoints the last tick output
    std::uint32_t ticks_executed_low = 0;  ///< path ticks executed (64 bits in two words)
    std::uint32_t ticks_executed_high = 0;
    std::uint32_t last_completed_sequence = 0;  ///< sequence of the last span executed to its end
    std::uint32_t tick_check = 0;               ///< == tick_count: a torn copy would differ
    // Words that change only on a tick that changes the state, the queue, the job or applies
    // a request (every word after the hot ones).
    std::uint32_t state = 0;  ///< DeviceState
    /// FaultCode: kNone until a fault; kept through an e-stop that follows it; a reset clears it.
    std::uint32_t fault_code = 0;
    /// Advanced by every queue drop (stop, e-stop, fault, reset, set position); spans stamped
    /// with an older epoch are never executed.
    std::uint32_t epoch = 0;
    Lsb origin[Axes] = {};                  ///< where the first span of this epoch must start
    std::uint32_t generated_ticks_low = 0;  ///< ticks of the device's own stop and re-entry moves
    std::uint32_t generated_ticks_high = 0;
    std::uint32_t underruns = 0;           ///< controlled stops because the queue ran dry
    std::uint32_t job = 0;                 ///< job of the span in progress or last played (0: none)
    std::uint32_t span_epoch = 0;          ///< epoch stamp of the span in progress or last played
    std::uint32_t finished_job = 0;        ///< id of the last job run to its end (0: none yet)
    std::uint32_t finished_job_ticks = 0;  ///< path ticks that job executed (low 32 bits)
    std::uint32_t command_applied = 0;     ///< last command word the tick took from the mailbox
    std::uint32_t position_applied = 0;    ///< last set_position request the tick took

    /// Words from tick_count to tick_check: the ones a tick in the middle of a span changes.
    static constexpr unsigned kHotWords = 7 + Axes;

    DeviceState device_state() const { return static_cast<DeviceState>(state); }
    FaultCode fault() const { return static_cast<FaultCode>(fault_code); }
    bool held_by_underrun() const { return (flags & kStatusHeldByUnderrun) != 0; }
    bool path_tick() const { return (flags & kStatusPathTick) != 0; }
    bool own_move() const { return (flags & kStatusOwnMove) != 0; }
    bool paused() const { return (flags & kStatusPaused) != 0; }
    std::uint64_t ticks_executed() const {
        return (static_cast<std::uint64_t>(ticks_executed_high) << 32) | ticks_executed_low;
    }
    std::uint64_t generated_ticks() const {
        return (static_cast<std::uint64_t>(generated_ticks_high) << 32) | generated_ticks_low;
    }
};

}  // namespace pathstream::device
