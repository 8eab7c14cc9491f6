// Result codes of the core. No exceptions exist in firmware_core: every fallible call returns
// one of these, and the compiler refuses to let a caller ignore it.
#pragma once

#include <cstdint>

namespace pathstream {

/// Outcome of a core operation. Values are stable: they travel on the wire as fault codes.
enum class [[nodiscard]] Status : std::uint8_t {
    kOk = 0,
    kTickCountOutOfRange = 1,      ///< a span must last 1..kMaxSpanTicks ticks
    kControlValueOutOfRange = 2,   ///< a control point or tangent is outside its range
    kCurveOutOfRange = 3,          ///< the curve could leave +/-kMaxCurveLsb inside the span
    kDifferenceOutOfRange = 4,     ///< a per-tick difference could exceed +/-kMaxDifferenceLsb
    kUnknownBasis = 5,             ///< basis id not one of the Basis enumerators
    kTickOutsideSpan = 6,          ///< evaluation or start tick beyond the span's end
    kQueueFull = 7,                ///< span queue has no free slot; nothing was written
    kDiscontinuousSpan = 8,        ///< span does not start where the previous one ends
};

/// Short stable name of a status, for logs and host messages. Never null.
constexpr const char* status_name(Status s) {
    switch (s) {
        case Status::kOk: return "ok";
        case Status::kTickCountOutOfRange: return "tick count out of range";
        case Status::kControlValueOutOfRange: return "control value out of range";
        case Status::kCurveOutOfRange: return "curve leaves the position range";
        case Status::kDifferenceOutOfRange: return "per-tick difference out of range";
        case Status::kUnknownBasis: return "unknown basis";
        case Status::kTickOutsideSpan: return "tick outside span";
        case Status::kQueueFull: return "span queue full";
        case Status::kDiscontinuousSpan: return "span does not start where the previous one ends";
    }
    return "unknown status";
}

}  // namespace pathstream
