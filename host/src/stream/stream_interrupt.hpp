// What an interrupted stream does next (Ctrl-C, SIGTERM), from the operator's requests and the
// device's state; the Modbus and CAN streamers share it.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <vector>

#include "pathstream/device/device_state.hpp"
#include "pathstream/host/device_link.hpp"
#include "pathstream/host/stream_types.hpp"

namespace pathstream::host {

class StreamInterrupt {
public:
    enum class Action { kNone, kHold, kStop };

    explicit StreamInterrupt(const InterruptOptions& options) : options_(options) {}

    /// The command to send now, each at most once: a hold at the first request (a stop
    /// instead when the device was never started: it drops what is queued and nothing moved),
    /// a stop at the second request or when the hold has not come to rest in time.
    Action next_action(bool started) {
        const int request =
            std::max(options_.request != nullptr ? options_.request->load() : 0, forced_);
        if (request >= 1 && !hold_sent_ && !stop_sent_) {
            if (!started) {
                stop_sent_ = true;
                return Action::kStop;
            }
            hold_sent_ = true;
            hold_at_ = Clock::now();
            return Action::kHold;
        }
        if (hold_sent_ && !stop_sent_ &&
            (request >= 2 || std::chrono::duration<double>(Clock::now() - hold_at_).count() >
                                 options_.hold_timeout_seconds)) {
            stop_sent_ = true;
            return Action::kStop;
        }
        return Action::kNone;
    }

    /// The stream cannot go on (its plan failed): from now on as if the operator asked for a
    /// hold, which becomes a stop when the device never started or the hold times out.
    void force_hold() { forced_ = std::max(forced_, 1); }

    /// An interrupt is under way: send no more spans, start and resume nothing.
    bool active() const { return hold_sent_ || stop_sent_; }
    bool hold_sent() const { return hold_sent_; }
    bool stop_sent() const { return stop_sent_; }

    /// The interrupt is complete: after a hold, the device holds at rest (or the hold came too
    /// late and the job ended, idle); after a stop, it is idle. Fault and e-stop end it too.
    bool settled(const DeviceSnapshot& s) const {
        using device::DeviceState;
        const DeviceState state = s.state;
        if (state == DeviceState::kIdle || state == DeviceState::kFault ||
            state == DeviceState::kEstop)
            return true;
        return !stop_sent_ && state == DeviceState::kHolding && !s.own_move();
    }

    /// 1: held (the job's rest still queued), 2: stopped.
    int outcome() const { return stop_sent_ ? 2 : 1; }

private:
    using Clock = std::chrono::steady_clock;
    const InterruptOptions& options_;
    int forced_ = 0;
    bool hold_sent_ = false;
    bool stop_sent_ = false;
    Clock::time_point hold_at_;
};

/// Programmed pauses seen by a stream: tells the operator once per pause and sends the resume
/// when they ask for it at the terminal.
class PauseWatch {
public:
    PauseWatch(const InterruptOptions& options, const std::vector<PlanPause>& pauses)
        : options_(options), pauses_(pauses) {}

    /// After each status read. `plan_ticks`: path ticks of the plan executed so far. True when
    /// the resume should be sent now.
    bool observe(const DeviceSnapshot& s, std::uint64_t plan_ticks) {
        const bool paused = s.paused() && s.state == device::DeviceState::kHolding;
        if (paused && !was_paused_) {
            resume_sent_ = false;
            if (options_.on_pause) options_.on_pause(index_at(plan_ticks));
        }
        was_paused_ = paused;
        if (!paused || resume_sent_ || !options_.resume_requested) return false;
        resume_sent_ = options_.resume_requested();
        return resume_sent_;
    }

private:
    // The pause the device rests at: the first one at or after the ticks executed (a pause's
    // tick is the end of the span it follows).
    std::size_t index_at(std::uint64_t plan_ticks) const {
        const auto it =
            std::lower_bound(pauses_.begin(), pauses_.end(), plan_ticks,
                             [](const PlanPause& p, std::uint64_t t) { return p.tick < t; });
        if (it == pauses_.end()) return pauses_.empty() ? 0 : pauses_.size() - 1;
        return static_cast<std::size_t>(it - pauses_.begin());
    }

    const InterruptOptions& options_;
    const std::vector<PlanPause>& pauses_;
    bool was_paused_ = false;
    bool resume_sent_ = false;
};

}  // namespace pathstream::host
