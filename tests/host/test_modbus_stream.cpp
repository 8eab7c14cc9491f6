// A planned drawing streamed over Modbus TCP and RTU (a pty) to the simulated device running
// the core: the device executes, tick for tick, the setpoints `pathstream plan` computes.
#include <atomic>
#include <catch2/catch.hpp>
#include <thread>
#include <vector>

#include "pathstream/hal/modbus_server.hpp"
#include "pathstream/host/core_playback.hpp"
#include "pathstream/host/geometry.hpp"
#include "pathstream/host/json_path.hpp"
#include "pathstream/host/modbus_stream.hpp"
#include "pathstream/host/planner.hpp"
#include "pathstream/linux_device/modbus_motion_device.hpp"
#include "pathstream/machine/machine.hpp"
#include "pathstream/span.hpp"
#include "stream_support.hpp"

using namespace pathstream;
using test::check_recorded;
using test::end_of;
using test::Job;
using test::plan_example;
using test::plan_example_from;
using test::plan_setpoints;
using test::start_of;

namespace {

// Runs the device loop on its own thread until stopped.
struct DeviceThread {
    std::unique_ptr<linux_device::ModbusMotionDevice> device;
    std::atomic<bool> stop{false};
    std::thread thread;

    void run(hal::ModbusServer& server, double time_scale) {
        thread = std::thread([this, &server, time_scale] {
            linux_device::DeviceLoopOptions o;
            o.time_scale = time_scale;
            linux_device::run_device_loop(
                *device, [&](std::chrono::microseconds w) { server.poll_once(w); }, o, stop);
        });
    }
    ~DeviceThread() {
        stop = true;
        if (thread.joinable()) thread.join();
    }
};

void check_executed(const Job& job, const linux_device::ModbusMotionDevice& device,
                    const host::StreamReport& report) {
    const std::size_t axes = job.plan.spans.front().control.size();
    const std::vector<Lsb> expected = plan_setpoints(job.plan, axes);
    const std::vector<Lsb>& got = device.recorded_setpoints();
    REQUIRE(report.ticks_executed == job.plan.total_ticks);
    REQUIRE(got.size() == job.plan.total_ticks * axes);
    for (std::size_t i = 0; i < got.size(); ++i) {
        INFO("tick " << i / axes << " axis " << i % axes);
        REQUIRE(got[i] == expected[i]);
    }
    for (std::size_t a = 0; a < axes; ++a)
        CHECK(report.final_position[a] == expected[expected.size() - axes + a]);
    CHECK(report.last_completed == job.plan.spans.size());
    // Pen output per path tick equals the plan's pen-down spans.
    std::size_t k = 0;
    for (const auto& span : job.plan.spans) {
        for (std::uint32_t t = 0; t < span.ticks; ++t, ++k) {
            REQUIRE((device.recorded_ticks()[k].outputs & kOutputPenDown) ==
                    (span.pen_down ? 1 : 0));
        }
    }
}

}  // namespace

TEST_CASE("a drawing streamed over Modbus TCP executes exactly the planned setpoints",
          "[modbus][stream][threads]") {
    const Job job = plan_example("wave.json");
    DeviceThread dt;
    dt.device = linux_device::ModbusMotionDevice::create(start_of(job.plan));
    dt.device->record(true);
    hal::ModbusServer server = hal::ModbusServer::tcp(dt.device->handler(), {"127.0.0.1", 0, 4});
    dt.run(server, 10.0);
    host::StreamOptions o;
    o.target = "modbus-tcp://127.0.0.1:" + std::to_string(server.port()) + "?unit=1";
    const host::StreamReport report = host::stream_modbus(job.plan, job.machine, o);
    dt.stop = true;
    dt.thread.join();
    check_executed(job, *dt.device, report);
    CHECK(report.spans_sent == job.plan.spans.size());
    CHECK(report.bytes_sent > 0);
}

TEST_CASE("a drawing streamed over Modbus RTU on a pty executes exactly the planned setpoints",
          "[modbus][stream][threads]") {
    const Job job = plan_example("wave.json");
    DeviceThread dt;
    dt.device = linux_device::ModbusMotionDevice::create(start_of(job.plan));
    dt.device->record(true);
    hal::ModbusServer server = hal::ModbusServer::rtu_pty(dt.device->handler());
    dt.run(server, 10.0);
    host::StreamOptions o;
    o.target = "modbus-rtu://" + server.client_device() + "?baud=115200&parity=N&unit=1";
    const host::StreamReport report = host::stream_modbus(job.plan, job.machine, o);
    dt.stop = true;
    dt.thread.join();
    check_executed(job, *dt.device, report);
}

TEST_CASE(
    "stream with a lead-in: a device resting elsewhere (after homing) gets a pen-up move to the "
    "drawing first",
    "[modbus][stream][threads]") {
    const Job drawing = plan_example("rose.json");
    const Lsb rest[2] = {5000, -7000};  // where homing left the machine, not the drawing's start
    DeviceThread dt;
    dt.device = linux_device::ModbusMotionDevice::create({rest[0], rest[1]});
    dt.device->record(true);
    hal::ModbusServer server = hal::ModbusServer::tcp(dt.device->handler(), {"127.0.0.1", 0, 4});
    dt.run(server, 20.0);
    host::StreamOptions o;
    o.target = "modbus-tcp://127.0.0.1:" + std::to_string(server.port()) + "?unit=1";
    // Without the lead-in the streamer refuses, naming both points.
    CHECK_THROWS_WITH(
        host::stream_modbus(drawing.plan, drawing.machine, o),
        Catch::Contains(
            "device rests at x 5.0000 y -7.0000 mm (5000 -7000 LSB) but the plan starts at "
            "x 139.3220 y 100.0000 mm (139322 100000 LSB)"));
    const std::vector<Lsb> at = host::modbus_rest_position(drawing.machine, o);
    REQUIRE(at == std::vector<Lsb>{5000, -7000});
    const host::Path path =
        host::load_json_path(std::string(PATHSTREAM_SOURCE_DIR) + "/examples/rose.json");
    std::vector<host::BezierSegment> segments = host::to_bezier_segments(path);
    host::prepend_lead_in(segments,
                          {at[0] * drawing.machine.mm_per_lsb, at[1] * drawing.machine.mm_per_lsb});
    Job job{drawing.machine, host::plan_path(segments, drawing.machine)};
    REQUIRE(start_of(job.plan) == std::vector<Lsb>{5000, -7000});
    REQUIRE(job.plan.total_ticks > drawing.plan.total_ticks);
    const host::StreamReport report = host::stream_modbus(job.plan, job.machine, o);
    dt.stop = true;
    dt.thread.join();
    check_executed(job, *dt.device, report);
    // Pen up until the drawing's first point, which the move reaches exactly.
    const std::vector<Lsb>& got = dt.device->recorded_setpoints();
    std::size_t first_down = 0;
    while ((dt.device->recorded_ticks()[first_down].outputs & kOutputPenDown) == 0) ++first_down;
    CHECK(got[2 * first_down] == 139322);
    CHECK(got[2 * first_down + 1] == 100000);
}

// Two drawings in a row to one device, with no manual step between them: each stream marks
// its last span as the job's end, the device runs to rest there, reports the job finished and
// idles; the second stream finds it idle where the first ended and (with the lead-in) starts
// there. The recorded ticks are compared once the device thread has stopped.
static void two_drawings_in_a_row(DeviceThread& dt, const std::string& target,
                                  const char* second_name) {
    const Job first = plan_example("wave.json");
    host::StreamOptions o;
    o.target = target;
    const host::StreamReport r1 = host::stream_modbus(first.plan, first.machine, o);
    CHECK(r1.ticks_executed == first.plan.total_ticks);
    const std::vector<Lsb> rest =
        host::modbus_rest_position(first.machine, o);  // throws unless idle
    CHECK(rest == end_of(first.plan));
    const Job second = plan_example_from(second_name, rest);
    const host::StreamReport r2 = host::stream_modbus(second.plan, second.machine, o);
    CHECK(r2.ticks_executed == second.plan.total_ticks);
    CHECK(r2.last_completed == first.plan.spans.size() + second.plan.spans.size());
    CHECK(host::modbus_rest_position(second.machine, o) == end_of(second.plan));
    CHECK(dt.device->state() == device::DeviceState::kIdle);  // idle
    dt.stop = true;
    dt.thread.join();
    check_recorded(first.plan, *dt.device, 0);
    check_recorded(second.plan, *dt.device, first.plan.total_ticks);
    CHECK(dt.device->recorded_setpoints().size() ==
          (first.plan.total_ticks + second.plan.total_ticks) * 2);
}

TEST_CASE("two drawings in a row over Modbus TCP, each ending idle at rest, no manual step",
          "[modbus][stream][threads]") {
    DeviceThread dt;
    dt.device = linux_device::ModbusMotionDevice::create(start_of(plan_example("wave.json").plan));
    dt.device->record(true);
    hal::ModbusServer server = hal::ModbusServer::tcp(dt.device->handler(), {"127.0.0.1", 0, 4});
    dt.run(server, 20.0);
    two_drawings_in_a_row(dt, "modbus-tcp://127.0.0.1:" + std::to_string(server.port()) + "?unit=1",
                          "rose.json");
}

TEST_CASE("two drawings in a row over Modbus RTU, each ending idle at rest, no manual step",
          "[modbus][stream][threads]") {
    DeviceThread dt;
    dt.device = linux_device::ModbusMotionDevice::create(start_of(plan_example("wave.json").plan));
    dt.device->record(true);
    hal::ModbusServer server = hal::ModbusServer::rtu_pty(dt.device->handler());
    dt.run(server, 20.0);
    two_drawings_in_a_row(
        dt, "modbus-rtu://" + server.client_device() + "?baud=115200&parity=N&unit=1", "wave.json");
}
