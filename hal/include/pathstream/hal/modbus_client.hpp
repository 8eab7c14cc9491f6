// A Modbus client (master) on libmodbus for the host: one target, typed errors, own retry and
// reconnect policy, byte counters for bus-load figures.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <span>
#include <string_view>

#include "pathstream/hal/modbus_error.hpp"
#include "pathstream/hal/modbus_target.hpp"

namespace pathstream::hal {

/// Client settings. Timeouts apply to each try.
struct ModbusClientOptions {
    /// From the end of the request to the first byte of the response (libmodbus's response
    /// timeout; also bounds a TCP connect).
    std::chrono::milliseconds response_timeout{500};
    /// Longest gap between two bytes of one response.
    std::chrono::milliseconds byte_timeout{500};
    /// Tries per transaction, >= 1. 1 = no retry: every failure goes to the caller. See
    /// ModbusClient for what happens between tries.
    int attempts = 1;
};

/// Counters since construction. Bytes are whole ADUs (RTU: unit + PDU + CRC; TCP: MBAP 7 +
/// PDU) computed from the function code and counts (modbus_adu.hpp), so they equal what a
/// bus analyser would see for the frames that went through: sent counts every try that
/// was written; received counts valid responses and exception responses only (a timed-out
/// or corrupt response has no known length).
struct ModbusClientCounters {
    std::uint64_t transactions = 0;         ///< calls that succeeded
    std::uint64_t attempts = 0;             ///< tries, first ones included
    std::uint64_t retries = 0;              ///< tries after the first
    std::uint64_t timeouts = 0;             ///< tries that ended in kTimeout
    std::uint64_t bad_frames = 0;           ///< tries that ended in kBadFrame
    std::uint64_t connection_losses = 0;    ///< tries that ended in kConnectionLost
    std::uint64_t connect_failures = 0;     ///< failed (re)connects
    std::uint64_t exception_responses = 0;  ///< device exceptions (never retried)
    std::uint64_t reconnects = 0;           ///< successful connects after the first
    std::uint64_t adu_bytes_sent = 0;
    std::uint64_t adu_bytes_received = 0;
};

/// Talks to one device (the target URL's unit id) over TCP or RTU.
///
/// Errors: every method throws ModbusError; kind() tells timeout, connection lost, connect
/// failed, exception response (with the device's code) and bad frame (CRC, mismatched
/// reply) apart. Argument errors (counts outside the function's limits, a read to the
/// broadcast unit) throw std::invalid_argument before anything is sent.
///
/// Retry policy (options.attempts = N): a transaction is tried up to N times while it fails
/// transiently (ModbusError::transient(): not an exception response; a device that refused
/// will refuse again). Between tries the link is put back in a known state: TCP closes and
/// reconnects (a late response could still arrive on the old connection), RTU flushes the
/// input and waits for the line to go quiet (a late response from the device must not be
/// taken for the next one). After the last try the last error is thrown, its message naming
/// the try count. After any transient failure with retries exhausted, TCP is left closed
/// and the next call connects first; reconnect() does that eagerly.
/// A retried write may be applied twice (its response, not its request, may be what got
/// lost): retries are safe for idempotent writes (same values to the same registers). A
/// register map that queues what it is written (spans) must make a repeat harmless, e.g.
/// with a sequence number in the written block. That is the map's job, not the transport's.
///
/// RTU broadcast (unit 0): write_register/write_registers send and return at once (no
/// response exists; attempts are ignored, the line's turnaround delay is the caller's).
///
/// Threading: not thread-safe; one thread per client. Each call blocks for at most
/// attempts x (connect + response_timeout + bytes x byte_timeout), plus RTU quiet waits.
class ModbusClient {
public:
    /// Opens the port / connects. Throws ModbusError (kConnectFailed) if that fails.
    explicit ModbusClient(const ModbusTarget& target, const ModbusClientOptions& options = {});
    /// parse_modbus_target(url) first; std::invalid_argument on a bad URL.
    explicit ModbusClient(std::string_view url, const ModbusClientOptions& options = {});
    ~ModbusClient();
    ModbusClient(ModbusClient&&) noexcept;
    ModbusClient& operator=(ModbusClient&&) noexcept;

    /// FC4: out.size() registers (1..125) from `address`.
    void read_input_registers(std::uint16_t address, std::span<std::uint16_t> out);
    /// FC3: out.size() registers (1..125) from `address`.
    void read_holding_registers(std::uint16_t address, std::span<std::uint16_t> out);
    /// FC6: one register.
    void write_register(std::uint16_t address, std::uint16_t value);
    /// FC16: values.size() registers (1..123) from `address`.
    void write_registers(std::uint16_t address, std::span<const std::uint16_t> values);
    /// FC5: coil `address` on or off. Not to the broadcast unit (std::invalid_argument):
    /// an output write must be confirmed.
    void write_coil(std::uint16_t address, bool on);
    /// FC15: values.size() coils (1..1968) from `address`, coil address + k on when
    /// values[k] != 0. Not to the broadcast unit (std::invalid_argument).
    void write_coils(std::uint16_t address, std::span<const std::uint8_t> values);
    /// FC23: writes `values` (1..121) at write_address, then reads out.size() (1..125)
    /// registers from read_address, in one transaction (the device writes first).
    void write_read_registers(std::uint16_t write_address, std::span<const std::uint16_t> values,
                              std::uint16_t read_address, std::span<std::uint16_t> out);

    /// Closes and opens the link again (TCP: a new connection; RTU: reopens the port).
    /// Throws ModbusError (kConnectFailed); the client is then closed and the next call
    /// tries to connect again.
    void reconnect();
    /// Closes the link; the next call connects first.
    void close();
    /// True while a connection / open port exists (not a liveness check: a dead peer is
    /// only noticed by the next transaction).
    bool connected() const;

    const ModbusTarget& target() const;
    const ModbusClientOptions& options() const;
    const ModbusClientCounters& counters() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace pathstream::hal
