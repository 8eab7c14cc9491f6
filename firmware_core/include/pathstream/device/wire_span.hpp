// The span as it travels on a bus: a Hermite span whose start is implied (the previous
// span's end), declared once here for the device (decode) and the host (encode).
//
// Layout, big-endian (Modbus register order), docs/device.md:
//   u16 ticks - 1 | u8 flags | u8 outputs | per axis: i32 P1, i32 T1 [, i32 T0]
// T0 is present unless flags has kWireContinueTangent, in which case it equals the previous
// span's T1 (the planner shares tangents between spans of equal length, so most spans omit it).
// kWireJobEnd marks the last span of a job; kWirePause a programmed pause after a span.
#pragma once

#include <cstddef>
#include <cstdint>

#include "pathstream/span.hpp"
#include "pathstream/status.hpp"
#include "pathstream/units.hpp"

namespace pathstream::device {

/// Flag: T0 of every axis equals the previous span's T1 and is not sent.
inline constexpr std::uint8_t kWireContinueTangent = 1u << 0;
/// Flag: the last span of a job. It must end at rest (every T1 = 0); the device runs it to its
/// end, reports the job finished and becomes idle there (docs/device.md, "Jobs").
inline constexpr std::uint8_t kWireJobEnd = 1u << 1;
/// Flag: a programmed pause after this span (a pen change, G-code M0). It must end at rest;
/// the device holds there with the pen up, as after a hold command, until it is resumed.
inline constexpr std::uint8_t kWirePause = 1u << 2;
/// Flags a receiver understands; any other bit set makes the span invalid.
inline constexpr std::uint8_t kWireKnownFlags = kWireContinueTangent | kWireJobEnd | kWirePause;

/// Bytes of one wire span for `axes` axes. Constant, any context.
constexpr std::size_t wire_span_bytes(unsigned axes, bool continue_tangent) {
    return 4 + static_cast<std::size_t>(axes) * (continue_tangent ? 8u : 12u);
}

/// A Hermite span in wire terms, all axes (unused axes ignored).
struct WireSpan {
    std::uint32_t ticks = 1;  ///< 1..kMaxSpanTicks
    std::uint8_t flags = 0;   ///< kWireContinueTangent | kWireJobEnd | kWirePause
    std::uint8_t outputs = 0;
    std::int32_t end[kMaxAxes] = {};            ///< P1
    std::int32_t end_tangent[kMaxAxes] = {};    ///< T1
    std::int32_t start_tangent[kMaxAxes] = {};  ///< T0 (sent only without kWireContinueTangent)
};

/// Writes `span` for `axes` axes to out[0..wire_span_bytes). Returns the bytes written, or 0
/// when `capacity` is too small or ticks is out of range (nothing meaningful written).
/// Cost: O(axes). Any context.
std::size_t encode_wire_span(const WireSpan& span, unsigned axes, std::uint8_t* out,
                             std::size_t capacity);

/// Reads one wire span for `axes` axes from bytes[0..available) into `out` and sets
/// `consumed`. Errors: kBadBatch (truncated, unknown flag bits), kTickCountOutOfRange never
/// (every u16 + 1 is a valid count). `out.start_tangent` is left as is when the span continues
/// the tangent: the caller fills it from the previous span. Cost: O(axes). Any context.
[[nodiscard]] Status decode_wire_span(const std::uint8_t* bytes, std::size_t available,
                                      unsigned axes, WireSpan& out, std::size_t& consumed);

/// The core Span of a wire span that starts at `start` (LSB per axis): Hermite P0 = start,
/// P1 = end, T0 = start_tangent, T1 = end_tangent; tag and outputs copied. O(Axes).
template <unsigned Axes>
Span<Axes> to_core_span(const WireSpan& w, const Lsb (&start)[Axes], std::uint32_t tag) {
    Span<Axes> s;
    s.basis = Basis::kHermite;
    s.ticks = w.ticks;
    s.tag = tag;
    s.outputs = w.outputs;
    for (unsigned a = 0; a < Axes; ++a) {
        s.control[a][0] = start[a];
        s.control[a][1] = w.end[a];
        s.control[a][2] = w.start_tangent[a];
        s.control[a][3] = w.end_tangent[a];
    }
    return s;
}

/// CRC-16/MODBUS (reflected polynomial 0xA001, initial 0xFFFF) of bytes[0..length): the
/// batch check value. Bitwise, no table (~8 shifts per byte). Any context.
std::uint16_t crc16_modbus(const std::uint8_t* bytes, std::size_t length);

}  // namespace pathstream::device
