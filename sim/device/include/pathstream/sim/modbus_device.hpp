// The simulated Modbus device: the firmware core's MotionDevice and Modbus register map
// behind a libmodbus server (TCP or RTU), ticked on a clock. What `pathstream device` runs and
// what the streaming tests talk to.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "pathstream/hal/modbus_register_handler.hpp"
#include "pathstream/units.hpp"

namespace pathstream::sim {

/// Span queue depth of the simulated Modbus device.
inline constexpr std::uint32_t kModbusDeviceCapacity = 64;

/// One tick the device executed, as recorded.
struct DeviceTick {
    std::uint8_t state = 0;    ///< device::DeviceState after the tick
    std::uint8_t outputs = 0;  ///< discrete outputs (pen) after the tick
};

/// A MotionDevice<axes, kModbusDeviceCapacity> with its register map, type-erased over the
/// axis count. Not thread-safe: one thread serves and ticks it.
class SimulatedModbusDevice {
public:
    /// `start`: the axes' initial position (LSB), its size is the axis count (1..8).
    /// Throws std::invalid_argument for another size.
    static std::unique_ptr<SimulatedModbusDevice> create(const std::vector<Lsb>& start);
    virtual ~SimulatedModbusDevice() = default;

    /// The register map as a transport's handler.
    virtual hal::ModbusRegisterHandler& handler() = 0;
    /// One device tick; when recording and the tick was a path tick (supplied by an accepted
    /// span, not a generated stop or re-entry move) appends its setpoints and outputs.
    virtual void tick() = 0;
    virtual unsigned axes() const = 0;
    /// Tick rate the host configured (0 before configuration).
    virtual std::uint32_t tick_hz() const = 0;
    /// Device state (device::DeviceState as a number).
    virtual std::uint8_t state() const = 0;
    /// Setpoint of the last tick.
    virtual Lsb position(unsigned axis) const = 0;
    /// Raises an external fault (as a drive fault input would).
    virtual void raise_fault() = 0;

    /// Records every path tick from now on: setpoints[k * axes + axis] is path tick k's.
    void record(bool on) { recording_ = on; }
    const std::vector<Lsb>& recorded_setpoints() const { return setpoints_; }
    const std::vector<DeviceTick>& recorded_ticks() const { return ticks_; }
    /// Records every tick from now on, path or not (stop and re-entry moves, rest): what the
    /// axes were actually commanded, for checking the device's own moves against the limits.
    /// every_tick_setpoints()[k * axes + axis] is tick k's (k counted from the call).
    void record_every_tick(bool on) { recording_every_tick_ = on; }
    const std::vector<Lsb>& every_tick_setpoints() const { return every_tick_; }
    std::uint64_t ticks_run() const { return ticks_run_; }

protected:
    bool recording_ = false;
    bool recording_every_tick_ = false;
    std::vector<Lsb> setpoints_;
    std::vector<Lsb> every_tick_;
    std::vector<DeviceTick> ticks_;
    std::uint64_t ticks_run_ = 0;
};

/// How the device loop paces ticks.
struct DeviceLoopOptions {
    /// Device ticks run `time_scale` times faster than real time (1 = real time). The tick
    /// rate is the configured one (unconfigured: 1 kHz).
    double time_scale = 1.0;
    /// Stop after this much wall time (0: until `stop` is set).
    std::chrono::milliseconds run_for{0};
};

/// The pacing shared by every simulated device: calls `tick` whenever a tick falls due on the
/// steady clock (period 1 / (tick_hz() x time_scale), tick_hz() read after every tick, 1 kHz
/// while it is 0), and `serve` with the time left until the next one, until `stop` becomes
/// true or options.run_for passes. Ticks that fall due while `serve` runs are run right after
/// it, so the count never drifts. Returns the ticks run. Throws std::invalid_argument for a
/// time scale <= 0.
std::uint64_t run_paced_loop(const std::function<void()>& tick, const std::function<std::uint32_t()>& tick_hz,
                             const std::function<void(std::chrono::microseconds)>& serve,
                             const DeviceLoopOptions& options, const std::atomic<bool>& stop);

/// Serves `server_poll` (a function polling the Modbus server for up to the given wait) and
/// ticks `device` on the steady clock until `stop` becomes true or run_for passes. Ticks that
/// fall due while a request is served run right after it (the count never drifts).
/// Returns the ticks run.
std::uint64_t run_device_loop(SimulatedModbusDevice& device,
                              const std::function<void(std::chrono::milliseconds)>& server_poll,
                              const DeviceLoopOptions& options, const std::atomic<bool>& stop);

}  // namespace pathstream::sim
