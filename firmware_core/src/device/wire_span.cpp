#include "pathstream/device/wire_span.hpp"

namespace pathstream::device {
namespace {

void put_u16(std::uint8_t*& p, std::uint32_t v) {
    *p++ = static_cast<std::uint8_t>((v >> 8) & 0xFFu);
    *p++ = static_cast<std::uint8_t>(v & 0xFFu);
}

void put_i32(std::uint8_t*& p, std::int32_t v) {
    const std::uint32_t u = static_cast<std::uint32_t>(v);  // two's complement on the wire
    put_u16(p, u >> 16);
    put_u16(p, u & 0xFFFFu);
}

std::uint32_t get_u16(const std::uint8_t*& p) {
    const std::uint32_t v = (static_cast<std::uint32_t>(p[0]) << 8) | p[1];
    p += 2;
    return v;
}

std::int32_t get_i32(const std::uint8_t*& p) {
    const std::uint32_t high = get_u16(p);
    const std::uint32_t u = (high << 16) | get_u16(p);
    // Two's complement back to signed without implementation-defined conversion.
    return u <= 0x7FFFFFFFu ? static_cast<std::int32_t>(u) : -static_cast<std::int32_t>(~u) - 1;
}

}  // namespace

std::size_t encode_wire_span(const WireSpan& span, unsigned axes, std::uint8_t* out,
                             std::size_t capacity) {
    const bool continues = (span.flags & kWireContinueTangent) != 0;
    const std::size_t size = wire_span_bytes(axes, continues);
    if (axes < 1 || axes > kMaxAxes || capacity < size || span.ticks < 1 ||
        span.ticks > kMaxSpanTicks || (span.flags & ~kWireKnownFlags) != 0) {
        return 0;
    }
    std::uint8_t* p = out;
    put_u16(p, span.ticks - 1);
    *p++ = span.flags;
    *p++ = span.outputs;
    for (unsigned a = 0; a < axes; ++a) {
        put_i32(p, span.end[a]);
        put_i32(p, span.end_tangent[a]);
        if (!continues) put_i32(p, span.start_tangent[a]);
    }
    return size;
}

Status decode_wire_span(const std::uint8_t* bytes, std::size_t available, unsigned axes,
                        WireSpan& out, std::size_t& consumed) {
    if (axes < 1 || axes > kMaxAxes || available < 4) return Status::kBadBatch;
    const std::uint8_t* p = bytes;
    const std::uint32_t ticks = get_u16(p) + 1;
    const std::uint8_t flags = *p++;
    const std::uint8_t outputs = *p++;
    if ((flags & ~kWireKnownFlags) != 0 || (outputs & ~kOutputKnownMask) != 0)
        return Status::kBadBatch;
    const bool continues = (flags & kWireContinueTangent) != 0;
    const std::size_t size = wire_span_bytes(axes, continues);
    if (available < size) return Status::kBadBatch;
    out.ticks = ticks;
    out.flags = flags;
    out.outputs = outputs;
    for (unsigned a = 0; a < axes; ++a) {
        out.end[a] = get_i32(p);
        out.end_tangent[a] = get_i32(p);
        if (!continues) out.start_tangent[a] = get_i32(p);
    }
    consumed = size;
    return Status::kOk;
}

std::uint16_t crc16_modbus(const std::uint8_t* bytes, std::size_t length) {
    std::uint32_t crc = 0xFFFFu;
    for (std::size_t i = 0; i < length; ++i) {
        crc ^= bytes[i];
        for (int bit = 0; bit < 8; ++bit) crc = (crc & 1u) != 0 ? (crc >> 1) ^ 0xA001u : crc >> 1;
    }
    return static_cast<std::uint16_t>(crc);
}

}  // namespace pathstream::device
