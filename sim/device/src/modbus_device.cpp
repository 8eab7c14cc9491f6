#include <algorithm>
#include "pathstream/sim/modbus_device.hpp"

#include <stdexcept>
#include <string>
#include <thread>

#include "pathstream/device/modbus_register_map.hpp"
#include "pathstream/machine/core_span_conversion.hpp"

namespace pathstream::sim {
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
    hal::ModbusException write_read_holding_registers(std::uint16_t write_address, std::uint16_t write_count,
                                                      const std::uint16_t* values, std::uint16_t read_address,
                                                      std::uint16_t read_count, std::uint16_t* out) override {
        return convert(
            map_.write_read_holding_registers(write_address, write_count, values, read_address, read_count, out));
    }

private:
    static hal::ModbusException convert(device::modbus::Exception e) {
        return static_cast<hal::ModbusException>(static_cast<std::uint8_t>(e));
    }
    device::ModbusRegisterMap<Axes, kModbusDeviceCapacity>& map_;
};

template <unsigned Axes>
class Device final : public MotionDeviceBase<Axes, kModbusDeviceCapacity, SimulatedModbusDevice> {
public:
    explicit Device(const Lsb (&start)[Axes])
        : MotionDeviceBase<Axes, kModbusDeviceCapacity, SimulatedModbusDevice>(start), map_(this->device_), handler_(map_) {}

    hal::ModbusRegisterHandler& handler() override { return handler_; }

    // The task's share of every loop turn comes first: a jog in progress is fed.
    void connect_homing(const device::HomingPort& port) override { map_.operator_commands().set_homing(port); }

    void tick() override {
        map_.service();
        MotionDeviceBase<Axes, kModbusDeviceCapacity, SimulatedModbusDevice>::tick();
    }

private:
    device::ModbusRegisterMap<Axes, kModbusDeviceCapacity> map_;
    MapHandler<Axes> handler_;
};

}  // namespace

std::unique_ptr<SimulatedModbusDevice> SimulatedModbusDevice::create(const std::vector<Lsb>& start) {
    return host::with_axes(start.size(), [&](auto axes) -> std::unique_ptr<SimulatedModbusDevice> {
        constexpr unsigned A = decltype(axes)::value;
        Lsb s[A];
        for (unsigned a = 0; a < A; ++a) s[a] = start[a];
        return std::make_unique<Device<A>>(s);
    });
}

std::uint64_t run_paced_loop(const std::function<void()>& tick, const std::function<std::uint32_t()>& tick_hz,
                             const std::function<void(std::chrono::microseconds)>& serve,
                             const DeviceLoopOptions& options, const std::atomic<bool>& stop) {
    using clock = std::chrono::steady_clock;
    if (!(options.time_scale > 0)) throw std::invalid_argument("time scale must be positive");
    const auto begin = clock::now();
    std::uint64_t ticks = 0;
    double due_seconds = 0;  // tick k is due at begin + the sum of the tick periods before it
    while (!stop.load(std::memory_order_relaxed)) {
        const auto now = clock::now();
        if (options.run_for.count() > 0 && now - begin >= options.run_for) break;
        const double elapsed = std::chrono::duration<double>(now - begin).count();
        while (due_seconds <= elapsed) {
            tick();
            ++ticks;
            const std::uint32_t hz = tick_hz() != 0 ? tick_hz() : 1000;
            const double period = 1.0 / (hz * options.time_scale);
            due_seconds += period;
            // At rest, faster than rest_tick_hz: the next tick a rest period of wall time from
            // now, the idle ticks in between dropped (nothing happens in them to make up).
            if (options.at_rest && 1.0 / period > options.rest_tick_hz && options.at_rest()) {
                due_seconds = std::max(due_seconds, elapsed + 1.0 / options.rest_tick_hz);
                break;
            }
        }
        const double wait = due_seconds - elapsed;
        serve(std::chrono::microseconds(wait > 0 ? static_cast<long>(wait * 1e6) : 0));
    }
    return ticks;
}

std::uint64_t run_device_loop(SimulatedModbusDevice& device,
                              const std::function<void(std::chrono::microseconds)>& server_poll,
                              const DeviceLoopOptions& options, const std::atomic<bool>& stop) {
    return run_paced_loop([&] { device.tick(); }, [&] { return device.tick_hz(); },
                          server_poll,
                          options, stop);
}

}  // namespace pathstream::sim
