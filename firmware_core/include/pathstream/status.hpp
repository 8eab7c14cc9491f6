// Result codes of the core. No exceptions exist in firmware_core: every fallible call returns
// one of these, and the compiler refuses to let a caller ignore it.
#pragma once

#include <cstdint>

namespace pathstream {

/// Outcome of a core operation. Values are stable: they travel on the wire as fault codes.
enum class [[nodiscard]] Status : std::uint8_t{
    kOk = 0,
    kTickCountOutOfRange = 1,     ///< a span must last 1..kMaxSpanTicks ticks
    kControlValueOutOfRange = 2,  ///< a control point or tangent is outside its range
    kCurveOutOfRange = 3,         ///< the curve could leave +/-kMaxCurveLsb inside the span
    kDifferenceOutOfRange = 4,    ///< a per-tick difference could exceed +/-kMaxDifferenceLsb
    kUnknownBasis = 5,            ///< basis id not one of the Basis enumerators
    kTickOutsideSpan = 6,         ///< evaluation or start tick beyond the span's end
    kQueueFull = 7,               ///< span queue has no free slot; nothing was written
    kDiscontinuousSpan = 8,       ///< span does not start where the previous one ends
    kVelocityLimit = 9,           ///< the span's exact curve is faster than an axis may move
    kAccelerationLimit = 10,      ///< the span's exact curve accelerates harder than allowed
    kBadLimits = 11,              ///< a configured limit is zero or out of range
    kNotConfigured = 12,          ///< spans or start before the limits were configured
    kBadSequence = 13,            ///< a batch does not carry the next expected sequence number
    kBadBatch = 14,               ///< a batch's length, span count or check value is wrong
    kWrongState = 15,             ///< the command is not allowed in the device's state
    kStopTooLong = 16,            ///< no controlled stop fits in one span (limits too low)
    kNothingToResume = 17,        ///< start, or resume after an underrun, needs queued spans
    kVelocityStep = 18,           ///< a span starts at another velocity than the previous one ends
    kJobEndMoving = 19,           ///< the last span of a job must end at rest (end tangents 0)
    kUnknownCommand = 20,         ///< a command value the device does not know
    kNoHoming = 21,               ///< home: no homing switch for a requested axis
    kOutsideTravel = 22,          ///< the span could leave an axis's travel (its soft limits)
    kPauseMoving = 23,            ///< a span with a pause after it must end at rest
    kJerkLimit = 24,              ///< the span's exact cubic has more jerk than an axis may
    kAccelerationStep = 25,       ///< acceleration steps at a join by more than one tick of jerk
    kBadShaper = 26,              ///< input shaper taps refused (check_shaper_taps)
};

/// Short stable name of a status, for logs and host messages. Never null.
constexpr const char* status_name(Status s) {
    switch (s) {
        case Status::kOk:
            return "ok";
        case Status::kTickCountOutOfRange:
            return "tick count out of range";
        case Status::kControlValueOutOfRange:
            return "control value out of range";
        case Status::kCurveOutOfRange:
            return "curve leaves the position range";
        case Status::kDifferenceOutOfRange:
            return "per-tick difference out of range";
        case Status::kUnknownBasis:
            return "unknown basis";
        case Status::kTickOutsideSpan:
            return "tick outside span";
        case Status::kQueueFull:
            return "span queue full";
        case Status::kDiscontinuousSpan:
            return "span does not start where the previous one ends";
        case Status::kVelocityLimit:
            return "span exceeds an axis velocity limit";
        case Status::kAccelerationLimit:
            return "span exceeds an axis acceleration limit";
        case Status::kBadLimits:
            return "limit zero or out of range";
        case Status::kNotConfigured:
            return "device limits not configured";
        case Status::kBadSequence:
            return "batch sequence number is not the next expected";
        case Status::kBadBatch:
            return "batch length, span count or check value is wrong";
        case Status::kWrongState:
            return "command not allowed in this state";
        case Status::kStopTooLong:
            return "no controlled stop fits in one span";
        case Status::kNothingToResume:
            return "nothing queued to start or resume";
        case Status::kVelocityStep:
            return "span starts at another velocity than the previous one ends";
        case Status::kJobEndMoving:
            return "the last span of a job must end at rest";
        case Status::kUnknownCommand:
            return "unknown command";
        case Status::kNoHoming:
            return "no homing switch for that axis";
        case Status::kOutsideTravel:
            return "span leaves an axis's travel (soft limits)";
        case Status::kPauseMoving:
            return "a span followed by a pause must end at rest";
        case Status::kJerkLimit:
            return "span exceeds an axis jerk limit";
        case Status::kAccelerationStep:
            return "acceleration steps at a join by more than one tick of jerk";
        case Status::kBadShaper:
            return "input shaper taps out of range or not summing to one";
    }
    return "unknown status";
}

}  // namespace pathstream
