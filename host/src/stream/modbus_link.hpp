// The Modbus transport to one device (docs/modbus.md): connecting with retries, transactions
// that reconnect until the link timeout, and the status block parsed. The streamer and
// `pathstream ctl` share it.
#pragma once

#include <chrono>
#include <cstdint>
#include <sstream>
#include <string>
#include <thread>

#include "pathstream/device/modbus_map.hpp"
#include "pathstream/hal/modbus_client.hpp"
#include "pathstream/hal/modbus_error.hpp"
#include "pathstream/host/device_link.hpp"
#include "pathstream/host/modbus_stream.hpp"

namespace pathstream::host {

/// The status block's first `count` registers `r` (status::kStreamingCount or kCount) as a
/// snapshot; the homing states only when `count` covers them (else not homed).
DeviceSnapshot parse_modbus_status(const std::uint16_t* r, std::size_t count);

class ModbusLink {
public:
    using Clock = std::chrono::steady_clock;

    /// Connects to options.target, retrying until link_timeout_seconds have passed (a device
    /// may still be starting). Throws StreamError naming the target.
    explicit ModbusLink(const StreamOptions& options);

    [[noreturn]] void fail(const std::string& what) const {
        throw StreamError(options_.target + ": " + what);
    }

    /// Runs one transaction `f`; transient failures past the client's own tries reconnect and
    /// retry until link_timeout_seconds have passed without any success.
    template <typename F>
    void transact(F&& f) {
        while (true) {
            try {
                f();
                last_ok_ = Clock::now();
                return;
            } catch (const hal::ModbusError& e) {
                if (!e.transient()) throw;
                const double silent =
                    std::chrono::duration<double>(Clock::now() - last_ok_).count();
                if (silent > options_.link_timeout_seconds) {
                    std::ostringstream m;
                    m << "no answer for " << static_cast<long>(silent + 0.5) << " s (" << e.what()
                      << ")";
                    fail(m.str());
                }
                std::this_thread::sleep_for(std::chrono::milliseconds(20));
                try {
                    client_.reconnect();
                } catch (const hal::ModbusError&) {
                    // the next try reconnects again; the deadline above bounds it
                }
            }
        }
    }

    /// The status block's first `count` registers (FC4), parsed: the whole block by default,
    /// status::kStreamingCount while streaming. Counts status_reads.
    DeviceSnapshot read_status(std::uint16_t count = device::modbus::status::kCount);
    /// Writes command register 100; a refusal throws the ModbusError (non-transient).
    void write_command(device::Command c);
    /// Restarts the link-timeout clock (before a first transaction).
    void mark_alive() { last_ok_ = Clock::now(); }

    hal::ModbusClient& client() { return client_; }
    const hal::ModbusClient& client() const { return client_; }
    const StreamOptions& options() const { return options_; }
    std::uint64_t status_reads() const { return status_reads_; }

private:
    const StreamOptions& options_;
    hal::ModbusClient client_;
    Clock::time_point last_ok_ = Clock::now();
    std::uint64_t status_reads_ = 0;
};

}  // namespace pathstream::host
