// A Modbus server (slave) on libmodbus: TCP or RTU transport, serving a
// ModbusRegisterHandler. The device loop drives it: poll_once()/serve_for() between ticks.
#pragma once

#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "pathstream/hal/modbus_register_handler.hpp"
#include "pathstream/hal/modbus_serial_line.hpp"

namespace pathstream::hal {

/// Where a TCP server listens.
struct ModbusTcpEndpoint {
    std::string host = "127.0.0.1";  ///< address or name to bind; "0.0.0.0" / "::" for all
    std::uint16_t port = 0;          ///< 0 = an ephemeral port (read it back with port())
    std::size_t max_clients = 16;    ///< connections kept at once; see ModbusServer
};

/// Settings common to both transports.
struct ModbusServerOptions {
    /// RTU: the unit id (slave id) served, 1..247; requests for other ids are ignored (no
    /// reply, as on a shared bus), unit 0 is broadcast (writes applied, no reply).
    /// TCP: not used; every unit id is answered and echoed (the MBAP unit id addresses
    /// devices behind a gateway; this server is the device).
    int unit = 1;
    /// Longest gap allowed inside one request before it is dropped as incomplete. RTU: bounds
    /// how long a half-sent frame can stall poll_once(). TCP: a connection whose frame stalls
    /// longer is closed (nothing ever waits for it).
    std::chrono::milliseconds byte_timeout{100};
};

/// Counters, readable from any thread while the server runs (relaxed atomics).
struct ModbusServerCounters {
    std::atomic<std::uint64_t> requests{
        0};  ///< well-formed requests for this server, broadcasts included
    std::atomic<std::uint64_t> exceptions{0};  ///< exception responses (or refused broadcasts)
    std::atomic<std::uint64_t> broadcasts{0};  ///< RTU unit-0 requests (never answered)
    std::atomic<std::uint64_t> ignored{0};     ///< RTU requests for other unit ids
    std::atomic<std::uint64_t> bad_frames{0};  ///< CRC errors, incomplete or oversize frames
    std::atomic<std::uint64_t> connections_accepted{0};  ///< TCP
    std::atomic<std::uint64_t> connections_closed{0};    ///< TCP: by the peer, an error or eviction
    std::atomic<std::uint64_t> adu_bytes_received{
        0};  ///< whole ADUs as on the wire (header/CRC included)
    std::atomic<std::uint64_t> adu_bytes_sent{0};  ///< whole ADUs as on the wire
};

/// Serves one register space over one transport. libmodbus does the framing (MBAP, CRC,
/// unit filtering on RTU); this class checks each request against the spec and dispatches
/// FC3, FC4, FC6, FC16 and FC23 to the handler; any other function code is answered with
/// illegal function.
///
/// Threading: single-threaded and poll-driven. Only the thread that calls poll_once() /
/// serve_for() touches the handler and the descriptors; nothing runs in the background.
/// counters() may be read from any thread. Not copyable; movable.
///
/// TCP: up to max_clients connections at once. Each connection's bytes are read without
/// waiting into its own frame buffer (MBAP framing done here, libmodbus only frames replies),
/// so a peer sending one byte at a time, or not reading its replies (non-blocking sends: it
/// is closed), never holds the server or the ticks around poll_once(). A peer that closes or
/// errors loses only its connection. When a new client arrives and all slots are taken, a
/// connection that never completed a request is closed for it, else the one idle the longest:
/// a streaming master keeps its slot against a connection flood, and a master reconnecting
/// after a silent link loss (no FIN ever seen) still gets in.
///
/// RTU: one serial line (a device path, or a pty this server creates for tests and
/// simulators). A corrupt frame is counted and the input flushed; the master's retry finds
/// a quiet line.
class ModbusServer {
public:
    /// Listens on `endpoint`. Throws std::system_error when the address cannot be bound.
    static ModbusServer tcp(ModbusRegisterHandler& handler, const ModbusTcpEndpoint& endpoint,
                            const ModbusServerOptions& options = {});
    /// Opens a serial device with libmodbus (termios from `line`). Throws std::system_error.
    static ModbusServer rtu(ModbusRegisterHandler& handler, const ModbusSerialLine& line,
                            const ModbusServerOptions& options = {});
    /// Creates a raw pseudo-terminal and serves on its near end; masters open
    /// client_device(). Baud and format do not matter on a pty. Throws std::system_error.
    static ModbusServer rtu_pty(ModbusRegisterHandler& handler,
                                const ModbusServerOptions& options = {});

    ModbusServer(ModbusServer&&) noexcept;
    ModbusServer& operator=(ModbusServer&&) noexcept;
    ~ModbusServer();  ///< closes every descriptor; the handler is not called

    /// Waits up to `max_wait` for activity (ppoll(2), microsecond resolution: an idle device
    /// sleeps until its next tick), then accepts new TCP connections and answers at most one
    /// request per connection (RTU: one request). Returns the number of requests handled
    /// (answered, broadcast or refused with an exception). Worst-case duration: TCP, max_wait
    /// + handler time per ready connection (reads never wait); RTU, max_wait + byte_timeout
    /// (an incomplete frame) + handler time. max_wait 0 = do not wait (check and return).
    std::size_t poll_once(std::chrono::microseconds max_wait);

    /// poll_once() repeatedly until `duration` has passed. Returns requests handled.
    std::size_t serve_for(std::chrono::milliseconds duration);

    /// TCP: the bound port (the ephemeral one when the endpoint asked for 0). RTU: 0.
    std::uint16_t port() const;
    /// RTU on a pty: the path a master opens (/dev/pts/N). Otherwise the device path (RTU)
    /// or "" (TCP).
    const std::string& client_device() const;
    /// Live counters (see ModbusServerCounters).
    const ModbusServerCounters& counters() const;
    /// TCP: connections currently open (accepted minus closed). Safe from any thread while
    /// another one polls: a count from the atomic counters, never the client list itself.
    std::size_t open_connections() const;

private:
    struct Impl;
    explicit ModbusServer(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

}  // namespace pathstream::hal
