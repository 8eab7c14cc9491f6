// A simulated device's discrete I/O and homing, type-erased over the axis count: the
// DeviceGpio glue (inputs before each tick, outputs after it) and a HomingSequencer fed by the
// homing switch's level after each tick. The simulated Modbus and CAN devices own one when
// `pathstream device --machine` wires them to a profile's GPIO lines (docs/gpio.md).
#pragma once

#include <cstdint>
#include <memory>

#include "pathstream/device/homing.hpp"
#include "pathstream/device/homing_run.hpp"
#include "pathstream/device/motion_device.hpp"
#include "pathstream/device/operator_commands.hpp"
#include "pathstream/linux_device/device_gpio.hpp"

namespace pathstream::linux_device {

/// Which line does what for up to kMaxAxes axes; null = not fitted. The lines are not owned.
struct MachineWiring {
    static constexpr unsigned kMaxAxes = 8;
    hal::DigitalInput* estop = nullptr;
    hal::DigitalInput* limit[kMaxAxes][2] = {};  ///< [axis][LimitSide]
    hal::DigitalOutput* enable = nullptr;
    hal::DigitalOutput* pen = nullptr;
    /// Spindle, spindle direction, mist, flood: by device::kMachineOutputBits index.
    hal::DigitalOutput* machine[device::kMachineOutputCount] = {};
};

/// The I/O of one device. Task context, the thread that ticks the device.
class DeviceIo {
public:
    virtual ~DeviceIo() = default;
    /// Drains the inputs' edges into the device (e-stop, limit faults). Before every tick.
    virtual void before_tick() = 0;
    /// Drives enable, pen, spindle and coolant from the new state; advances homing. After
    /// every tick.
    virtual void after_tick() = 0;

    /// Starts homing `config.axis` against its `side` switch (which must be wired: else
    /// kBadLimits). The switch's fault is masked while homing and armed again when it ends.
    /// The device must be configured and idle (the sequencer's errors otherwise).
    [[nodiscard]] virtual Status start_homing(const device::HomingConfig& config,
                                              device::LimitSide side) = 0;
    /// True from start_homing() until the sequence ends (done or error).
    virtual bool homing_busy() const = 0;
    virtual device::HomingPhase homing_phase() const = 0;
    virtual device::HomingError homing_error() const = 0;
    /// The device's Status behind HomingError::kDeviceRefused.
    virtual Status homing_error_status() const = 0;
    /// Where the slow approach saw the switch, before zero was set (LSB, old coordinates).
    virtual Lsb latch_position() const = 0;
    /// How far the search stop ran past the switch (LSB).
    virtual std::int64_t search_overshoot() const = 0;

    /// The axes a bus's home command may home, in order (init: the profile's gpio.home).
    /// kBadLimits for more axes than the device has, a repeated axis, or an unwired switch.
    [[nodiscard]] virtual Status set_homing_plan(const device::HomingAxis* axes,
                                                 unsigned count) = 0;
    /// Starts a homing run (a bus's home command, through homing_port()): the plan's axes in
    /// `mask` (0: all), one after another; each later one starts when the one before ends
    /// homed. kWrongState unless idle with nothing queued and no homing going on; kNoHoming
    /// for an axis outside the plan; the first axis's start refusal otherwise.
    [[nodiscard]] virtual Status start_homing_run(unsigned mask) = 0;
    /// True while a homing run goes on.
    virtual bool homing_run_busy() const = 0;
    /// The axis the sequencer homes or homed last.
    virtual unsigned homing_axis() const = 0;
    /// Axis `axis`'s homing state, as the bus status reports it.
    virtual device::HomingReport homing_report(unsigned axis) const = 0;
    /// The run as the core's commands reach it (valid while this object lives).
    device::HomingPort homing_port() {
        device::HomingPort p;
        p.context = this;
        p.start = [](void* c, std::uint8_t mask) {
            return static_cast<DeviceIo*>(c)->start_homing_run(mask);
        };
        p.busy = [](const void* c) { return static_cast<const DeviceIo*>(c)->homing_run_busy(); };
        p.report = [](const void* c, unsigned axis) {
            return static_cast<const DeviceIo*>(c)->homing_report(axis);
        };
        return p;
    }

    virtual std::uint32_t estop_edges() const = 0;
    virtual std::uint32_t limit_trips() const = 0;
};

template <unsigned Axes, std::uint32_t Capacity>
class DeviceIoFor final : public DeviceIo {
public:
    /// `device` and the wired lines must outlive this object.
    DeviceIoFor(device::MotionDevice<Axes, Capacity>& device, const MachineWiring& wiring)
        : device_(device), glue_(device, narrow(wiring)), homing_(device), wiring_(wiring) {}

    void before_tick() override { glue_.poll_inputs(); }
    void after_tick() override {
        glue_.update_outputs();
        if (!homing_.busy()) return;
        homing_.poll(glue_.limit_active(homing_axis_, homing_side_));
        if (homing_.busy()) return;
        glue_.mask_limit(homing_axis_, homing_side_, false);
        if (!run_.busy()) return;
        run_.finished(homing_.phase() == device::HomingPhase::kDone ? device::HomingError::kNone
                                                                    : homing_.error());
        (void)start_next_axis();
    }

    Status set_homing_plan(const device::HomingAxis* axes, unsigned count) override {
        for (unsigned i = 0; i < count; ++i) {
            const unsigned a = axes[i].config.axis;
            if (a < Axes && wiring_.limit[a][static_cast<unsigned>(axes[i].side)] == nullptr) {
                return Status::kBadLimits;
            }
        }
        return run_.set_plan(axes, count);
    }

    Status start_homing_run(unsigned mask) override {
        if (homing_.busy() || run_.busy() || device_.state() != device::DeviceState::kIdle ||
            device_.queued_spans() != 0) {
            return Status::kWrongState;
        }
        if (Status s = run_.begin(mask); s != Status::kOk) return s;
        return start_next_axis();
    }
    bool homing_run_busy() const override { return run_.busy(); }
    unsigned homing_axis() const override { return homing_axis_; }
    device::HomingReport homing_report(unsigned axis) const override { return run_.report(axis); }

    // The run's next axis: started, or (refused) recorded as failed, which ends the run.
    Status start_next_axis() {
        const device::HomingAxis* next = run_.next();
        if (next == nullptr) return Status::kOk;
        const Status s = start_homing(next->config, next->side);
        if (s != Status::kOk) {
            run_.finished(homing_.error() != device::HomingError::kNone
                              ? homing_.error()
                              : device::HomingError::kDeviceRefused);
        }
        return s;
    }

    Status start_homing(const device::HomingConfig& config, device::LimitSide side) override {
        if (config.axis >= Axes ||
            wiring_.limit[config.axis][static_cast<unsigned>(side)] == nullptr) {
            return Status::kBadLimits;
        }
        homing_axis_ = config.axis;
        homing_side_ = side;
        const Status s = homing_.start(config);
        glue_.mask_limit(homing_axis_, homing_side_, s == Status::kOk);
        return s;
    }
    bool homing_busy() const override { return homing_.busy(); }
    device::HomingPhase homing_phase() const override { return homing_.phase(); }
    device::HomingError homing_error() const override { return homing_.error(); }
    Status homing_error_status() const override { return homing_.error_status(); }
    Lsb latch_position() const override { return homing_.latch_position(); }
    std::int64_t search_overshoot() const override { return homing_.search_overshoot(); }
    std::uint32_t estop_edges() const override { return glue_.estop_edges(); }
    std::uint32_t limit_trips() const override { return glue_.limit_trips(); }

private:
    static DeviceWiring<Axes> narrow(const MachineWiring& w) {
        DeviceWiring<Axes> d;
        d.estop = w.estop;
        d.enable = w.enable;
        d.pen = w.pen;
        for (unsigned k = 0; k < device::kMachineOutputCount; ++k) d.machine[k] = w.machine[k];
        for (unsigned a = 0; a < Axes; ++a) {
            d.limit[a][0] = w.limit[a][0];
            d.limit[a][1] = w.limit[a][1];
        }
        return d;
    }

    device::MotionDevice<Axes, Capacity>& device_;
    DeviceGpio<Axes, Capacity> glue_;
    device::HomingSequencer<Axes, Capacity> homing_;
    device::HomingRun<Axes> run_;
    MachineWiring wiring_;
    unsigned homing_axis_ = 0;
    device::LimitSide homing_side_ = device::LimitSide::kNegative;
};

}  // namespace pathstream::linux_device
