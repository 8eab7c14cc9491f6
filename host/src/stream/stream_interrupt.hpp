// What an interrupted stream does next (Ctrl-C, SIGTERM), from the operator's requests and the
// device's state; the Modbus and CAN streamers share it.
#pragma once

#include <chrono>

#include "pathstream/device/device_state.hpp"
#include "pathstream/host/device_link.hpp"
#include "pathstream/host/modbus_stream.hpp"

namespace pathstream::host {

class StreamInterrupt {
public:
    enum class Action { kNone, kHold, kStop };

    explicit StreamInterrupt(const InterruptOptions& options) : options_(options) {}

    /// The command to send now, each at most once: a hold at the first request (a stop
    /// instead when the device was never started: it drops what is queued and nothing moved),
    /// a stop at the second request or when the hold has not come to rest in time.
    Action next_action(bool started) {
        const int request = options_.request != nullptr ? options_.request->load() : 0;
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

    /// An interrupt is under way: send no more spans, start and resume nothing.
    bool active() const { return hold_sent_ || stop_sent_; }
    bool hold_sent() const { return hold_sent_; }
    bool stop_sent() const { return stop_sent_; }

    /// The interrupt is complete: after a hold, the device holds at rest (or the hold came too
    /// late and the job ended, idle); after a stop, it is idle. Fault and e-stop end it too.
    bool settled(const DeviceSnapshot& s) const {
        using device::DeviceState;
        const auto state = static_cast<DeviceState>(s.state);
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
    bool hold_sent_ = false;
    bool stop_sent_ = false;
    Clock::time_point hold_at_;
};

}  // namespace pathstream::host
