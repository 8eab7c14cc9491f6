// A shaped stream to the simulated Modbus device: the host streams a plan as ever, the device
// plays it exactly and sends every tick through its input shaper; the axes' commands are the
// exact weighted sums of the device's own, within its limits, and end where the plan ends.
#include <atomic>
#include <catch2/catch.hpp>
#include <chrono>
#include <cstdint>
#include <string>
#include <thread>
#include <vector>

#include "pathstream/hal/modbus_server.hpp"
#include "pathstream/host/modbus_stream.hpp"
#include "pathstream/linux_device/modbus_motion_device.hpp"
#include "pathstream/linux_device/paced_loop.hpp"
#include "pathstream/machine/device_setup.hpp"
#include "pathstream/machine/shaper_design.hpp"
#include "stream_support.hpp"

using namespace pathstream;
using namespace pathstream::test;

namespace {

std::int64_t floor_div(std::int64_t a, std::int64_t b) {
    const std::int64_t q = a / b;
    return (a % b != 0 && (a < 0) != (b < 0)) ? q - 1 : q;
}

/// Largest |k-th difference| of one axis of an interleaved record.
std::int64_t peak(const std::vector<Lsb>& x, std::size_t axes, std::size_t axis, int order) {
    std::vector<std::int64_t> d;
    for (std::size_t k = axis; k < x.size(); k += axes) d.push_back(x[k]);
    for (int o = 0; o < order; ++o) {
        for (std::size_t i = 0; i + 1 < d.size(); ++i) d[i] = d[i + 1] - d[i];
        d.pop_back();
    }
    std::int64_t m = 0;
    for (std::int64_t v : d) m = std::max(m, v < 0 ? -v : v);
    return m;
}

}  // namespace

TEST_CASE("a shaped stream: the device shapes every tick exactly and within its limits",
          "[modbus][shaper][threads]") {
    const Job job = plan_example("wave.json");
    const auto device = linux_device::ModbusMotionDevice::create(start_of(job.plan));
    const std::uint32_t hz = static_cast<std::uint32_t>(job.machine.tick_hz);
    const std::vector<ShaperTap> taps[2] = {
        host::design_shaper_taps({host::ShaperType::kMzv, 40, 0.05}, hz,
                                 host::kDeviceShaperHistoryTicks),
        host::design_shaper_taps({host::ShaperType::kEi, 33, 0.1}, hz,
                                 host::kDeviceShaperHistoryTicks)};
    for (unsigned a = 0; a < 2; ++a)
        REQUIRE(device->configure_shaper(a, taps[a], hz) == Status::kOk);
    // Taps for another tick rate, or for an axis the device has not, are refused.
    CHECK(device->configure_shaper(0, taps[0], hz * 2) == Status::kBadShaper);
    CHECK(device->configure_shaper(2, taps[0], hz) == Status::kBadShaper);
    device->record(true);
    device->record_every_tick(true);
    hal::ModbusServer server = hal::ModbusServer::tcp(device->handler(), {"127.0.0.1", 0, 4});
    std::atomic<bool> stop{false}, settled{false};
    std::thread loop([&] {
        linux_device::DeviceLoopOptions lo;
        lo.time_scale = 10.0;
        linux_device::run_device_loop(
            *device,
            [&](std::chrono::microseconds w) {
                server.poll_once(w);
                // In the device's thread: the job is over and the shaped output has rested
                // for 50 ticks (a moving shaper output counts as a change).
                if (device->finished_job() != 0 && device->unchanged_ticks() >= 50) settled = true;
            },
            lo, stop);
    });
    host::StreamOptions o;
    o.target = "modbus-tcp://127.0.0.1:" + std::to_string(server.port()) + "?unit=1";
    const host::StreamReport report = host::stream_modbus(job.plan, job.machine, o);
    // The shaped output settles after the job (no wall time is assumed: a bounded wait).
    for (int i = 0; i < 60000 && !settled; ++i)
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    REQUIRE(settled);
    stop = true;
    loop.join();
    // The path ticks are the plan's, unshaped (an underrun under load only adds stop and
    // re-entry ticks, which the shaper takes like any other).
    check_recorded(job.plan, *device, 0);
    (void)report;

    const std::vector<Lsb>& command = device->every_tick_commands();
    const std::vector<Lsb>& shaped = device->every_tick_setpoints();
    REQUIRE(command.size() == shaped.size());
    const std::size_t ticks = command.size() / 2;
    REQUIRE(ticks > job.plan.total_ticks);
    const std::vector<Lsb> start = start_of(job.plan), end = end_of(job.plan);
    for (std::size_t a = 0; a < 2; ++a) {
        // Every shaped tick is the exact weighted sum of the commands, rounded once (the
        // device was at rest at the start before the record began).
        for (std::size_t k = 0; k < ticks; ++k) {
            std::int64_t sum = 0;
            for (const ShaperTap& t : taps[a]) {
                const std::int64_t u = k >= t.delay ? command[(k - t.delay) * 2 + a] : start[a];
                sum += static_cast<std::int64_t>(t.weight) * u;
            }
            INFO("tick " << k << " axis " << a);
            REQUIRE(shaped[k * 2 + a] ==
                    floor_div(2 * sum + kShaperWeightOne, 2 * std::int64_t{kShaperWeightOne}));
        }
        CHECK(peak(shaped, 2, a, 1) <= peak(command, 2, a, 1));
        CHECK(peak(shaped, 2, a, 2) <= peak(command, 2, a, 2) + 1);
        CHECK(shaped[(ticks - 1) * 2 + a] == end[a]);
        // The shaping did something: the output lagged the command somewhere.
        std::int64_t lag = 0;
        for (std::size_t k = 0; k < ticks; ++k)
            lag = std::max<std::int64_t>(lag, std::abs(shaped[k * 2 + a] - command[k * 2 + a]));
        CHECK(lag > 0);
    }
}
