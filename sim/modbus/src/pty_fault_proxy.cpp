#include "pathstream/sim/pty_fault_proxy.hpp"

#include <poll.h>
#include <unistd.h>

#include <stdexcept>

namespace pathstream::sim {

PtyFaultProxy::PtyFaultProxy(const PtyFaultOptions& options)
    : options_(options), a_to_b_{options.seed}, b_to_a_{~options.seed} {
    const auto valid = [](double r) { return r >= 0.0 && r <= 1.0; };
    if (!valid(options.corrupt_rate) || !valid(options.drop_rate)) {
        throw std::invalid_argument("PtyFaultProxy: rates must be in [0, 1]");
    }
}

PtyFaultProxy::~PtyFaultProxy() {
    stop();
}

// splitmix64: tiny, seedable with any value, and the same on every platform (the standard
// distributions are not).
std::uint64_t PtyFaultProxy::next(Direction& dir) {
    std::uint64_t z = (dir.state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

bool PtyFaultProxy::chance(Direction& dir, double rate) {
    // 53 random bits -> [0, 1). Drawn even when rate is 0 so that the fault sequence of one
    // kind does not shift when the other kind's rate changes.
    const double u = static_cast<double>(next(dir) >> 11) * 0x1.0p-53;
    return u < rate;
}

void PtyFaultProxy::forward(int from, int to, Direction& dir, std::atomic<std::uint64_t>& count) {
    std::uint8_t buffer[512];
    const ssize_t n = ::read(from, buffer, sizeof buffer);
    if (n <= 0) return;  // EAGAIN (spurious wake-up) or EIO: nothing to forward
    count.fetch_add(static_cast<std::uint64_t>(n), std::memory_order_relaxed);
    std::size_t kept = 0;
    for (ssize_t i = 0; i < n; ++i) {
        std::uint8_t byte = buffer[i];
        const bool drop = chance(dir, options_.drop_rate);
        const bool corrupt = chance(dir, options_.corrupt_rate);
        const auto bit = static_cast<unsigned>(next(dir) & 7u);
        if (drop) {
            counters_.dropped.fetch_add(1, std::memory_order_relaxed);
            continue;
        }
        if (corrupt) {
            byte = static_cast<std::uint8_t>(byte ^ (1u << bit));
            counters_.corrupted.fetch_add(1, std::memory_order_relaxed);
        }
        buffer[kept++] = byte;
    }
    std::size_t written = 0;
    while (written < kept) {
        const ssize_t w = ::write(to, buffer + written, kept - written);
        if (w <= 0) {  // the reader's queue is full (nobody reading): a real line loses it too
            counters_.overflowed.fetch_add(kept - written, std::memory_order_relaxed);
            return;
        }
        written += static_cast<std::size_t>(w);
    }
}

void PtyFaultProxy::poll_once(std::chrono::milliseconds max_wait) {
    pollfd fds[2] = {{a_.fd(), POLLIN, 0}, {b_.fd(), POLLIN, 0}};
    if (::poll(fds, 2, static_cast<int>(max_wait.count())) <= 0) return;
    if (fds[0].revents & POLLIN) forward(a_.fd(), b_.fd(), a_to_b_, counters_.bytes_a_to_b);
    if (fds[1].revents & POLLIN) forward(b_.fd(), a_.fd(), b_to_a_, counters_.bytes_b_to_a);
}

void PtyFaultProxy::start() {
    if (running_.exchange(true)) return;
    thread_ = std::thread([this] {
        while (running_.load(std::memory_order_relaxed)) poll_once(std::chrono::milliseconds(20));
    });
}

void PtyFaultProxy::stop() {
    running_.store(false);
    if (thread_.joinable()) thread_.join();
}

}  // namespace pathstream::sim
