// The Modbus transport to one device: connect, status block, command register.
#include "modbus_link.hpp"

#include <algorithm>
#include <cerrno>
#include <span>

#include "pathstream/device/modbus_map.hpp"

namespace pathstream::host {
namespace {

namespace mb = device::modbus;
namespace st = device::modbus::status;
using Clock = ModbusLink::Clock;

std::uint32_t u32(const std::uint16_t* r) {
    return (static_cast<std::uint32_t>(r[0]) << 16) | r[1];
}

hal::ModbusClientOptions client_options(const StreamOptions& o) {
    hal::ModbusClientOptions c;
    c.response_timeout = std::chrono::milliseconds(o.response_timeout_ms);
    // A response that lost a byte would otherwise wait libmodbus's 500 ms byte timeout for
    // it, whatever the response timeout: one gap of that size is already a lost frame.
    c.byte_timeout = c.response_timeout;
    c.attempts = static_cast<int>(std::max(1u, o.attempts));
    return c;
}

// The first connection, tried until link_timeout_seconds have passed; then a StreamError like
// every other dead link, not the transport's error. A refused TCP connection ends it at once:
// the host answered that nothing listens on that port, and waiting would not change that
// (a device still starting binds its port before it prints its address).
hal::ModbusClient connect(const StreamOptions& o) {
    const auto begin = Clock::now();
    while (true) {
        try {
            return hal::ModbusClient(o.target, client_options(o));
        } catch (const hal::ModbusError& e) {
            if (e.os_error() == ECONNREFUSED) {
                throw StreamError(
                    o.target +
                    ": cannot connect to the device: nothing listens there (connection "
                    "refused); is the device running, and is this its port?");
            }
            if (std::chrono::duration<double>(Clock::now() - begin).count() >
                o.link_timeout_seconds) {
                throw StreamError(o.target + ": cannot connect to the device (" + e.what() + ")");
            }
            std::this_thread::sleep_for(std::chrono::milliseconds(50));
        }
    }
}

}  // namespace

ModbusLink::ModbusLink(const StreamOptions& options)
    : options_(options), client_(connect(options)) {}

DeviceSnapshot parse_modbus_status(const std::uint16_t* r, std::size_t count) {
    DeviceSnapshot s;
    s.magic = r[st::kMagic];
    s.version = r[st::kVersion];
    s.state = device_state_of_wire(r[st::kState]);
    s.fault_code = r[st::kFaultCode];
    s.free_slots = r[st::kFreeSlots];
    s.capacity = r[st::kCapacity];
    s.last_accepted = u32(&r[st::kLastAcceptedSequence]);
    s.ticks_executed = u32(&r[st::kTicksExecuted]);
    for (unsigned a = 0; a < kMaxAxes; ++a)
        s.position[a] = static_cast<std::int32_t>(u32(&r[st::kPositions + 2 * a]));
    s.axes = r[st::kAxes];
    s.underruns = r[st::kUnderruns];
    s.last_completed = u32(&r[st::kLastCompletedSequence]);
    s.last_refusal = r[st::kLastRefusal];
    s.duplicates = r[st::kDuplicates];
    s.outputs = r[st::kOutputs];
    s.queued = r[st::kQueuedSpans];
    s.flags = r[st::kFlags];
    s.finished_job = u32(&r[st::kFinishedJob]);
    s.finished_job_ticks = u32(&r[st::kFinishedJobTicks]);
    s.epoch = u32(&r[st::kEpoch]);
    for (unsigned a = 0; a < kMaxAxes && st::kHoming + a < count; ++a) {
        s.homing[a].state = static_cast<device::AxisHoming>(r[st::kHoming + a] & 0xFFu);
        s.homing[a].error = static_cast<device::HomingError>(r[st::kHoming + a] >> 8);
    }
    return s;
}

DeviceSnapshot ModbusLink::read_status(std::uint16_t count) {
    std::uint16_t r[st::kCount] = {};
    count = std::min(count, st::kCount);
    transact([&] { client_.read_input_registers(0, std::span<std::uint16_t>(r, count)); });
    ++status_reads_;
    return parse_modbus_status(r, count);
}

void ModbusLink::write_command(device::Command c) {
    transact([&] { client_.write_register(mb::kCommand, static_cast<std::uint16_t>(c)); });
}

}  // namespace pathstream::host
