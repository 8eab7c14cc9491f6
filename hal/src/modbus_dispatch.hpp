// Private to the server: one received request ADU -> handler call -> reply on the wire.
#pragma once

#include <modbus/modbus.h>

#include <cstdint>
#include <vector>

#include "pathstream/hal/modbus_adu.hpp"
#include "pathstream/hal/modbus_register_handler.hpp"

namespace pathstream::hal::detail {

/// Buffers reused across requests so that serving allocates nothing after construction.
struct DispatchScratch {
    std::vector<std::uint16_t> values = std::vector<std::uint16_t>(125);    // registers to write
    std::vector<std::uint16_t> out = std::vector<std::uint16_t>(125);       // registers read
    std::vector<std::uint16_t> window = std::vector<std::uint16_t>(65536);  // modbus_reply's view
    std::vector<std::uint8_t> request;  // a patched copy of an FC23 request (see the .cpp)
};

/// What became of one request.
struct DispatchOutcome {
    bool exception = false;  ///< answered (or, broadcast, refused) with an exception
    bool broadcast = false;  ///< RTU unit 0: never answered
    int sent = 0;  ///< ADU bytes written (0 for a broadcast), -1 if the send failed (errno set)
};

/// Parses `adu` (a whole frame from modbus_receive on `ctx`, `length` bytes with header and,
/// on RTU, CRC), calls the handler and answers through libmodbus. Cost: one handler call and
/// one write; no allocation except the first FC23 whose ranges overlap.
DispatchOutcome dispatch_modbus_request(modbus_t* ctx, ModbusFraming framing,
                                        const std::uint8_t* adu, int length,
                                        ModbusRegisterHandler& handler, DispatchScratch& scratch);

}  // namespace pathstream::hal::detail
