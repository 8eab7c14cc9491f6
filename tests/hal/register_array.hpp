// Test support: a ModbusRegisterHandler over plain arrays, with validation to provoke every
// exception path, and a thread that serves a ModbusServer until told to stop.
#pragma once

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <thread>

#include "pathstream/hal/modbus_register_handler.hpp"
#include "pathstream/hal/modbus_server.hpp"

namespace pathstream::test {

using hal::ModbusException;

/// 1000 holding registers (0..999; 900..999 read-only), input register a = 3a + 1 for
/// a < 1000. Writing the value 0xDEAD anywhere is refused as an illegal value. Writes are all
/// or nothing, as the interface demands.
class RegisterArray : public hal::ModbusRegisterHandler {
public:
    static constexpr std::uint32_t kSize = 1000;
    static constexpr std::uint32_t kReadOnlyFrom = 900;
    static constexpr std::uint16_t kRefusedValue = 0xDEAD;

    ModbusException read_input_registers(std::uint16_t address, std::uint16_t count,
                                         std::uint16_t* out) override {
        if (address + count > kSize) return ModbusException::kIllegalDataAddress;
        for (std::uint16_t i = 0; i < count; ++i)
            out[i] = static_cast<std::uint16_t>(3 * (address + i) + 1);
        return ModbusException::kNone;
    }
    ModbusException read_holding_registers(std::uint16_t address, std::uint16_t count,
                                           std::uint16_t* out) override {
        if (address + count > kSize) return ModbusException::kIllegalDataAddress;
        for (std::uint16_t i = 0; i < count; ++i) out[i] = holding[address + i];
        return ModbusException::kNone;
    }
    ModbusException write_holding_registers(std::uint16_t address, std::uint16_t count,
                                            const std::uint16_t* values) override {
        if (address + count > kReadOnlyFrom) return ModbusException::kIllegalDataAddress;
        for (std::uint16_t i = 0; i < count; ++i) {
            if (values[i] == kRefusedValue) return ModbusException::kIllegalDataValue;
        }
        for (std::uint16_t i = 0; i < count; ++i) holding[address + i] = values[i];
        ++writes_applied;
        return ModbusException::kNone;
    }

    std::array<std::uint16_t, kSize> holding{};
    int writes_applied = 0;
};

/// Calls server.poll_once in a thread until destroyed or stop()ped. The server and its
/// handler belong to that thread meanwhile: read the handler only after stop().
class ServingThread {
public:
    explicit ServingThread(hal::ModbusServer& server)
        : thread_([this, &server] {
              while (!stop_.load()) server.poll_once(std::chrono::milliseconds(10));
          }) {}
    ~ServingThread() { stop(); }
    ServingThread(const ServingThread&) = delete;
    ServingThread& operator=(const ServingThread&) = delete;

    void stop() {
        stop_.store(true);
        if (thread_.joinable()) thread_.join();
    }

private:
    std::atomic<bool> stop_{false};
    std::thread thread_;
};

/// Waits (bounded) until `done()` holds; for effects without a reply (broadcasts).
template <class Predicate>
bool eventually(Predicate done, std::chrono::milliseconds limit = std::chrono::seconds(5)) {
    const auto end = std::chrono::steady_clock::now() + limit;
    while (!done()) {
        if (std::chrono::steady_clock::now() > end) return false;
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    return true;
}

}  // namespace pathstream::test
