#include "pathstream/sim/can_loopback.hpp"

#include <chrono>

#include "pathstream/device/can_protocol.hpp"

namespace pathstream::sim {

class CanLoopback::Endpoint final : public hal::CanBus {
public:
    Endpoint(CanLoopback& bus, std::size_t index) : bus_(bus), index_(index) {}
    hal::CanSendResult send(const hal::CanFrame& frame) override {
        return bus_.send_from(*this, frame);
    }
    bool receive(hal::CanFrame& out, std::uint32_t timeout_us) override {
        return bus_.receive_at(*this, out, timeout_us);
    }
    hal::CanBusState state() const override {
        std::lock_guard<std::mutex> lock(bus_.mutex_);
        return bus_off_ ? hal::CanBusState::kBusOff : hal::CanBusState::kErrorActive;
    }

    CanLoopback& bus_;
    std::size_t index_;
    std::deque<hal::CanFrame> queue_;  // guarded by bus_.mutex_
    bool bus_off_ = false;
    std::uint32_t sent_since_receive_ = 0;
    std::uint64_t sent_ = 0;
};

CanLoopback::CanLoopback(const CanFaults& faults) : faults_(faults), random_(faults.seed) {}
CanLoopback::~CanLoopback() = default;

hal::CanBus& CanLoopback::add_endpoint() {
    std::lock_guard<std::mutex> lock(mutex_);
    endpoints_.push_back(std::make_unique<Endpoint>(*this, endpoints_.size()));
    return *endpoints_.back();
}

void CanLoopback::set_bus_off(std::size_t index, bool off) {
    std::lock_guard<std::mutex> lock(mutex_);
    endpoints_.at(index)->bus_off_ = off;
    if (off) endpoints_.at(index)->queue_.clear();
}

CanLoopbackCounters CanLoopback::counters() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return counters_;
}

std::uint64_t CanLoopback::frames_sent_by(std::size_t index) const {
    std::lock_guard<std::mutex> lock(mutex_);
    return endpoints_.at(index)->sent_;
}

hal::CanSendResult CanLoopback::send_from(Endpoint& from, const hal::CanFrame& frame) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (from.bus_off_) return hal::CanSendResult::kBusOff;
    if (frame.length > 8 || frame.id > (frame.extended ? 0x1FFFFFFFu : 0x7FFu))
        return hal::CanSendResult::kError;
    if (faults_.tx_budget != 0 && from.sent_since_receive_ >= faults_.tx_budget)
        return hal::CanSendResult::kQueueFull;
    ++from.sent_since_receive_;
    ++from.sent_;
    ++counters_.frames;
    counters_.data_bytes += frame.length;
    counters_.bits_worst_case +=
        device::can::frame_bits_worst_case(frame.remote ? 0u : frame.length);
    // One decision per frame, in send order: the same seed loses the same frames of a run
    // whose send order is the same.
    if (faults_.drop_fraction > 0 &&
        std::uniform_real_distribution<double>(0, 1)(random_) < faults_.drop_fraction) {
        ++counters_.dropped;
        return hal::CanSendResult::kQueued;
    }
    for (auto& e : endpoints_) {
        if (e.get() != &from && !e->bus_off_) e->queue_.push_back(frame);
    }
    arrived_.notify_all();
    return hal::CanSendResult::kQueued;
}

bool CanLoopback::receive_at(Endpoint& at, hal::CanFrame& out, std::uint32_t timeout_us) {
    std::unique_lock<std::mutex> lock(mutex_);
    at.sent_since_receive_ = 0;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::microseconds(timeout_us);
    while (at.queue_.empty()) {
        if (arrived_.wait_until(lock, deadline) == std::cv_status::timeout && at.queue_.empty())
            return false;
    }
    out = at.queue_.front();
    at.queue_.pop_front();
    return true;
}

}  // namespace pathstream::sim
