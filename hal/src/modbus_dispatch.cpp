#include "modbus_dispatch.hpp"

#include <algorithm>

#include "modbus_request.hpp"

namespace pathstream::hal::detail {
namespace {

void decode_registers(const std::uint8_t* bytes, std::uint16_t count, std::uint16_t* out) {
    for (std::uint16_t i = 0; i < count; ++i) out[i] = load_be16(bytes + 2 * i);
}

ModbusException call_handler(ModbusRegisterHandler& handler, const ModbusRequest& req,
                             DispatchScratch& s) {
    switch (req.function) {
        case kFcReadHolding:
            return handler.read_holding_registers(req.address, req.count, s.out.data());
        case kFcReadInput:
            return handler.read_input_registers(req.address, req.count, s.out.data());
        case kFcWriteSingle:
        case kFcWriteMultiple:
            decode_registers(req.values, req.count, s.values.data());
            return handler.write_holding_registers(req.address, req.count, s.values.data());
        case kFcWriteRead:
            decode_registers(req.values, req.write_count, s.values.data());
            return handler.write_read_holding_registers(req.write_address, req.write_count,
                                                        s.values.data(), req.address, req.count,
                                                        s.out.data());
        default:
            return ModbusException::kIllegalFunction;
    }
}

// libmodbus builds success responses from a modbus_mapping_t (modbus_reply): we point one at
// exactly the requested range, filled from the handler. modbus_reply echoes the transaction
// id and unit, adds the CRC or MBAP, and suppresses replies to RTU broadcasts.
int reply_success(modbus_t* ctx, const ModbusRequest& req, const std::uint8_t* adu, int length,
                  DispatchScratch& s) {
    modbus_mapping_t map{};
    switch (req.function) {
        case kFcReadInput:
            map.start_input_registers = req.address;
            map.nb_input_registers = req.count;
            map.tab_input_registers = s.out.data();
            return modbus_reply(ctx, adu, length, &map);
        case kFcReadHolding:
            map.start_registers = req.address;
            map.nb_registers = req.count;
            map.tab_registers = s.out.data();
            return modbus_reply(ctx, adu, length, &map);
        case kFcWriteSingle:
        case kFcWriteMultiple:
            // modbus_reply stores the values into the mapping (already done by the handler:
            // this copy is thrown away) and echoes address and count.
            map.start_registers = req.address;
            map.nb_registers = req.count;
            map.tab_registers = s.values.data();
            return modbus_reply(ctx, adu, length, &map);
        case kFcWriteRead: {
            // modbus_reply writes the request's values into the mapping, then reads the read
            // range from it. One window must cover both ranges; where they overlap, the
            // handler's read result (which may differ from what was written: a register map
            // may transform or refuse parts) must win, so we hand modbus_reply a copy of the
            // request whose overlapping write values are the handler's read values.
            const std::uint32_t lo = std::min(req.address, req.write_address);
            const std::uint32_t hi = std::max<std::uint32_t>(req.address + req.count,
                                                             req.write_address + req.write_count);
            std::copy(s.out.begin(), s.out.begin() + req.count,
                      s.window.begin() + (req.address - lo));
            s.request.assign(adu, adu + length);
            const int header = modbus_get_header_length(ctx);
            std::uint8_t* values = s.request.data() + header + 10;  // FC23 write values
            for (std::uint32_t a = req.write_address; a < req.write_address + req.write_count;
                 ++a) {
                if (a >= req.address && a < static_cast<std::uint32_t>(req.address) + req.count) {
                    const std::uint16_t v = s.out[a - req.address];
                    values[2 * (a - req.write_address)] = static_cast<std::uint8_t>(v >> 8);
                    values[2 * (a - req.write_address) + 1] = static_cast<std::uint8_t>(v & 0xFF);
                }
            }
            // The copy's CRC is stale; modbus_reply does not check it (modbus_receive did).
            map.start_registers = static_cast<int>(lo);
            map.nb_registers = static_cast<int>(hi - lo);
            map.tab_registers = s.window.data();
            return modbus_reply(ctx, s.request.data(), length, &map);
        }
        default:
            return -1;  // unreachable: parse_modbus_request accepted only the cases above
    }
}

}  // namespace

DispatchOutcome dispatch_modbus_request(modbus_t* ctx, ModbusFraming framing,
                                        const std::uint8_t* adu, int length,
                                        ModbusRegisterHandler& handler, DispatchScratch& s) {
    DispatchOutcome outcome;
    const int header = modbus_get_header_length(ctx);
    const int trailer = framing == ModbusFraming::kRtu ? 2 : 0;  // CRC
    const std::uint8_t unit = adu[header - 1];
    outcome.broadcast = framing == ModbusFraming::kRtu && unit == 0;

    const int pdu_length = length - header - trailer;
    ModbusRequest req;
    ModbusException ex =
        pdu_length < 1
            ? ModbusException::kIllegalFunction
            : parse_modbus_request(adu + header, static_cast<std::size_t>(pdu_length), req);
    if (ex == ModbusException::kNone) {
        // A broadcast has nobody to read the answer: only writes make sense (spec 2.1);
        // reads and FC23 are dropped without touching the handler.
        const bool pure_write = req.function == kFcWriteSingle || req.function == kFcWriteMultiple;
        if (outcome.broadcast && !pure_write) return outcome;
        ex = call_handler(handler, req, s);
    }
    outcome.exception = ex != ModbusException::kNone;
    if (outcome.broadcast) return outcome;
    outcome.sent = outcome.exception ? modbus_reply_exception(ctx, adu, static_cast<unsigned>(ex))
                                     : reply_success(ctx, req, adu, length, s);
    return outcome;
}

}  // namespace pathstream::hal::detail
