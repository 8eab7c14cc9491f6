// What every bus device (Modbus, native CAN) shares: a MotionDevice ticked by a Linux thread,
// per-tick recording, self-configuration from a machine profile, and optional GPIO and homing
// (DeviceIo). The bus side differs; this part is written once.
#pragma once

#include <cstdint>
#include <cstring>
#include <memory>
#include <type_traits>
#include <vector>

#include "pathstream/device/motion_device.hpp"
#include "pathstream/input_shaper.hpp"
#include "pathstream/linux_device/device_io.hpp"
#include "pathstream/machine/device_setup.hpp"
#include "pathstream/machine/shaper_design.hpp"
#include "pathstream/shaper_taps.hpp"
#include "pathstream/units.hpp"

namespace pathstream::linux_device {

/// One tick the device executed, as recorded.
struct DeviceTick {
    std::uint8_t state = 0;    ///< device::DeviceState after the tick
    std::uint8_t outputs = 0;  ///< discrete outputs (pen) after the tick
};

/// Something outside the device that follows its axes after every tick: a simulated machine's
/// switches (sim/), a recorder. Task context, the thread that ticks the device.
class TickObserver {
public:
    virtual ~TickObserver() = default;
    /// `position`: the setpoints the tick output (device coordinates, `axes` of them);
    /// `positions_set`: the device's count of applied position settings (a change means the
    /// coordinates jumped while the axes stood still).
    virtual void after_tick(const Lsb* position, unsigned axes, std::uint32_t positions_set) = 0;
};

/// A MotionDevice type-erased over the axis count. Not thread-safe: one thread serves and
/// ticks it.
class AnyMotionDevice {
public:
    virtual ~AnyMotionDevice() = default;

    /// One device tick (with the I/O's inputs before and outputs after it, when attached);
    /// when recording and the tick was a path tick (supplied by an accepted span, not a
    /// generated stop or re-entry move) appends its setpoints and outputs.
    virtual void tick() = 0;
    virtual unsigned axes() const = 0;
    /// Tick rate the device is configured for (0 before configuration).
    virtual std::uint32_t tick_hz() const = 0;
    /// Device state (device::DeviceState as a number).
    virtual device::DeviceState state() const = 0;
    /// Fault code (device::FaultCode as a number; 0 = none).
    virtual std::uint16_t fault_code() const = 0;
    /// Setpoint of the last tick.
    virtual Lsb position(unsigned axis) const = 0;
    /// Job of the span in progress or last played (0: none); docs/device.md, "Jobs".
    virtual std::uint32_t job() const = 0;
    /// The last job run to its end (0: none) and its path ticks.
    virtual std::uint32_t finished_job() const = 0;
    virtual std::uint32_t finished_job_ticks() const = 0;
    /// Raises an external fault (as a drive fault input would).
    virtual void raise_fault() = 0;
    /// Raises `code` (e.g. kOutputFailed: an output module did not confirm a write); the next
    /// tick stops the machine at once. The first code raised is kept until a reset.
    virtual void raise_fault(device::FaultCode code) = 0;
    /// The outputs the last tick drove (MotionDevice::outputs: pen, spindle, coolant).
    virtual std::uint8_t outputs() const = 0;
    /// Configures the device as a host's configuration would (idle only). Returns the
    /// device's Status (kBadLimits for zero limits or a wrong axis count, kWrongState;
    /// kBadShaper for a tick rate other than the one an input shaper was set for).
    [[nodiscard]] virtual Status configure(const host::DeviceLimitsLsb& limits) = 0;
    /// Shapes `axis`'s output from now on with `taps` (empty: unshaped), designed for
    /// `tick_hz` ticks (docs/input-shaping.md): every tick's setpoints go through an
    /// InputShaper<axes, host::kDeviceShaperHistoryTicks> before the observer and the
    /// every-tick record see them; the status, the bus and the path-tick record keep the
    /// unshaped command. A jump of the coordinates (set position, homing's zero) resets the
    /// shaper instead of becoming a motion. kBadShaper for an axis out of range, taps
    /// check_shaper_taps refuses or a tick rate other than the configured one; kWrongState
    /// while the shaped output still moves. Task context, the ticking thread.
    [[nodiscard]] virtual Status configure_shaper(unsigned axis, const std::vector<ShaperTap>& taps,
                                                  std::uint32_t tick_hz) = 0;
    /// Wires the device to discrete lines; from now on every tick polls the inputs before
    /// it and drives the outputs after it. The lines must outlive the device. Init context.
    virtual DeviceIo& attach_io(const MachineWiring& wiring) = 0;

    /// Calls `observer` after every tick from now on (nullptr: none). The observer must outlive
    /// the device or be removed first. Init context.
    void observe_ticks(TickObserver* observer) { observer_ = observer; }

    /// Records every path tick from now on: setpoints[k * axes + axis] is path tick k's
    /// command (before any input shaper).
    void record(bool on) { recording_ = on; }
    const std::vector<Lsb>& recorded_setpoints() const { return setpoints_; }
    const std::vector<DeviceTick>& recorded_ticks() const { return ticks_; }
    /// Records every tick from now on, path or not (stop and re-entry moves, rest): what the
    /// axes were actually commanded (after any input shaper), for checking the device's own
    /// moves against the limits. every_tick_setpoints()[k * axes + axis] is tick k's (k
    /// counted from the call).
    void record_every_tick(bool on) { recording_every_tick_ = on; }
    const std::vector<Lsb>& every_tick_setpoints() const { return every_tick_; }
    /// With record_every_tick: every tick's command before the input shaper (the same as
    /// every_tick_setpoints() without one).
    const std::vector<Lsb>& every_tick_commands() const { return every_tick_command_; }
    std::uint64_t ticks_run() const { return ticks_run_; }
    /// Consecutive ticks, up to the last, that changed nothing in the device's status but its
    /// tick count: how long it has been at rest (a dwell or a wait for the host included).
    std::uint64_t unchanged_ticks() const { return unchanged_ticks_; }

protected:
    TickObserver* observer_ = nullptr;
    bool recording_ = false;
    bool recording_every_tick_ = false;
    std::vector<Lsb> setpoints_;
    std::vector<Lsb> every_tick_;
    std::vector<Lsb> every_tick_command_;
    std::vector<DeviceTick> ticks_;
    std::uint64_t ticks_run_ = 0;
    std::uint64_t unchanged_ticks_ = 0;
};

/// The shared half of a bus device class: `Interface` (a AnyMotionDevice) with
/// its MotionDevice<Axes, Capacity> and the common functions implemented.
template <unsigned Axes, std::uint32_t Capacity, typename Interface>
class MotionDeviceBase : public Interface {
public:
    explicit MotionDeviceBase(const Lsb (&start)[Axes]) : device_(start) {}

    void tick() override {
        if (io_) io_->before_tick();
        Lsb command[Axes], out[Axes];
        const std::uint64_t before = device_.ticks_executed();
        device_.tick(command);
        for (unsigned a = 0; a < Axes; ++a) out[a] = command[a];
        if (shaper_) shape(out);
        if (io_) io_->after_tick();
        // The status but its tick count (the words after tick_count and before tick_check,
        // then every word after it), against the last tick's.
        static_assert(std::has_unique_object_representations_v<device::DeviceStatus<Axes>>,
                      "compared bytewise");
        device::DeviceStatus<Axes> now = device_.status();
        now.tick_count = now.tick_check = 0;
        // A shaped output still moving after the command rests is not at rest.
        const bool same =
            std::memcmp(&now, &last_status_, sizeof now) == 0 && (!shaper_ || shaper_->settled());
        this->unchanged_ticks_ = same ? this->unchanged_ticks_ + 1 : 0;
        last_status_ = now;
        if (this->observer_ != nullptr)
            this->observer_->after_tick(out, Axes, device_.status().position_applied);
        ++this->ticks_run_;
        if (this->recording_every_tick_) {
            this->every_tick_.insert(this->every_tick_.end(), out, out + Axes);
            this->every_tick_command_.insert(this->every_tick_command_.end(), command,
                                             command + Axes);
        }
        if (this->recording_ && device_.ticks_executed() != before) {  // a path tick
            this->setpoints_.insert(this->setpoints_.end(), command, command + Axes);
            this->ticks_.push_back({static_cast<std::uint8_t>(device_.state()), device_.outputs()});
        }
    }
    unsigned axes() const override { return Axes; }
    std::uint32_t tick_hz() const override {
        return device_.configured() ? device_.limits().tick_hz : 0;
    }
    device::DeviceState state() const override { return device_.state(); }
    std::uint16_t fault_code() const override {
        return static_cast<std::uint16_t>(device_.fault_code());
    }
    Lsb position(unsigned axis) const override { return device_.position(axis); }
    std::uint32_t job() const override { return device_.status().job; }
    std::uint32_t finished_job() const override { return device_.status().finished_job; }
    std::uint32_t finished_job_ticks() const override {
        return device_.status().finished_job_ticks;
    }
    void raise_fault() override { device_.raise_fault(device::FaultCode::kExternal); }
    void raise_fault(device::FaultCode code) override { device_.raise_fault(code); }
    std::uint8_t outputs() const override { return device_.outputs(); }
    Status configure(const host::DeviceLimitsLsb& l) override {
        if (l.max_velocity.size() != Axes || l.max_acceleration.size() != Axes)
            return Status::kBadLimits;
        device::MotionLimits<Axes> m;
        m.tick_hz = l.tick_hz;
        for (unsigned a = 0; a < Axes; ++a) {
            m.axis[a].max_velocity = l.max_velocity[a];
            m.axis[a].max_acceleration = l.max_acceleration[a];
            if (l.min_position.size() == Axes && l.max_position.size() == Axes) {
                m.axis[a].min_position = l.min_position[a];
                m.axis[a].max_position = l.max_position[a];
            }
            if (l.max_jerk.size() == Axes) m.axis[a].max_jerk = l.max_jerk[a];
        }
        m.pen_down_ticks = l.pen_down_ticks;
        if (shaper_ && l.tick_hz != shaper_tick_hz_) return Status::kBadShaper;
        return device_.configure(m);
    }
    Status configure_shaper(unsigned axis, const std::vector<ShaperTap>& taps,
                            std::uint32_t tick_hz) override {
        if (axis >= Axes || tick_hz == 0 || (this->tick_hz() != 0 && tick_hz != this->tick_hz()))
            return Status::kBadShaper;
        if (shaper_tick_hz_ != 0 && tick_hz != shaper_tick_hz_) return Status::kBadShaper;
        if (!shaper_) {
            Lsb at[Axes];
            for (unsigned a = 0; a < Axes; ++a) at[a] = device_.position(a);
            shaper_ = std::make_unique<Shaper>(at);
            positions_set_ = device_.status().position_applied;
        }
        const Status s =
            shaper_->configure(axis, taps.data(), static_cast<std::uint32_t>(taps.size()));
        if (s == Status::kOk) shaper_tick_hz_ = tick_hz;
        return s;
    }
    DeviceIo& attach_io(const MachineWiring& wiring) override {
        io_ = std::make_unique<DeviceIoFor<Axes, Capacity>>(device_, wiring);
        connect_homing(io_->homing_port());
        return *io_;
    }

protected:
    /// Hands the I/O's homing to the bus protocol's commands (home over the bus).
    virtual void connect_homing(const device::HomingPort& port) = 0;

    using Shaper = InputShaper<Axes, host::kDeviceShaperHistoryTicks>;
    /// The tick's setpoints through the shaper; a new coordinate origin resets it first.
    void shape(Lsb (&out)[Axes]) {
        const std::uint32_t applied = device_.status().position_applied;
        if (applied != positions_set_) {
            positions_set_ = applied;
            shaper_->reset(out);
        }
        Lsb shaped[Axes];
        shaper_->shape(out, shaped);
        for (unsigned a = 0; a < Axes; ++a) out[a] = shaped[a];
    }

    device::MotionDevice<Axes, Capacity> device_;
    std::unique_ptr<DeviceIo> io_;
    device::DeviceStatus<Axes> last_status_{};
    std::unique_ptr<Shaper> shaper_;  // 16 KB per axis: only with a shaper
    std::uint32_t shaper_tick_hz_ = 0;
    std::uint32_t positions_set_ = 0;
};

}  // namespace pathstream::linux_device
