#include "event_hub.hpp"

#include <algorithm>

namespace pathstream::host::serve {

EventHub::EventHub(std::size_t capacity) : capacity_(std::max<std::size_t>(capacity, 1)) {}

std::uint64_t EventHub::publish(std::string json, const std::string& sticky_kind) {
    std::uint64_t sequence = 0;
    {
        const std::lock_guard<std::mutex> lock(mutex_);
        sequence = next_++;
        if (!sticky_kind.empty()) sticky_[sticky_kind] = HubEvent{sequence, json};
        events_.push_back(HubEvent{sequence, std::move(json)});
        if (events_.size() > capacity_) events_.pop_front();
    }
    changed_.notify_all();
    return sequence;
}

std::vector<HubEvent> EventHub::wait_after(std::uint64_t sequence,
                                           std::chrono::milliseconds timeout,
                                           std::uint64_t* missed) {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait_for(lock, timeout, [&] { return closed_ || next_ - 1 > sequence; });
    std::vector<HubEvent> out;
    if (closed_) return out;
    const std::uint64_t oldest = events_.empty() ? next_ : events_.front().sequence;
    if (missed) *missed = oldest > sequence + 1 ? oldest - sequence - 1 : 0;
    for (const HubEvent& e : events_) {
        if (e.sequence > sequence) out.push_back(e);
    }
    return out;
}

std::vector<HubEvent> EventHub::sticky(std::uint64_t& continue_after) const {
    const std::lock_guard<std::mutex> lock(mutex_);
    std::vector<HubEvent> out;
    for (const auto& [kind, e] : sticky_) out.push_back(e);
    std::sort(out.begin(), out.end(),
              [](const HubEvent& a, const HubEvent& b) { return a.sequence < b.sequence; });
    continue_after = next_ - 1;
    return out;
}

void EventHub::forget(const std::string& kind) {
    const std::lock_guard<std::mutex> lock(mutex_);
    sticky_.erase(kind);
}

void EventHub::close() {
    {
        const std::lock_guard<std::mutex> lock(mutex_);
        closed_ = true;
    }
    changed_.notify_all();
}

std::uint64_t EventHub::published() const {
    const std::lock_guard<std::mutex> lock(mutex_);
    return next_ - 1;
}

std::string job_sticky_kind(const std::string& line) {
    std::string sticky;
    for (const char* k : {"job_start", "progress", "job_end", "pause", "state"}) {
        if (line.find(std::string("\"event\":\"") + k + "\"") != std::string::npos) sticky = k;
    }
    return sticky;
}

}  // namespace pathstream::host::serve
