// The one exception type of the Modbus client: what went wrong, as a kind a caller can act on.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>

namespace pathstream::hal {

/// A failed Modbus transaction or connection. kind() says what the caller can do about it:
/// retry (kTimeout, kBadFrame, kConnectionLost, kConnectFailed) or not (kExceptionResponse:
/// the device understood and refused; repeating the request gets the same answer).
class ModbusError : public std::runtime_error {
public:
    enum class Kind : std::uint8_t {
        kTimeout,            ///< no (complete) response within the response timeout
        kConnectionLost,     ///< the link failed mid-transaction (peer closed, I/O error)
        kConnectFailed,      ///< could not open the port / connect to the server
        kExceptionResponse,  ///< the device answered with an exception code
        kBadFrame,           ///< a response arrived but was corrupt or did not match the request
    };

    /// `exception_code` is the wire value (1..255) for kExceptionResponse, 0 otherwise;
    /// `os_error` the errno of a failed connect (kConnectFailed), 0 otherwise.
    ModbusError(Kind kind, const std::string& message, std::uint8_t exception_code = 0,
                int os_error = 0)
        : std::runtime_error(message),
          kind_(kind),
          exception_code_(exception_code),
          os_error_(os_error) {}

    Kind kind() const noexcept { return kind_; }
    /// The device's exception code (ModbusException values, or others such as 0x0B from a
    /// gateway); 0 unless kind() == kExceptionResponse.
    std::uint8_t exception_code() const noexcept { return exception_code_; }
    /// The system's error number of a failed connect (ECONNREFUSED: nothing listens there),
    /// 0 for the other kinds.
    int os_error() const noexcept { return os_error_; }
    /// True for the kinds that a retry may cure (everything but kExceptionResponse).
    bool transient() const noexcept { return kind_ != Kind::kExceptionResponse; }

private:
    Kind kind_;
    std::uint8_t exception_code_;
    int os_error_;
};

/// "timeout", "connection lost", ... for messages and logs. No allocation.
const char* to_string(ModbusError::Kind kind) noexcept;

/// "illegal data address", ... for any wire exception code ("exception 0x0C" style names
/// are not produced: unknown codes give "unknown exception"). No allocation.
const char* modbus_exception_name(std::uint8_t code) noexcept;

}  // namespace pathstream::hal
