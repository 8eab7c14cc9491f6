// Homing one axis against a switch: search toward it, back off, approach slowly, set zero.
//
// The sequencer is a producer like a bus master: it feeds its own moves to a MotionDevice as
// wire spans (accept_batch, checked like a host's), each move one job (its last span marks the job
// end, so the device idles at the move's end by itself), stops the device with a command when the
// switch is seen, and finally redefines the position with set_position. Every move is a
// rest-to-rest trapezoid of constant-acceleration Hermite spans (cubic term exactly zero), or under
// a jerk limit an S-curve of exact cubics (s_curve_ramp.hpp), so the device's exact limit check
// passes them like any planned span; integer math only (docs/gpio.md).
#pragma once

#include <cstdint>

#include "pathstream/device/axis_move.hpp"
#include "pathstream/device/motion_device.hpp"
#include "pathstream/device/stop_spans.hpp"

namespace pathstream::device {

/// What to home and how. Velocities in LSB/s, distances in LSB.
struct HomingConfig {
    unsigned axis = 0;
    bool toward_positive = false;       ///< the switch is at the positive end ("x+")
    std::uint32_t search_velocity = 0;  ///< fast approach; >= 1
    std::uint32_t latch_velocity = 0;   ///< slow approach that defines zero; >= 1
    std::uint32_t backoff = 0;          ///< distance moved off the switch after the search; >= 1
    std::uint32_t max_travel = 0;       ///< the search gives up after this distance; >= 1
    Lsb home_position = 0;              ///< coordinate of the latch point after homing
    /// Distance moved off the switch after zero is set (0: stay where the latch stop ended,
    /// on the switch). A machine pulled off its switch can move either way without
    /// re-triggering it, and the switch's next edge is a real event.
    std::uint32_t pull_off = 0;
};

enum class HomingPhase : std::uint8_t {
    kIdle,        ///< not started
    kStarting,    ///< started; the first poll chooses the first move
    kSearch,      ///< moving toward the switch at search velocity
    kSearchStop,  ///< switch seen: controlled stop
    kBackoff,     ///< moving off the switch
    kBackoffStop,
    kLatch,      ///< approaching at latch velocity
    kLatchStop,  ///< switch seen again: controlled stop
    kSetZero,    ///< set_position requested
    kPullOff,    ///< moving off the switch in the new coordinates
    kPullOffStop,
    kDone,
    kError,
};

enum class HomingError : std::uint8_t {
    kNone,
    kBadConfig,       ///< a velocity, distance or the axis is out of range
    kDeviceRefused,   ///< the device refused a span, a command or set_position (error_status())
    kSwitchNotFound,  ///< the search covered max_travel without the switch
    kSwitchStuck,     ///< the switch was still active after the back-off or the pull-off
    kLatchNotFound,   ///< the slow approach did not find the switch again
    kInterrupted,     ///< the device went to fault or e-stop, or was stopped from outside
};

/// Where one axis stands with homing, as the bus status reports it.
enum class AxisHoming : std::uint8_t {
    kNotHomed = 0,  ///< never homed since the device started
    kHoming = 1,    ///< homing now, or waiting its turn in a homing run
    kHomed = 2,     ///< its last homing ended with zero set
    kFailed = 3,    ///< its last homing ended in an error (HomingReport::error)
};

/// One axis's homing state and, when it failed, why.
struct HomingReport {
    AxisHoming state = AxisHoming::kNotHomed;
    HomingError error = HomingError::kNone;
};

/// Homes one axis of a MotionDevice. Task context: call poll() with the switch's level after
/// every tick (or as often as the task runs; the latch point is the position at the poll that
/// first sees the switch, so its precision is one poll period of latch velocity).
template <unsigned Axes, std::uint32_t Capacity>
class HomingSequencer {
public:
    explicit HomingSequencer(MotionDevice<Axes, Capacity>& device) : device_(device) {}

    /// Starts homing. The device must be configured and idle (kWrongState otherwise);
    /// kBadConfig for zero velocities or distances, a distance above kMaxPositionLsb (2^27) or
    /// a bad axis. Task context.
    [[nodiscard]] Status start(const HomingConfig& config) {
        config_ = config;
        error_ = HomingError::kNone;
        error_status_ = Status::kOk;
        if (config.axis >= Axes || config.search_velocity == 0 || config.latch_velocity == 0 ||
            config.backoff == 0 || config.max_travel == 0 || config.max_travel > kMaxPositionLsb ||
            config.backoff > kMaxPositionLsb || config.pull_off > kMaxPositionLsb) {
            return finish_error(HomingError::kBadConfig, Status::kBadLimits);
        }
        if (!device_.configured())
            return finish_error(HomingError::kDeviceRefused, Status::kNotConfigured);
        if (device_.state() != DeviceState::kIdle)
            return finish_error(HomingError::kDeviceRefused, Status::kWrongState);
        // The first move is chosen by the first poll, which knows the switch: a machine
        // already standing on it backs off first.
        phase_ = HomingPhase::kStarting;
        // The switch lies wherever it lies: the soft limits hold again once homing ends.
        device_.enforce_travel(false);
        return Status::kOk;
    }

    /// Advances the sequence; `switch_active` is the homing switch's level now. Task context.
    void poll(bool switch_active) {
        advance(switch_active);
        if (!busy()) device_.enforce_travel(true);
    }

private:
    // One step of the sequence (poll's body).
    void advance(bool switch_active) {
        const DeviceState s = device_.state();
        if (phase_ == HomingPhase::kIdle || phase_ == HomingPhase::kDone ||
            phase_ == HomingPhase::kError)
            return;
        if (s == DeviceState::kFault || s == DeviceState::kEstop) {
            (void)finish_error(HomingError::kInterrupted, Status::kWrongState);
            return;
        }
        if (stop_requested_for_ == HomingPhase::kError) {
            // A failed search, back-off or latch: report once the device has stopped.
            if (idle(s)) phase_ = HomingPhase::kError;
            return;
        }
        switch (phase_) {
            case HomingPhase::kStarting:
                if (switch_active) {
                    trigger_ = device_.position(config_.axis);
                    overshoot_ = 0;
                    if (begin_move(-toward(config_.backoff), config_.search_velocity) ==
                        Status::kOk) {
                        phase_ = HomingPhase::kBackoff;
                    }
                } else if (begin_move(toward(config_.max_travel), config_.search_velocity) ==
                           Status::kOk) {
                    phase_ = HomingPhase::kSearch;
                }
                break;
            case HomingPhase::kSearch:
                if (switch_active) {
                    trigger_ = device_.position(config_.axis);
                    request_stop(HomingPhase::kSearchStop);
                } else if (feed() && move_done(s)) {
                    error_ = HomingError::kSwitchNotFound;
                    request_stop(HomingPhase::kError);
                }
                break;
            case HomingPhase::kSearchStop:
                if (idle(s)) {
                    const Lsb here = device_.position(config_.axis);
                    overshoot_ = here > trigger_ ? here - trigger_ : trigger_ - here;
                    if (begin_move(-toward(config_.backoff), config_.search_velocity) ==
                        Status::kOk) {
                        phase_ = HomingPhase::kBackoff;
                    }
                }
                break;
            case HomingPhase::kBackoff:
                if (feed() && move_done(s)) {
                    if (switch_active) {
                        error_ = HomingError::kSwitchStuck;
                        request_stop(HomingPhase::kError);
                    } else {
                        request_stop(HomingPhase::kBackoffStop);
                    }
                }
                break;
            case HomingPhase::kBackoffStop:
                if (idle(s)) {
                    const std::int64_t travel =
                        2 * static_cast<std::int64_t>(config_.backoff) + overshoot_;
                    if (begin_move(toward(travel), config_.latch_velocity) == Status::kOk)
                        phase_ = HomingPhase::kLatch;
                }
                break;
            case HomingPhase::kLatch:
                if (switch_active) {
                    trigger_ = device_.position(config_.axis);
                    request_stop(HomingPhase::kLatchStop);
                } else if (feed() && move_done(s)) {
                    error_ = HomingError::kLatchNotFound;
                    request_stop(HomingPhase::kError);
                }
                break;
            case HomingPhase::kLatchStop:
                if (idle(s)) {
                    Lsb p[Axes];
                    for (unsigned a = 0; a < Axes; ++a) p[a] = device_.position(a);
                    p[config_.axis] = config_.home_position + (p[config_.axis] - trigger_);
                    if (Status st = device_.set_position(p); st != Status::kOk) {
                        (void)finish_error(HomingError::kDeviceRefused, st);
                        return;
                    }
                    phase_ = HomingPhase::kSetZero;
                }
                break;
            case HomingPhase::kSetZero:
                if (device_.position_pending()) break;
                if (config_.pull_off == 0) {
                    phase_ = HomingPhase::kDone;
                } else if (begin_move(-toward(config_.pull_off), config_.search_velocity) ==
                           Status::kOk) {
                    phase_ = HomingPhase::kPullOff;
                }
                break;
            case HomingPhase::kPullOff:
                if (feed() && move_done(s)) {
                    if (switch_active) {
                        error_ = HomingError::kSwitchStuck;
                        request_stop(HomingPhase::kError);
                    } else {
                        request_stop(HomingPhase::kPullOffStop);
                    }
                }
                break;
            case HomingPhase::kPullOffStop:
                if (idle(s)) phase_ = HomingPhase::kDone;
                break;
            default:
                break;
        }
    }

public:
    HomingPhase phase() const { return phase_; }
    HomingError error() const { return error_; }
    /// The device's Status behind kDeviceRefused (or kOk).
    Status error_status() const { return error_status_; }
    bool busy() const {
        return phase_ != HomingPhase::kIdle && phase_ != HomingPhase::kDone &&
               phase_ != HomingPhase::kError;
    }
    /// Position at which the latch approach saw the switch, before set zero (LSB).
    Lsb latch_position() const { return trigger_; }
    /// How far the search stop ran past the point where the switch was seen (LSB).
    std::int64_t search_overshoot() const { return overshoot_; }

private:
    static constexpr unsigned kFeedSpans = 8;  // spans per accept_batch: a small stack buffer

    std::int64_t toward(std::int64_t distance) const {
        return config_.toward_positive ? distance : -distance;
    }

    Status finish_error(HomingError e, Status s) {
        error_ = e;
        error_status_ = s;
        phase_ = HomingPhase::kError;
        return e == HomingError::kBadConfig ? Status::kBadLimits : s;
    }

    Status begin_move(std::int64_t distance, std::uint32_t velocity) {
        Lsb from[Axes];
        for (unsigned a = 0; a < Axes; ++a) from[a] = device_.position(a);
        if (Status s = move_.plan(from, config_.axis, distance, velocity, device_.limits());
            s != Status::kOk) {
            return finish_error(HomingError::kDeviceRefused, s);
        }
        stop_requested_for_ = HomingPhase::kIdle;
        fed_all_ = false;
        move_job_ = device_.last_accepted_sequence() + 1u;  // a job's id: its first span's sequence
        if (!feed()) return error_status_;
        if (Status s = device_.command(Command::kStart); s != Status::kOk)
            return finish_error(HomingError::kDeviceRefused, s);
        return Status::kOk;
    }

    // Queues as many of the move's spans as fit. False after an error (phase kError).
    bool feed() {
        if (stop_requested_for_ != HomingPhase::kIdle) return true;
        while (move_.pending()) {
            const std::uint32_t room = device_.free_slots();
            if (room == 0) return true;
            std::uint8_t bytes[kFeedSpans * (4 + 12 * Axes)];
            std::size_t length = 0;
            std::uint16_t count = 0;
            while (count < kFeedSpans && count < room && move_.pending()) {
                WireSpan w;
                if (!move_.next(w)) {
                    (void)finish_error(HomingError::kDeviceRefused, Status::kAccelerationLimit);
                    return false;
                }
                if (!move_.pending()) w.flags |= kWireJobEnd;  // the move ends at rest: the job too
                length += encode_wire_span(w, Axes, bytes + length, sizeof bytes - length);
                ++count;
            }
            const Status s =
                device_.accept_batch(device_.last_accepted_sequence() + 1u, count, bytes, length);
            if (s != Status::kOk) {
                (void)finish_error(HomingError::kDeviceRefused, s);
                return false;
            }
        }
        fed_all_ = true;
        return true;
    }

    // The whole move was queued and executed: its job finished, the device idle at its end.
    bool move_done(DeviceState s) const {
        return fed_all_ && s == DeviceState::kIdle && device_.finished_job() == move_job_;
    }

    // Stops the device unless it already idles (its move finished); the phases that wait for
    // idle also wait until the tick has taken the stop, so a later move is never dropped by it.
    void request_stop(HomingPhase next) {
        if (device_.state() != DeviceState::kIdle) {
            if (Status st = device_.command(Command::kStop); st != Status::kOk) {
                (void)finish_error(HomingError::kDeviceRefused, st);
                return;
            }
        }
        stop_requested_for_ = next;
        if (next != HomingPhase::kError) phase_ = next;
    }

    // Idle, and no command of ours still waiting for the tick.
    bool idle(DeviceState s) const { return s == DeviceState::kIdle && !device_.command_pending(); }

    MotionDevice<Axes, Capacity>& device_;
    HomingConfig config_;
    HomingPhase phase_ = HomingPhase::kIdle;
    HomingError error_ = HomingError::kNone;
    Status error_status_ = Status::kOk;
    AxisMove<Axes> move_;
    bool fed_all_ = false;
    std::uint32_t move_job_ = 0;
    HomingPhase stop_requested_for_ = HomingPhase::kIdle;
    Lsb trigger_ = 0;
    std::int64_t overshoot_ = 0;
};

}  // namespace pathstream::device
