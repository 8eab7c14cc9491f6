// Operator commands with an argument, which the device carries out itself: a jog (one axis
// moved by a distance at up to a feed, planned and limit-checked on the device) and set
// position (one axis's coordinate redefined at rest). Both bus mappings carry them as a
// command value with an axis, a signed 32-bit value and a feed (docs/device.md, "Jog and set
// position").
#pragma once

#include <cstdint>

#include "pathstream/device/axis_move.hpp"
#include "pathstream/device/command.hpp"
#include "pathstream/device/motion_device.hpp"

namespace pathstream::device {

/// Feed of a jog: per mille of the axis's configured max velocity (1..1000; 0 means 1000).
inline constexpr std::uint16_t kJogFeedFull = 1000;

/// A jog in progress: the device's own job of rest-to-rest spans (AxisMove: constant
/// acceleration ramps, or S-curves under a jerk limit, cruise, a creep span at rest), fed into
/// the span queue as room frees,
/// each span checked like a host's (continuity, exact limits). Task context only: start() from
/// the bus handler, service() from the task loop (at least once per span period, 8 ticks on
/// the example machines, or the queue may run dry and the device underrun-stop).
template <unsigned Axes, std::uint32_t Capacity>
class Jog {
public:
    explicit Jog(MotionDevice<Axes, Capacity>& device) : device_(device) {}

    /// Jogs `axis` by `distance` LSB (signed, not 0) at up to `feed` per mille of its max
    /// velocity, with the operator's pen as it is (set_pen: a jog with the pen down draws, as a
    /// plotter's manual walk does, and leaves it down). Refusals: kNotConfigured; kWrongState
    /// unless idle with nothing queued; kControlValueOutOfRange for an axis >= Axes, distance 0, an
    /// end point outside
    /// +-kMaxPositionLsb or a feed above 1000; kBadLimits when the limits allow no move. On kOk
    /// the job is queued (as much as fits) and started: it takes the next sequence numbers and
    /// ends idle at the new point, reported as a finished job like any other.
    [[nodiscard]] Status start(unsigned axis, std::int32_t distance, std::uint16_t feed) {
        if (!device_.configured()) return Status::kNotConfigured;
        if (device_.state() != DeviceState::kIdle || device_.queued_spans() != 0 ||
            device_.command_pending() || device_.position_pending()) {
            return Status::kWrongState;
        }
        if (axis >= Axes || distance == 0 || feed > kJogFeedFull)
            return Status::kControlValueOutOfRange;
        Lsb from[Axes];
        for (unsigned a = 0; a < Axes; ++a) from[a] = device_.position(a);
        const std::int64_t end = static_cast<std::int64_t>(from[axis]) + distance;
        if (end > kMaxPositionLsb || end < -kMaxPositionLsb) return Status::kControlValueOutOfRange;
        // The travel (soft limits): the jog must end inside it. One that starts outside (after
        // a set position, or homing's pull-off past a limit) may come back in: its spans are
        // then let through without the travel check, since they start outside by definition.
        const AxisLimits& travel = device_.limits().axis[axis];
        if (end < travel.min_position || end > travel.max_position) return Status::kOutsideTravel;
        const bool from_outside =
            from[axis] < travel.min_position || from[axis] > travel.max_position;
        const std::uint64_t max_velocity = device_.limits().axis[axis].max_velocity;
        const std::uint16_t per_mille = feed == 0 ? kJogFeedFull : feed;
        std::uint64_t velocity = max_velocity * per_mille / kJogFeedFull;
        if (velocity == 0) velocity = 1;
        if (Status s = move_.plan(from, axis, distance, static_cast<std::uint32_t>(velocity),
                                  device_.limits());
            s != Status::kOk) {
            return s;
        }
        pen_ = static_cast<std::uint8_t>(device_.outputs() & kOutputPenDown);
        epoch_ = device_.epoch();
        job_ = device_.last_accepted_sequence() + 1u;
        active_ = true;
        travel_off_ = from_outside;
        if (travel_off_) device_.enforce_travel(false);
        if (Status s = feed_spans(); s != Status::kOk) {
            end_jog();
            return s;
        }
        return device_.start_keeping_pen();
    }

    /// Queues more of the jog as room frees; gives up when the device dropped the jog (stop,
    /// fault, e-stop: a new epoch) or it ran to its end.
    void service() {
        if (!active_) return;
        const DeviceState state = device_.state();
        if (device_.epoch() != epoch_ || state == DeviceState::kStopping ||
            state == DeviceState::kFault || state == DeviceState::kEstop) {
            end_jog();
            return;
        }
        if (feed_spans() != Status::kOk) end_jog();
    }

    /// Spans of the jog still to be queued.
    bool feeding() const { return active_; }
    /// The jog's job id (its first span's sequence number).
    std::uint32_t job() const { return job_; }

private:
    static constexpr unsigned kFeedSpans = 8;  // spans per accept_batch: a small stack buffer

    // The jog is fed no more; the travel check holds again.
    void end_jog() {
        active_ = false;
        if (travel_off_) device_.enforce_travel(true);
        travel_off_ = false;
    }

    Status feed_spans() {
        while (move_.pending()) {
            const std::uint32_t room = device_.free_slots();
            if (room == 0) return Status::kOk;
            std::uint8_t bytes[kFeedSpans * (4 + 12 * Axes)];
            std::size_t length = 0;
            std::uint16_t count = 0;
            while (count < kFeedSpans && count < room && move_.pending()) {
                WireSpan w;
                if (!move_.next(w)) return Status::kAccelerationLimit;
                if (!move_.pending()) w.flags |= kWireJobEnd;
                w.outputs = pen_;
                length += encode_wire_span(w, Axes, bytes + length, sizeof bytes - length);
                ++count;
            }
            if (Status s = device_.accept_batch(device_.last_accepted_sequence() + 1u, count, bytes,
                                                length);
                s != Status::kOk) {
                return s;
            }
        }
        end_jog();
        return Status::kOk;
    }

    MotionDevice<Axes, Capacity>& device_;
    AxisMove<Axes> move_;
    std::uint32_t epoch_ = 0;
    std::uint32_t job_ = 0;
    std::uint8_t pen_ = 0;     // the operator's pen when the jog started: every span carries it
    bool travel_off_ = false;  // this jog started outside the travel and turned its check off
    bool active_ = false;
};

/// Redefines `axis`'s coordinate as `position` without moving (the other axes keep theirs):
/// MotionDevice::set_position, so idle with nothing queued only (kWrongState otherwise);
/// kControlValueOutOfRange for an axis >= Axes or a position outside +-kMaxPositionLsb.
template <unsigned Axes, std::uint32_t Capacity>
[[nodiscard]] Status set_axis_position(MotionDevice<Axes, Capacity>& device, unsigned axis,
                                       std::int32_t position) {
    if (axis >= Axes || position > kMaxPositionLsb || position < -kMaxPositionLsb) {
        return Status::kControlValueOutOfRange;
    }
    Lsb p[Axes];
    for (unsigned a = 0; a < Axes; ++a) p[a] = device.position(a);
    p[axis] = position;
    return device.set_position(p);
}

}  // namespace pathstream::device
