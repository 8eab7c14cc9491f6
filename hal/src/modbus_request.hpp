// Private to the server: a Modbus request PDU parsed and checked against the spec's limits.
#pragma once

#include <cstddef>
#include <cstdint>

#include "pathstream/hal/modbus_register_handler.hpp"

namespace pathstream::hal::detail {

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

    bool writes() const {
        return function == kFcWriteSingle || function == kFcWriteMultiple ||
               function == kFcWriteRead;
    }
};

/// Parses `pdu` (function code first, `length` bytes, no header or CRC) in the spec's order
/// of checks: function code (kIllegalFunction), then quantities and byte counts
/// (kIllegalDataValue), then address + count <= 65536 (kIllegalDataAddress). Returns kNone
/// and fills `out` when the handler should see the request. `out.values` points into `pdu`.
ModbusException parse_modbus_request(const std::uint8_t* pdu, std::size_t length,
                                     ModbusRequest& out);

/// Big-endian register at p[0..1].
inline std::uint16_t load_be16(const std::uint8_t* p) {
    return static_cast<std::uint16_t>((p[0] << 8) | p[1]);
}

}  // namespace pathstream::hal::detail
