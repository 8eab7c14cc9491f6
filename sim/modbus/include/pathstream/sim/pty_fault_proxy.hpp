// A serial line with faults: two pseudo-terminals joined by a forwarder that flips bits in
// and drops bytes at given rates, to prove that RTU masters and servers recover.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <string>
#include <thread>

#include "pathstream/hal/pseudo_terminal.hpp"

namespace pathstream::sim {

/// Fault rates per forwarded byte, applied independently in each direction.
struct PtyFaultOptions {
    double corrupt_rate = 0.0;  ///< probability that a byte gets one bit flipped
    double drop_rate = 0.0;     ///< probability that a byte is not delivered
    std::uint64_t seed = 1;     ///< same seed + same byte streams = same faults
};

/// Counters, readable from any thread.
struct PtyFaultCounters {
    std::atomic<std::uint64_t> bytes_a_to_b{0};  ///< bytes read from side A (before faults)
    std::atomic<std::uint64_t> bytes_b_to_a{0};
    std::atomic<std::uint64_t> corrupted{0};
    std::atomic<std::uint64_t> dropped{0};
    std::atomic<std::uint64_t> overflowed{0};  ///< lost because the far side's buffer was full
};

/// Two ptys, A and B. Whatever a program writes to path_a() comes out of path_b() and the
/// other way round, with faults. Decisions come from one 64-bit generator per direction
/// (splitmix64 of the seed), so they depend only on the seed and the position of the byte
/// in its direction's stream, not on timing or chunking.
///
/// Threading: either call poll_once() from one thread, or start() a background thread
/// (stop() or the destructor joins it). Not both.
class PtyFaultProxy {
public:
    /// Opens both ptys. Throws std::invalid_argument for rates outside [0, 1],
    /// std::system_error when no pty is free.
    explicit PtyFaultProxy(const PtyFaultOptions& options);
    ~PtyFaultProxy();  ///< stop()s
    PtyFaultProxy(const PtyFaultProxy&) = delete;
    PtyFaultProxy& operator=(const PtyFaultProxy&) = delete;

    const std::string& path_a() const { return a_.peer_path(); }
    const std::string& path_b() const { return b_.peer_path(); }
    const PtyFaultCounters& counters() const { return counters_; }

    /// Waits up to `max_wait` for bytes on either side and forwards what is there.
    void poll_once(std::chrono::milliseconds max_wait);
    /// Runs poll_once in a thread until stop().
    void start();
    void stop();

private:
    struct Direction {
        std::uint64_t state;
    };
    void forward(int from, int to, Direction& dir, std::atomic<std::uint64_t>& count);
    bool chance(Direction& dir, double rate);
    std::uint64_t next(Direction& dir);

    PtyFaultOptions options_;
    hal::PseudoTerminal a_{true};
    hal::PseudoTerminal b_{true};
    Direction a_to_b_;
    Direction b_to_a_;
    PtyFaultCounters counters_;
    std::atomic<bool> running_{false};
    std::thread thread_;
};

}  // namespace pathstream::sim
