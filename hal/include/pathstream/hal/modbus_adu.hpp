// Sizes of Modbus frames on the wire, per function code, for byte counters and bus-load
// budgets: a serial line's wire time is ADU bytes x bits per character / baud
// (docs/modbus-transport.md).
#pragma once

#include <cstddef>
#include <cstdint>

namespace pathstream::hal {

/// How a PDU is framed: RTU adds the unit id before and a CRC-16 after it; TCP puts the
/// 7-byte MBAP header (transaction, protocol, length, unit) before it.
enum class ModbusFraming : std::uint8_t { kRtu, kTcp };

inline constexpr std::size_t kModbusRtuOverheadBytes = 3;  ///< unit id + CRC-16
inline constexpr std::size_t kModbusMbapBytes = 7;         ///< TCP header, unit id included

/// ADU bytes for a PDU of `pdu_bytes` (function code included). constexpr, no cost.
constexpr std::size_t modbus_adu_bytes(ModbusFraming framing, std::size_t pdu_bytes) {
    return pdu_bytes +
           (framing == ModbusFraming::kRtu ? kModbusRtuOverheadBytes : kModbusMbapBytes);
}

// PDU sizes from the Modbus application protocol spec v1.1b3, section 6. Counts are
// registers; callers pass counts already within the function's limits.

/// FC3/FC4 request: fc, address, count.
constexpr std::size_t modbus_read_request_pdu_bytes() {
    return 5;
}
/// FC3/FC4/FC23 response: fc, byte count, 2 bytes per register.
constexpr std::size_t modbus_read_response_pdu_bytes(std::size_t count) {
    return 2 + 2 * count;
}
/// FC5 and FC6 request and their echoed response: fc, address, value.
constexpr std::size_t modbus_write_single_pdu_bytes() {
    return 5;
}
/// FC16 request: fc, address, count, byte count, 2 bytes per register.
constexpr std::size_t modbus_write_multiple_request_pdu_bytes(std::size_t count) {
    return 6 + 2 * count;
}
/// FC15 request: fc, address, count, byte count, one bit per coil.
constexpr std::size_t modbus_write_coils_request_pdu_bytes(std::size_t count) {
    return 6 + (count + 7) / 8;
}
/// FC15 and FC16 response: fc, address, count.
constexpr std::size_t modbus_write_multiple_response_pdu_bytes() {
    return 5;
}
/// FC23 request: fc, read address, read count, write address, write count, byte count,
/// 2 bytes per written register.
constexpr std::size_t modbus_write_read_request_pdu_bytes(std::size_t write_count) {
    return 10 + 2 * write_count;
}
/// Exception response: fc | 0x80, exception code.
constexpr std::size_t modbus_exception_pdu_bytes() {
    return 2;
}

/// Bits per character on a serial line: start bit + data bits + parity bit (if any) + stop
/// bits. 8E1 and 8N2 give 11; 8N1 gives 10 (common, though the RTU spec asks for 11).
constexpr unsigned modbus_serial_char_bits(int data_bits, char parity, int stop_bits) {
    return 1u + static_cast<unsigned>(data_bits) + (parity == 'N' ? 0u : 1u) +
           static_cast<unsigned>(stop_bits);
}

}  // namespace pathstream::hal
