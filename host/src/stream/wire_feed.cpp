#include "wire_feed.hpp"

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <thread>

namespace pathstream::host {

void WireFeed::wait_first() {
    while (!have_pending_ && count() == 0) {
        switch (supply_.take(pending_)) {
            case SpanSupply::Take::kSpan:
                have_pending_ = true;
                break;
            case SpanSupply::Take::kEnd:
                throw std::invalid_argument("the plan has no spans");
            case SpanSupply::Take::kWait:
                std::this_thread::sleep_for(std::chrono::milliseconds(1));
                break;
        }
    }
    if (count() > 0) return;
    axes_ = static_cast<unsigned>(pending_.control.size());
    if (axes_ < 1 || axes_ > 8) throw std::invalid_argument("1 to 8 axes");
    for (unsigned a = 0; a < axes_; ++a) start_[a] = pending_.control[a][0];
}

bool WireFeed::sendable(std::size_t index) {
    if (error_) return false;
    try {
        return available(index);
    } catch (...) {
        error_ = std::current_exception();
        return false;
    }
}

bool WireFeed::available(std::size_t index) {
    while (index >= count() && !complete_) {
        if (!have_pending_) {
            const SpanSupply::Take t = supply_.take(pending_);
            if (t == SpanSupply::Take::kWait) return false;
            if (t == SpanSupply::Take::kEnd) throw std::invalid_argument("the plan has no spans");
            have_pending_ = true;
        }
        const SpanSupply::Take t = supply_.take(incoming_);
        if (t == SpanSupply::Take::kWait) return false;
        encode(pending_, t == SpanSupply::Take::kEnd);
        if (t == SpanSupply::Take::kEnd) {
            have_pending_ = false;
            complete_ = true;
        } else {
            std::swap(pending_, incoming_);
        }
    }
    return index < count();
}

void WireFeed::encode(const CoreSpan& span, bool last) {
    entries_.push_back({encoder_.encode(span, last), ticks_});
    ticks_ += span.ticks;
    for (unsigned a = 0; a < axes_; ++a) end_[a] = span.control[a][1];
    if (span.pause_after) pauses_.push_back({ticks_, span.subpath});
}

void WireFeed::release_before(std::size_t index) {
    while (base_ < index && !entries_.empty()) {
        entries_.pop_front();
        ++base_;
    }
}

std::optional<std::uint64_t> WireFeed::total_ticks() const {
    if (complete_) return ticks_;
    return supply_.total_ticks();
}

}  // namespace pathstream::host
