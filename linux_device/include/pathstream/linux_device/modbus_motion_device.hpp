// The Modbus device: the firmware core's MotionDevice and Modbus register map behind a libmodbus
// server (TCP or RTU), ticked on the steady clock. What `pathstream device` runs and what the
// streaming tests talk to.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "pathstream/hal/modbus_register_handler.hpp"
#include "pathstream/linux_device/any_motion_device.hpp"
#include "pathstream/linux_device/paced_loop.hpp"
#include "pathstream/units.hpp"

namespace pathstream::linux_device {

/// Span queue depth of the Modbus device.
inline constexpr std::uint32_t kModbusDeviceCapacity = 64;

/// A MotionDevice<axes, kModbusDeviceCapacity> with its register map, type-erased over the
/// axis count. Not thread-safe: one thread serves and ticks it.
class ModbusMotionDevice : public AnyMotionDevice {
public:
    /// `start`: the axes' initial position (LSB), its size is the axis count (1..8).
    /// Throws std::invalid_argument for another size.
    static std::unique_ptr<ModbusMotionDevice> create(const std::vector<Lsb>& start);

    /// The register map as a transport's handler.
    virtual hal::ModbusRegisterHandler& handler() = 0;
};

/// Serves `server_poll` (a function polling the Modbus server for up to the given wait, to the
/// microsecond: an idle device sleeps until its next tick) and
/// ticks `device` on the steady clock until `stop` becomes true or run_for passes. Ticks that
/// fall due while a request is served run right after it (the count never drifts).
/// Returns the ticks run.
std::uint64_t run_device_loop(ModbusMotionDevice& device,
                              const std::function<void(std::chrono::microseconds)>& server_poll,
                              const DeviceLoopOptions& options, const std::atomic<bool>& stop);

}  // namespace pathstream::linux_device
