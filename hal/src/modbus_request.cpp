#include "modbus_request.hpp"

namespace pathstream::hal::detail {
namespace {

// A range must stay inside the 16-bit register space: address + count - 1 <= 0xFFFF.
bool range_fits(std::uint16_t address, std::uint16_t count) {
    return static_cast<std::uint32_t>(address) + count <= 0x10000u;
}

}  // namespace

ModbusException parse_modbus_request(const std::uint8_t* pdu, std::size_t length,
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

}  // namespace pathstream::hal::detail
