// A Modbus request PDU parsed and checked against the spec's limits, for any server: the
// Linux transport (libmodbus underneath) and the freestanding RTU slave of a firmware image.
// Freestanding: no heap, no exceptions, no OS headers.
#pragma once

#include <cstddef>
#include <cstdint>

#include "pathstream/hal/modbus_register_handler.hpp"

namespace pathstream::hal::pdu {

inline constexpr std::uint8_t kFcReadHolding = 0x03;
inline constexpr std::uint8_t kFcReadInput = 0x04;
inline constexpr std::uint8_t kFcWriteSingle = 0x06;
inline constexpr std::uint8_t kFcWriteMultiple = 0x10;
inline constexpr std::uint8_t kFcWriteRead = 0x17;

inline constexpr std::uint16_t kMaxReadCount = 125;       // FC3, FC4, FC23 read
inline constexpr std::uint16_t kMaxWriteCount = 123;      // FC16
inline constexpr std::uint16_t kMaxWriteReadCount = 121;  // FC23 write

/// One request, ready for the handler. Addresses and counts are in registers.
struct ModbusRequest {
    std::uint8_t function = 0;
    std::uint16_t address = 0;             ///< FC3/4/6/16; FC23: the read address
    std::uint16_t count = 0;               ///< FC3/4/16 (1 for FC6); FC23: the read count
    std::uint16_t write_address = 0;       ///< FC23 only
    std::uint16_t write_count = 0;         ///< FC23 only
    const std::uint8_t* values = nullptr;  ///< big-endian register bytes to write (FC6/16/23)

    constexpr bool writes() const {
        return function == kFcWriteSingle || function == kFcWriteMultiple ||
               function == kFcWriteRead;
    }
};

/// Big-endian register at p[0..1].
constexpr std::uint16_t load_be16(const std::uint8_t* p) {
    return static_cast<std::uint16_t>((p[0] << 8) | p[1]);
}

/// A range must stay inside the 16-bit register space: address + count - 1 <= 0xFFFF.
constexpr bool range_fits(std::uint16_t address, std::uint16_t count) {
    return static_cast<std::uint32_t>(address) + count <= 0x10000u;
}

/// Parses `pdu` (function code first, `length` bytes, no header or CRC) in the spec's order
/// of checks: function code (kIllegalFunction), then quantities and byte counts
/// (kIllegalDataValue), then address + count <= 65536 (kIllegalDataAddress). Returns kNone
/// and fills `out` when the handler should see the request. `out.values` points into `pdu`.
/// Constant time; any context.
constexpr ModbusException parse_modbus_request(const std::uint8_t* pdu, std::size_t length,
                                               ModbusRequest& out) {
    if (length < 1) return ModbusException::kIllegalFunction;
    out = ModbusRequest{};
    out.function = pdu[0];
    switch (out.function) {
        case kFcReadHolding:
        case kFcReadInput:
            if (length < 5) return ModbusException::kIllegalDataValue;
            out.address = load_be16(pdu + 1);
            out.count = load_be16(pdu + 3);
            if (out.count < 1 || out.count > kMaxReadCount)
                return ModbusException::kIllegalDataValue;
            if (!range_fits(out.address, out.count)) return ModbusException::kIllegalDataAddress;
            return ModbusException::kNone;
        case kFcWriteSingle:
            if (length < 5) return ModbusException::kIllegalDataValue;
            out.address = load_be16(pdu + 1);
            out.count = 1;
            out.values = pdu + 3;
            return ModbusException::kNone;
        case kFcWriteMultiple: {
            if (length < 6) return ModbusException::kIllegalDataValue;
            out.address = load_be16(pdu + 1);
            out.count = load_be16(pdu + 3);
            const std::size_t bytes = pdu[5];
            if (out.count < 1 || out.count > kMaxWriteCount || bytes != 2u * out.count ||
                length < 6 + bytes) {
                return ModbusException::kIllegalDataValue;
            }
            if (!range_fits(out.address, out.count)) return ModbusException::kIllegalDataAddress;
            out.values = pdu + 6;
            return ModbusException::kNone;
        }
        case kFcWriteRead: {
            if (length < 10) return ModbusException::kIllegalDataValue;
            out.address = load_be16(pdu + 1);
            out.count = load_be16(pdu + 3);
            out.write_address = load_be16(pdu + 5);
            out.write_count = load_be16(pdu + 7);
            const std::size_t bytes = pdu[9];
            if (out.count < 1 || out.count > kMaxReadCount || out.write_count < 1 ||
                out.write_count > kMaxWriteReadCount || bytes != 2u * out.write_count ||
                length < 10 + bytes) {
                return ModbusException::kIllegalDataValue;
            }
            if (!range_fits(out.address, out.count) ||
                !range_fits(out.write_address, out.write_count)) {
                return ModbusException::kIllegalDataAddress;
            }
            out.values = pdu + 10;
            return ModbusException::kNone;
        }
        default:
            return ModbusException::kIllegalFunction;
    }
}

}  // namespace pathstream::hal::pdu
