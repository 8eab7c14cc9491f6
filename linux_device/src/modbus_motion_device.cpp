#include "pathstream/linux_device/modbus_motion_device.hpp"

#include <stdexcept>
#include <string>

#include "pathstream/device/modbus_register_map.hpp"
#include "pathstream/machine/core_span_conversion.hpp"

namespace pathstream::linux_device {
namespace {

// Adapts the core's register map (no virtual functions, its own exception enum) to the
// transport's handler interface; the values of the two enums are the Modbus codes.
template <unsigned Axes>
class MapHandler final : public hal::ModbusRegisterHandler {
public:
    explicit MapHandler(device::ModbusRegisterMap<Axes, kModbusDeviceCapacity>& map) : map_(map) {}

    hal::ModbusException read_input_registers(std::uint16_t address, std::uint16_t count,
                                              std::uint16_t* out) override {
        return convert(map_.read_input_registers(address, count, out));
    }
    hal::ModbusException read_holding_registers(std::uint16_t address, std::uint16_t count,
                                                std::uint16_t* out) override {
        return convert(map_.read_holding_registers(address, count, out));
    }
    hal::ModbusException write_holding_registers(std::uint16_t address, std::uint16_t count,
                                                 const std::uint16_t* values) override {
        return convert(map_.write_holding_registers(address, count, values));
    }
    hal::ModbusException write_read_holding_registers(
        std::uint16_t write_address, std::uint16_t write_count, const std::uint16_t* values,
        std::uint16_t read_address, std::uint16_t read_count, std::uint16_t* out) override {
        return convert(map_.write_read_holding_registers(write_address, write_count, values,
                                                         read_address, read_count, out));
    }

private:
    static hal::ModbusException convert(device::modbus::Exception e) {
        return static_cast<hal::ModbusException>(static_cast<std::uint8_t>(e));
    }
    device::ModbusRegisterMap<Axes, kModbusDeviceCapacity>& map_;
};

template <unsigned Axes>
class Device final : public MotionDeviceBase<Axes, kModbusDeviceCapacity, ModbusMotionDevice> {
public:
    explicit Device(const Lsb (&start)[Axes])
        : MotionDeviceBase<Axes, kModbusDeviceCapacity, ModbusMotionDevice>(start),
          map_(this->device_),
          handler_(map_) {}

    hal::ModbusRegisterHandler& handler() override { return handler_; }

    // The task's share of every loop turn comes first: a jog in progress is fed.
    void connect_homing(const device::HomingPort& port) override {
        map_.operator_commands().set_homing(port);
    }

    void tick() override {
        map_.service();
        MotionDeviceBase<Axes, kModbusDeviceCapacity, ModbusMotionDevice>::tick();
    }

private:
    device::ModbusRegisterMap<Axes, kModbusDeviceCapacity> map_;
    MapHandler<Axes> handler_;
};

}  // namespace

std::unique_ptr<ModbusMotionDevice> ModbusMotionDevice::create(const std::vector<Lsb>& start) {
    return host::with_axes(start.size(), [&](auto axes) -> std::unique_ptr<ModbusMotionDevice> {
        constexpr unsigned A = decltype(axes)::value;
        Lsb s[A];
        for (unsigned a = 0; a < A; ++a) s[a] = start[a];
        return std::make_unique<Device<A>>(s);
    });
}

std::uint64_t run_device_loop(ModbusMotionDevice& device,
                              const std::function<void(std::chrono::microseconds)>& server_poll,
                              const DeviceLoopOptions& options, const std::atomic<bool>& stop) {
    return run_paced_loop([&] { device.tick(); }, [&] { return device.tick_hz(); }, server_poll,
                          options, stop);
}

}  // namespace pathstream::linux_device
