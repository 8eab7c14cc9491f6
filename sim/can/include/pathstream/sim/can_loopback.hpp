// An in-process CAN bus for tests and benches: endpoints implementing hal::CanBus that see
// each other's frames (not their own, as on a real bus), with seeded fault injection: a
// fraction of frames lost, a transmit budget per receive call, and forced bus-off.
// Thread-safe: each endpoint may be used from its own thread.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <random>
#include <vector>

#include "pathstream/hal/can_bus.hpp"

namespace pathstream::sim {

/// Faults the loopback injects.
struct CanFaults {
    double drop_fraction = 0;  ///< each frame is lost for every receiver with this probability
    std::uint64_t seed = 1;    ///< of the drop decisions (deterministic sequence of decisions)
    std::uint32_t tx_budget =
        0;  ///< frames an endpoint may send between two receive() calls (0: unlimited)
};

/// What went over the loopback.
struct CanLoopbackCounters {
    std::uint64_t frames = 0;  ///< frames sent (including the dropped ones: they took bus time)
    std::uint64_t dropped = 0;
    std::uint64_t bits_worst_case = 0;  ///< sum of frame_bits_worst_case over the frames sent
    std::uint64_t data_bytes = 0;
};

class CanLoopback {
public:
    explicit CanLoopback(const CanFaults& faults = {});
    ~CanLoopback();

    /// A new endpoint; it lives as long as the loopback.
    hal::CanBus& add_endpoint();
    /// Forces endpoint `index` (creation order, from 0) bus-off (it neither sends nor
    /// receives) or back to error-active.
    void set_bus_off(std::size_t index, bool off);
    CanLoopbackCounters counters() const;
    /// Frames sent by endpoint `index` (queued, not refused).
    std::uint64_t frames_sent_by(std::size_t index) const;

private:
    class Endpoint;
    friend class Endpoint;
    hal::CanSendResult send_from(Endpoint& from, const hal::CanFrame& frame);
    bool receive_at(Endpoint& at, hal::CanFrame& out, std::uint32_t timeout_us);

    mutable std::mutex mutex_;
    std::condition_variable arrived_;
    CanFaults faults_;
    std::mt19937_64 random_;
    std::vector<std::unique_ptr<Endpoint>> endpoints_;
    CanLoopbackCounters counters_;
};

}  // namespace pathstream::sim
