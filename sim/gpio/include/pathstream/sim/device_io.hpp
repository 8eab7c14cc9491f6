// A simulated device's discrete I/O and homing, type-erased over the axis count: the
// DeviceGpio glue (inputs before each tick, outputs after it) and a HomingSequencer fed by the
// homing switch's level after each tick. The simulated Modbus and CAN devices own one when
// `pathstream device --machine` wires them to a profile's GPIO lines (docs/gpio.md).
#pragma once

#include <cstdint>
#include <memory>

#include "pathstream/device/homing.hpp"
#include "pathstream/device/motion_device.hpp"
#include "pathstream/sim/device_gpio.hpp"

namespace pathstream::sim {

/// Which line does what for up to kMaxAxes axes; null = not fitted. The lines are not owned.
struct MachineWiring {
    static constexpr unsigned kMaxAxes = 8;
    hal::DigitalInput* estop = nullptr;
    hal::DigitalInput* limit[kMaxAxes][2] = {};  ///< [axis][LimitSide]
    hal::DigitalOutput* enable = nullptr;
    hal::DigitalOutput* pen = nullptr;
};

/// The I/O of one device. Task context, the thread that ticks the device.
class DeviceIo {
public:
    virtual ~DeviceIo() = default;
    /// Drains the inputs' edges into the device (e-stop, limit faults). Before every tick.
    virtual void before_tick() = 0;
    /// Drives enable and pen from the new state; advances homing. After every tick.
    virtual void after_tick() = 0;

    /// Starts homing `config.axis` against its `side` switch (which must be wired: else
    /// kBadLimits). The switch's fault is masked while homing and armed again when it ends.
    /// The device must be configured and idle (the sequencer's errors otherwise).
    [[nodiscard]] virtual Status start_homing(const device::HomingConfig& config, device::LimitSide side) = 0;
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

    virtual std::uint32_t estop_edges() const = 0;
    virtual std::uint32_t limit_trips() const = 0;
};

template <unsigned Axes, std::uint32_t Capacity>
class DeviceIoFor final : public DeviceIo {
public:
    /// `device` and the wired lines must outlive this object.
    DeviceIoFor(device::MotionDevice<Axes, Capacity>& device, const MachineWiring& wiring)
        : glue_(device, narrow(wiring)), homing_(device), wiring_(wiring) {}

    void before_tick() override { glue_.poll_inputs(); }
    void after_tick() override {
        glue_.update_outputs();
        if (!homing_.busy()) return;
        homing_.poll(glue_.limit_active(homing_axis_, homing_side_));
        if (!homing_.busy()) glue_.mask_limit(homing_axis_, homing_side_, false);
    }

    Status start_homing(const device::HomingConfig& config, device::LimitSide side) override {
        if (config.axis >= Axes || wiring_.limit[config.axis][static_cast<unsigned>(side)] == nullptr) {
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
        for (unsigned a = 0; a < Axes; ++a) {
            d.limit[a][0] = w.limit[a][0];
            d.limit[a][1] = w.limit[a][1];
        }
        return d;
    }

    DeviceGpio<Axes, Capacity> glue_;
    device::HomingSequencer<Axes, Capacity> homing_;
    MachineWiring wiring_;
    unsigned homing_axis_ = 0;
    device::LimitSide homing_side_ = device::LimitSide::kNegative;
};

}  // namespace pathstream::sim
