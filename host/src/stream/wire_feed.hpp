// A job's wire spans as a streaming client sends them, pulled from a SpanSupply as they are
// needed and dropped once the device executed them: the Modbus and CAN clients share it.
#pragma once

#include <cstdint>
#include <deque>
#include <exception>
#include <optional>
#include <vector>

#include "pathstream/host/span_supply.hpp"
#include "pathstream/host/wire_plan.hpp"

namespace pathstream::host {

/// Encodes one span behind the supply (a span is the job's last only once the supply ends)
/// and keeps the encoded spans and their tick counts from the oldest one not released: memory
/// follows what the device has queued, not the job. One thread (the streamer's).
class WireFeed {
public:
    explicit WireFeed(SpanSupply& supply) : supply_(supply) {}

    /// Waits for the job's first span (sleeping 1 ms at a time): its start point and axis
    /// count. Throws the supply's error, std::invalid_argument for a job without spans.
    void wait_first();
    unsigned axes() const { return axes_; }
    /// Where the job starts, LSB per axis (after wait_first).
    const std::int32_t* start() const { return start_; }
    /// Where the last span encoded ends, LSB per axis.
    const std::int32_t* end() const { return end_; }

    /// Takes from the supply, without waiting, until span `index` is encoded; true when it
    /// is. Throws the supply's error and WireEncoder's.
    bool available(std::size_t index);
    /// available(), except that an error of the supply or the encoder (planning failed) is
    /// kept, not thrown: false from then on, and error() holds it, for a streamer that brings
    /// the device to a stop before it reports the error.
    bool sendable(std::size_t index);
    /// The error sendable() kept, or null.
    std::exception_ptr error() const { return error_; }
    /// Every span of the job was taken and encoded: count() is the job's span count.
    bool complete() const { return complete_; }
    /// Spans encoded so far.
    std::size_t count() const { return base_ + entries_.size(); }
    /// The encoded span `index` (released <= index < count()).
    const std::vector<std::uint8_t>& bytes(std::size_t index) const {
        return entries_.at(index - base_).bytes;
    }
    /// Ticks of the spans before `index` (released <= index <= count()).
    std::uint64_t ticks_before(std::size_t index) const {
        return index == count() ? ticks_ : entries_.at(index - base_).ticks_before;
    }
    /// The spans before `index` are no longer needed (executed): their memory is freed.
    void release_before(std::size_t index);
    /// The job's ticks: counted once complete, else what the supply knows (nullopt while
    /// planning goes on).
    std::optional<std::uint64_t> total_ticks() const;
    /// The programmed pauses of the spans encoded so far (tick: the end of the span that
    /// carries pause_after; subpath: that span's).
    const std::vector<PlanPause>& pauses() const { return pauses_; }

private:
    struct Entry {
        std::vector<std::uint8_t> bytes;
        std::uint64_t ticks_before = 0;
    };
    void encode(const CoreSpan& span, bool last);

    SpanSupply& supply_;
    WireEncoder encoder_;
    CoreSpan pending_, incoming_;
    bool have_pending_ = false;
    bool complete_ = false;
    unsigned axes_ = 0;
    std::int32_t start_[8] = {};
    std::int32_t end_[8] = {};
    std::deque<Entry> entries_;
    std::size_t base_ = 0;  // index of entries_.front()
    std::uint64_t ticks_ = 0;
    std::vector<PlanPause> pauses_;
    std::exception_ptr error_;
};

}  // namespace pathstream::host
