// The register space a Modbus server serves, as the device's register map implements it.
// The transport (hal/modbus_server.hpp) parses and validates requests, the handler decides
// what the registers mean; neither knows the other's internals.
#pragma once

#include <cstdint>

namespace pathstream::hal {

/// Modbus exception codes a handler may answer with (values as on the wire).
enum class ModbusException : std::uint8_t {
    kNone = 0,
    kIllegalFunction = 1,
    kIllegalDataAddress = 2,
    kIllegalDataValue = 3,
    kServerDeviceFailure = 4,
    kServerDeviceBusy = 6
};

/// The register space a Modbus server serves. All calls come from the server's thread (the
/// one calling ModbusServer::poll_once / serve_for), one at a time.
/// Freestanding: no heap, no exceptions, no OS headers; the firmware's register map can
/// implement it unchanged.
///
/// Before any call the server has checked the request's shape against the Modbus spec: the
/// count is within the function's limit and address + count <= 65536, so `out` / `values`
/// always hold exactly `count` registers (the server owns those buffers; they are valid for
/// the call only). What is left to the handler is the meaning: which addresses exist
/// (kIllegalDataAddress), which values are acceptable (kIllegalDataValue), whether it can
/// serve now (kServerDeviceBusy).
///
/// Any answer other than kNone is sent to the master as an exception response; on a
/// broadcast (RTU unit 0) nothing is sent either way. Handlers should return quickly: the
/// server answers only after the call returns, and the master's response timeout runs
/// meanwhile (500 ms by default).
class ModbusRegisterHandler {
public:
    virtual ~ModbusRegisterHandler() = default;

    /// FC4 (read input registers). Fill out[0..count). count 1..125. On an exception the
    /// contents of `out` are ignored.
    virtual ModbusException read_input_registers(std::uint16_t address, std::uint16_t count,
                                                 std::uint16_t* out) = 0;

    /// FC3 (read holding registers). Fill out[0..count). count 1..125. On an exception the
    /// contents of `out` are ignored.
    virtual ModbusException read_holding_registers(std::uint16_t address, std::uint16_t count,
                                                   std::uint16_t* out) = 0;

    /// FC6 (count 1) and FC16 (count 1..123): all or nothing; on an exception nothing
    /// changed. Also called for broadcasts (no reply goes out, so the master cannot learn
    /// of a refusal).
    virtual ModbusException write_holding_registers(std::uint16_t address, std::uint16_t count,
                                                    const std::uint16_t* values) = 0;

    /// FC23 (write_count 1..121, read_count 1..125): the write happens first, then the read
    /// (Modbus spec order); if the write is refused nothing is read. A read refused after an
    /// accepted write leaves the write applied (the master sees the exception and cannot
    /// tell; a register map that cares overrides this to check the read range first).
    /// Default: write_holding_registers then read_holding_registers.
    virtual ModbusException write_read_holding_registers(
        std::uint16_t write_address, std::uint16_t write_count, const std::uint16_t* values,
        std::uint16_t read_address, std::uint16_t read_count, std::uint16_t* out);
};

inline ModbusException ModbusRegisterHandler::write_read_holding_registers(
    std::uint16_t write_address, std::uint16_t write_count, const std::uint16_t* values,
    std::uint16_t read_address, std::uint16_t read_count, std::uint16_t* out) {
    const ModbusException written = write_holding_registers(write_address, write_count, values);
    if (written != ModbusException::kNone) return written;
    return read_holding_registers(read_address, read_count, out);
}

}  // namespace pathstream::hal
