// The live updates of `pathstream serve`: JSON lines from the job, the device poller and the
// commands, fanned out to every page that listens (server-sent events).
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <map>
#include <mutex>
#include <string>
#include <vector>

namespace pathstream::host::serve {

/// One published line and its place in the order of all of them (from 1).
struct HubEvent {
    std::uint64_t sequence = 0;
    std::string json;  ///< one JSON object, no newline
};

/// The sticky kind of a job's event line (the kinds a page joining late must see): job_start,
/// progress, job_end, pause or state; "" for any other. Linear in the line.
std::string job_sticky_kind(const std::string& line);

/// A bounded log of the latest events that any number of threads publish to and any number
/// of listeners read from, each at its own pace. A listener that falls more than `capacity`
/// events behind misses the oldest (its next read says how many). Every member locks one
/// mutex for the copy of a few strings; no call blocks but wait_after.
class EventHub {
public:
    /// Keeps the last `capacity` events.
    explicit EventHub(std::size_t capacity = 4096);

    /// Appends `json` (one JSON object) and wakes the listeners. `sticky_kind`, when not
    /// empty, also keeps it as the latest of its kind (the device's status, the job's start),
    /// which a listener that joins later gets first. Returns its sequence number.
    std::uint64_t publish(std::string json, const std::string& sticky_kind = "");

    /// The events after `sequence`, waiting up to `timeout` for one when there is none; empty
    /// after the timeout or once close() was called. `missed` (optional) gets how many events
    /// after `sequence` were dropped before they were read.
    std::vector<HubEvent> wait_after(std::uint64_t sequence, std::chrono::milliseconds timeout,
                                     std::uint64_t* missed = nullptr);

    /// The latest event of every sticky kind, in the order they were published, and the
    /// sequence number a new listener continues after.
    std::vector<HubEvent> sticky(std::uint64_t& continue_after) const;

    /// Clears the sticky event of `kind` (a job's start once the job has ended).
    void forget(const std::string& kind);

    /// Wakes every waiting listener for good (the server stops).
    void close();

    /// Events published so far.
    std::uint64_t published() const;

private:
    mutable std::mutex mutex_;
    std::condition_variable changed_;
    std::deque<HubEvent> events_;
    std::map<std::string, HubEvent> sticky_;
    std::size_t capacity_;
    std::uint64_t next_ = 1;
    bool closed_ = false;
};

}  // namespace pathstream::host::serve
