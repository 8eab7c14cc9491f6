// Where a Modbus client connects, written as a URL:
//   modbus-tcp://HOST:PORT?unit=N
//   modbus-rtu:///dev/ttyX?baud=115200&parity=N&data_bits=8&stop_bits=1&unit=1
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "pathstream/hal/modbus_serial_line.hpp"

namespace pathstream::hal {

/// A parsed target URL. Host-side value type.
struct ModbusTarget {
    enum class Transport : std::uint8_t { kTcp, kRtu };
    Transport transport = Transport::kTcp;
    std::string host;          ///< TCP: name or address ("[::1]" URLs give "::1")
    std::uint16_t port = 502;  ///< TCP: 1..65535, 502 when the URL omits it
    ModbusSerialLine serial;   ///< RTU: device and character format
    int unit = 1;              ///< TCP: 0..255; RTU: 0..247 (0 = broadcast, writes only)
};

/// Parses a target URL. Every part is checked; the error names the URL and the part:
///   bad target URL 'x': unknown scheme (want modbus-tcp:// or modbus-rtu://)
///   bad target URL 'modbus-tcp://h:99999': port '99999' is not a number in 1..65535
///   bad target URL '...': unknown parameter 'bud' (want unit, baud, parity, data_bits, stop_bits)
/// Query parameters: unit (both); baud, parity (N, E, O; case-insensitive), data_bits (5..8),
/// stop_bits (1, 2) for RTU only. Throws std::invalid_argument. Cost: a few small strings.
ModbusTarget parse_modbus_target(std::string_view url);

/// The canonical URL of a target (every RTU parameter spelled out); parses back to `target`.
std::string to_string(const ModbusTarget& target);

}  // namespace pathstream::hal
