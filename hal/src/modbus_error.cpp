#include "pathstream/hal/modbus_error.hpp"

namespace pathstream::hal {

const char* to_string(ModbusError::Kind kind) noexcept {
    switch (kind) {
        case ModbusError::Kind::kTimeout:
            return "timeout";
        case ModbusError::Kind::kConnectionLost:
            return "connection lost";
        case ModbusError::Kind::kConnectFailed:
            return "connect failed";
        case ModbusError::Kind::kExceptionResponse:
            return "exception response";
        case ModbusError::Kind::kBadFrame:
            return "bad frame";
    }
    return "unknown";
}

const char* modbus_exception_name(std::uint8_t code) noexcept {
    // Names from the Modbus application protocol spec, section 7.
    switch (code) {
        case 1:
            return "illegal function";
        case 2:
            return "illegal data address";
        case 3:
            return "illegal data value";
        case 4:
            return "server device failure";
        case 5:
            return "acknowledge";
        case 6:
            return "server device busy";
        case 8:
            return "memory parity error";
        case 10:
            return "gateway path unavailable";
        case 11:
            return "gateway target device failed to respond";
        default:
            return "unknown exception";
    }
}

}  // namespace pathstream::hal
