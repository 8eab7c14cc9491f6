// The device: a task side (DeviceReceiver: batches, validation, limit and join checks,
// commands, configuration) and a tick side (DeviceExecutor: the queue's consumer, stops,
// re-entry, outputs) that share nothing but a DeviceChannel (the span queue, a mailbox, a
// status board). Every bus protocol (Modbus, CAN), the GPIO logic and homing drive this.
// docs/device.md has the contract of every shared field.
#pragma once

#include <cstddef>
#include <cstdint>

#include "pathstream/device/device_channel.hpp"
#include "pathstream/device/device_executor.hpp"
#include "pathstream/device/device_receiver.hpp"
#include "pathstream/device/device_state.hpp"
#include "pathstream/device/motion_limits.hpp"
#include "pathstream/device/wire_span.hpp"
#include "pathstream/status.hpp"

namespace pathstream::device {

/// A device of `Axes` axes with a span queue `Capacity` deep: one DeviceChannel, its
/// DeviceReceiver and its DeviceExecutor in one object (a port may also place the three
/// itself). Contexts: tick() runs in the tick interrupt; every other member runs in one task
/// (the bus server), except raise_fault() and set_estop_input() (any context). The status
/// getters read the tick's last published status (status() returns it whole; each getter
/// reads it once). Storage inline, no allocation.
template <unsigned Axes, std::uint32_t Capacity>
class MotionDevice {
public:
    /// Idle at `start` (LSB per axis), unconfigured. Init context.
    explicit MotionDevice(const Lsb (&start)[Axes])
        : channel_(start), receiver_(channel_), executor_(channel_, start) {}
    MotionDevice(const MotionDevice&) = delete;
    MotionDevice& operator=(const MotionDevice&) = delete;

    DeviceReceiver<Axes, Capacity>& receiver() { return receiver_; }
    DeviceExecutor<Axes, Capacity>& executor() { return executor_; }

    // ---- task side (DeviceReceiver) ---------------------------------------------------

    /// DeviceReceiver::configure. Task context.
    [[nodiscard]] Status configure(const MotionLimits<Axes>& limits) {
        return receiver_.configure(limits);
    }
    bool configured() const { return receiver_.configured(); }
    /// DeviceReceiver::enforce_travel (homing turns the soft limits off while it runs). Task.
    void enforce_travel(bool on) { receiver_.enforce_travel(on); }
    const MotionLimits<Axes>& limits() const { return receiver_.limits(); }
    /// DeviceReceiver::accept_batch. Task context.
    template <typename Between = NoInterleave>
    [[nodiscard]] Status accept_batch(std::uint32_t first_sequence, std::uint16_t count,
                                      const std::uint8_t* payload, std::size_t length,
                                      Between&& between = Between{}) {
        return receiver_.accept_batch(first_sequence, count, payload, length,
                                      static_cast<Between&&>(between));
    }
    /// DeviceReceiver::command. Task context.
    [[nodiscard]] Status command(Command c) { return receiver_.command(c); }
    /// DeviceReceiver::start_keeping_pen (the device's own jog). Task context.
    [[nodiscard]] Status start_keeping_pen() { return receiver_.start_keeping_pen(); }
    /// DeviceReceiver::set_pen: the operator's pen at rest while idle. Task context.
    [[nodiscard]] Status set_pen(bool down) { return receiver_.set_pen(down); }
    /// True until the tick has taken the last command posted. Task context.
    bool command_pending() const { return receiver_.command_pending(); }
    /// DeviceReceiver::raise_fault. Any context.
    void raise_fault(FaultCode code) { receiver_.raise_fault(code); }
    /// DeviceReceiver::set_estop_input. Any context.
    void set_estop_input(bool active) { receiver_.set_estop_input(active); }
    /// DeviceReceiver::set_position. Task context.
    [[nodiscard]] Status set_position(const Lsb (&position)[Axes]) {
        return receiver_.set_position(position);
    }
    bool position_pending() const { return receiver_.position_pending(); }

    // ---- status (task side; each reads the tick's last published status once) -----------

    DeviceStatus<Axes> status() const { return receiver_.status(); }
    DeviceState state() const { return status().device_state(); }
    FaultCode fault_code() const { return status().fault(); }
    std::uint32_t free_slots() const { return receiver_.free_slots(); }
    static constexpr std::uint32_t capacity() { return Capacity; }
    /// Sequence number of the last span accepted (0 before the first; the first is 1).
    std::uint32_t last_accepted_sequence() const { return receiver_.last_accepted_sequence(); }
    /// Sequence number (= tag) of the last span executed to its end.
    std::uint32_t last_completed_sequence() const { return status().last_completed_sequence; }
    /// Path ticks executed (ticks supplied by accepted spans; stop and re-entry moves excluded).
    std::uint64_t ticks_executed() const { return status().ticks_executed(); }
    /// Ticks of stop and re-entry moves the device generated itself.
    std::uint64_t generated_ticks() const { return status().generated_ticks(); }
    /// Setpoint output by the last tick, per axis.
    Lsb position(unsigned axis) const { return status().position[axis]; }
    /// Discrete outputs the last tick drove: the playing span's on a path tick; on any other
    /// tick the machine functions (kOutputMachineMask) of the span last played while a job runs,
    /// holds or stops, and no pen (except the pen-down lead at the end of a re-entry, and the
    /// operator's pen at rest while idle, set_pen).
    std::uint8_t outputs() const { return static_cast<std::uint8_t>(status().outputs); }
    std::uint32_t underruns() const { return status().underruns; }
    std::uint32_t duplicates() const { return receiver_.duplicates(); }
    std::uint32_t queued_spans() const { return receiver_.queued_spans(); }
    /// True while holding because the queue ran dry (not because of a hold command).
    bool held_by_underrun() const { return status().held_by_underrun(); }
    /// True while holding at a programmed pause (kWirePause), until resumed or stopped.
    bool paused() const { return status().paused(); }
    /// Id (sequence number of its first span) of the last job run to its end; 0 before.
    std::uint32_t finished_job() const { return status().finished_job; }
    /// Path ticks the last finished job executed (low 32 bits).
    std::uint32_t finished_job_ticks() const { return status().finished_job_ticks; }
    /// Queue epoch: advanced by every queue drop (stop, e-stop, fault, reset, set position).
    std::uint32_t epoch() const { return status().epoch; }

    // ---- tick interrupt (DeviceExecutor) ----------------------------------------------

    /// DeviceExecutor::tick. Tick interrupt context.
    void tick(Lsb (&out)[Axes]) { executor_.tick(out); }

private:
    DeviceChannel<Axes, Capacity> channel_;
    DeviceReceiver<Axes, Capacity> receiver_;
    DeviceExecutor<Axes, Capacity> executor_;
};

}  // namespace pathstream::device
