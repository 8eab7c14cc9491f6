// A simulated Modbus TCP I/O module with coils: the relay board or VFD interface a machine's
// spindle and coolant are wired to. It is libmodbus's own server (modbus_mapping_new,
// modbus_receive, modbus_reply) on 127.0.0.1, served by a thread of its own, so the client
// under test talks to an implementation that is not ours. It records every coil change, can
// hold its answers (a slow module) and can go away (a module switched off or unplugged).
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace pathstream::sim {

/// A Modbus TCP server with `coils` coils (1..65536; addresses 0..coils-1, all off at first): FC1,
/// FC5 and FC15 as libmodbus serves them; an address past the last coil is answered with exception
/// 2 (illegal data address). Any number of clients, one request at a time. Host test code: it
/// allocates and starts a thread.
class CoilModule {
public:
    /// One coil changed by a write.
    struct Change {
        std::uint16_t coil = 0;
        bool on = false;
        std::uint64_t request = 0;  ///< the write request that changed it (1: the first)
    };

    /// Listens on 127.0.0.1:`port` (0: a free port, see port()) and serves from a thread.
    /// Throws std::system_error when the port cannot be opened.
    explicit CoilModule(std::uint32_t coils = 16, std::uint16_t port = 0);
    /// stop().
    ~CoilModule();
    CoilModule(const CoilModule&) = delete;
    CoilModule& operator=(const CoilModule&) = delete;

    /// The TCP port it listens on.
    std::uint16_t port() const { return port_; }
    /// "modbus-tcp://127.0.0.1:PORT?unit=N" (a TCP module answers any unit).
    std::string url(int unit = 1) const;

    /// A coil's level now. Any thread.
    bool coil(std::uint16_t address) const;
    /// Every change so far, in order. Any thread.
    std::vector<Change> changes() const;
    /// Write requests (FC5, FC15) answered so far, refused ones included. Any thread.
    std::uint64_t write_requests() const;
    /// Requests taken but not answered yet (held, see hold_answers). Any thread.
    std::uint64_t waiting_requests() const;

    /// While held, a request is taken off the connection but neither applied nor answered
    /// until the hold is released: a module that is slow to answer. Any thread.
    void hold_answers(bool held);

    /// Waits until `done(*this)` holds or `limit` passes; true when it holds. `done` is
    /// called with no lock held, after every answered request and at least every 10 ms. Any
    /// thread but the module's (a bound for tests, not a timing measurement).
    bool wait_until(const std::function<bool(const CoilModule&)>& done,
                    std::chrono::milliseconds limit) const;

    /// Closes the listening port and every connection and ends the thread: a client's next
    /// request fails (connection lost, then refused). Idempotent. Any thread but the module's.
    void stop();

private:
    void serve();
    void answer(int fd);

    std::uint16_t port_ = 0;
    void* ctx_ = nullptr;      // modbus_t*, used by the module's thread only after start
    void* mapping_ = nullptr;  // modbus_mapping_t*, its tab_bits guarded by mutex_
    int listen_fd_ = -1;
    std::vector<int> clients_;  // the module's thread only

    mutable std::mutex mutex_;
    mutable std::condition_variable answered_;
    std::vector<Change> changes_;
    std::uint64_t write_requests_ = 0;
    std::uint64_t waiting_ = 0;
    bool held_ = false;
    bool stopping_ = false;
    std::thread thread_;
};

}  // namespace pathstream::sim
