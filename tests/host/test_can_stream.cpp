// A planned drawing streamed with the native CAN protocol over the in-process loopback to the
// simulated device running the core: the device executes, tick for tick, the setpoints
// `pathstream plan` computes; with lost frames too; bus-off at the device stops the host.
#include <atomic>
#include <catch2/catch.hpp>
#include <thread>
#include <vector>

#include "pathstream/device/can_protocol.hpp"
#include "pathstream/host/can_stream.hpp"
#include "pathstream/host/core_playback.hpp"
#include "pathstream/host/geometry.hpp"
#include "pathstream/host/json_path.hpp"
#include "pathstream/host/planner.hpp"
#include "pathstream/linux_device/can_motion_device.hpp"
#include "pathstream/machine/device_setup.hpp"
#include "pathstream/machine/machine.hpp"
#include "pathstream/sim/can_loopback.hpp"
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

// The device on loopback endpoint 0, served and ticked on its own thread.
struct DeviceThread {
    std::unique_ptr<linux_device::CanMotionDevice> device;
    std::atomic<bool> stop{false};
    std::thread thread;

    void run(hal::CanBus& bus, double time_scale) {
        thread = std::thread([this, &bus, time_scale] {
            linux_device::DeviceLoopOptions o;
            o.time_scale = time_scale;
            linux_device::run_can_device_loop(*device, bus, o, stop);
        });
    }
    void join() {
        stop = true;
        if (thread.joinable()) thread.join();
    }
    ~DeviceThread() { join(); }
};

void check_executed(const Job& job, const linux_device::CanMotionDevice& device,
                    const host::CanStreamReport& report) {
    const std::size_t axes = job.plan.spans.front().control.size();
    const std::vector<Lsb> expected = plan_setpoints(job.plan, axes);
    const std::vector<Lsb>& got = device.recorded_setpoints();
    REQUIRE(report.ticks_executed == job.plan.total_ticks);
    REQUIRE(got.size() == job.plan.total_ticks * axes);
    for (std::size_t i = 0; i < got.size(); ++i) {
        INFO("tick " << i / axes << " axis " << i % axes);
        REQUIRE(got[i] == expected[i]);
    }
    CHECK(report.last_completed == job.plan.spans.size());
    std::size_t k = 0;
    for (const auto& span : job.plan.spans) {
        for (std::uint32_t t = 0; t < span.ticks; ++t, ++k) {
            REQUIRE((device.recorded_ticks()[k].outputs & kOutputPenDown) ==
                    (span.pen_down ? 1 : 0));
        }
    }
}

struct Run {
    host::CanStreamReport report;
    std::unique_ptr<linux_device::CanMotionDevice> device;
    sim::CanLoopbackCounters bus;
};

Run stream_over_loopback(const Job& job, const sim::CanFaults& faults, double time_scale = 10.0) {
    sim::CanLoopback loop(faults);
    hal::CanBus& device_bus = loop.add_endpoint();
    hal::CanBus& host_bus = loop.add_endpoint();
    DeviceThread dt;
    dt.device = linux_device::CanMotionDevice::create(start_of(job.plan), 5);
    dt.device->record(true);
    dt.run(device_bus, time_scale);
    host::CanStreamOptions o;
    o.node = 5;
    o.ack_timeout_ms = 30;
    Run r;
    r.report = host::stream_can(job.plan, job.machine, host_bus, o);
    dt.join();
    r.device = std::move(dt.device);
    r.bus = loop.counters();
    return r;
}

}  // namespace

TEST_CASE("a drawing streamed natively over CAN executes exactly the planned setpoints",
          "[can][stream][threads]") {
    const Job job = plan_example("wave.json");
    const Run r = stream_over_loopback(job, {});
    check_executed(job, *r.device, r.report);
    CHECK(r.report.spans_sent == job.plan.spans.size());
    CHECK(r.report.retransmissions == 0);
    CHECK(r.device->refused_batches() ==
          0);  // never a span the device refuses (queue full included)
    CHECK(r.device->duplicates() == 0);
    CHECK(r.bus.frames == r.report.frames_sent + r.report.frames_received);
}

TEST_CASE("two drawings in a row natively over CAN, each ending idle at rest, no manual step",
          "[can][stream][threads]") {
    // Each stream marks its last span as the job's end: the device runs to rest there, reports
    // the job finished (status frame D) and idles; the second stream, planned from where the
    // first ended, finds it idle there.
    const Job first = plan_example("wave.json");
    const Job second = plan_example_from("rose.json", end_of(first.plan));
    sim::CanLoopback loop;
    hal::CanBus& device_bus = loop.add_endpoint();
    hal::CanBus& host_bus = loop.add_endpoint();
    DeviceThread dt;
    dt.device = linux_device::CanMotionDevice::create(start_of(first.plan), 5);
    dt.device->record(true);
    dt.run(device_bus, 20.0);
    host::CanStreamOptions o;
    o.node = 5;
    o.ack_timeout_ms = 30;
    const host::CanStreamReport r1 = host::stream_can(first.plan, first.machine, host_bus, o);
    CHECK(r1.ticks_executed == first.plan.total_ticks);
    CHECK(dt.device->state() == device::DeviceState::kIdle);
    for (unsigned a = 0; a < 2; ++a) CHECK(dt.device->position(a) == end_of(first.plan)[a]);
    const host::CanStreamReport r2 = host::stream_can(second.plan, second.machine, host_bus, o);
    CHECK(r2.ticks_executed == second.plan.total_ticks);
    // Sequence numbers run on across jobs, on both buses: the second job's last span is the
    // device's sequence number first + second.
    CHECK(r2.last_completed == first.plan.spans.size() + second.plan.spans.size());
    CHECK(r2.job == first.plan.spans.size() + 1);
    CHECK(dt.device->state() == device::DeviceState::kIdle);
    for (unsigned a = 0; a < 2; ++a) CHECK(dt.device->position(a) == end_of(second.plan)[a]);
    dt.join();
    check_recorded(first.plan, *dt.device, 0);
    check_recorded(second.plan, *dt.device, first.plan.total_ticks);
    CHECK(dt.device->recorded_setpoints().size() ==
          (first.plan.total_ticks + second.plan.total_ticks) * 2);
    CHECK(dt.device->refused_batches() == 0);
}

TEST_CASE(
    "over CAN the host reads where the device rests: a plan elsewhere is refused, a lead-in "
    "from there streams",
    "[can][stream][threads]") {
    const Job job = plan_example("wave.json");
    const std::vector<Lsb> rest = {start_of(job.plan)[0] + 12345, start_of(job.plan)[1] - 6789};
    sim::CanLoopback loop;
    hal::CanBus& device_bus = loop.add_endpoint();
    hal::CanBus& host_bus = loop.add_endpoint();
    DeviceThread dt;
    dt.device = linux_device::CanMotionDevice::create(rest, 5);
    dt.device->record(true);
    dt.run(device_bus, 20.0);
    host::CanStreamOptions o;
    o.node = 5;
    o.ack_timeout_ms = 30;
    CHECK(host::can_rest_position(job.machine, host_bus, o) == rest);
    std::string message;
    try {
        (void)host::stream_can(job.plan, job.machine, host_bus, o);
    } catch (const host::StreamError& e) {
        message = e.what();
    }
    const std::vector<Lsb> start = start_of(job.plan);
    const std::string expected =
        "device rests at " + host::position_text(job.machine, rest.data(), 2) +
        " but the plan starts at " + host::position_text(job.machine, start.data(), 2);
    INFO(message);
    CHECK(message.find(expected) != std::string::npos);
    CHECK(dt.device->recorded_setpoints().empty());  // nothing moved
    const Job led = plan_example_from("wave.json", rest);
    const host::CanStreamReport r = host::stream_can(led.plan, led.machine, host_bus, o);
    CHECK(r.ticks_executed == led.plan.total_ticks);
    dt.join();
    check_recorded(led.plan, *dt.device, 0);
}

TEST_CASE(
    "natively over CAN with 1 % of the frames lost, the device still executes every span once",
    "[can][stream][threads]") {
    const Job job = plan_example("wave.json");
    sim::CanFaults faults;
    faults.drop_fraction = 0.01;
    faults.seed = 42;
    const Run r = stream_over_loopback(job, faults);
    check_executed(job, *r.device,
                   r.report);  // no span lost or repeated: every path tick exactly once
    CHECK(r.bus.dropped > 0);
    CHECK(r.report.retransmissions > 0);
    CHECK(r.device->refused_batches() == 0);
}

TEST_CASE("natively over CAN with a transmit budget per poll, frames wait and nothing is lost",
          "[can][stream][threads]") {
    const Job job = plan_example("wave.json");
    sim::CanFaults faults;
    faults.tx_budget = 4;
    const Run r = stream_over_loopback(job, faults);
    check_executed(job, *r.device, r.report);
    CHECK(r.device->refused_batches() == 0);
}

TEST_CASE("bus-off at the device: the host stops with a clear error and the device holds",
          "[can][stream][threads]") {
    const Job job = plan_example("wave.json");
    sim::CanLoopback loop;
    hal::CanBus& device_bus = loop.add_endpoint();
    hal::CanBus& host_bus = loop.add_endpoint();
    DeviceThread dt;
    dt.device = linux_device::CanMotionDevice::create(start_of(job.plan), 5);
    dt.run(device_bus, 1.0);
    host::CanStreamOptions o;
    o.node = 5;
    o.ack_timeout_ms = 30;
    o.link_timeout_seconds = 0.5;
    o.name = "can://loop?node=5";
    std::atomic<bool> cut{false};
    std::string message;
    try {
        host::stream_can(job.plan, job.machine, host_bus, o, [&](double fraction, double) {
            if (fraction > 0.05 && !cut.exchange(true)) loop.set_bus_off(0, true);
        });
    } catch (const host::StreamError& e) {
        message = e.what();
    }
    REQUIRE(cut.load());
    CHECK_THAT(message, Catch::Contains("can://loop?node=5: no answer from node 5"));
    // The device saw its bus go off and held (a controlled stop), rather than run on blind.
    for (int i = 0; i < 200 && dt.device->state() != device::DeviceState::kHolding; ++i)
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    CHECK(dt.device->state() == device::DeviceState::kHolding);  // holding
    dt.join();
}

TEST_CASE("bus-off at the host: the streamer stops at once", "[can][stream][threads]") {
    const Job job = plan_example("wave.json");
    sim::CanLoopback loop;
    loop.add_endpoint();
    hal::CanBus& host_bus = loop.add_endpoint();
    loop.set_bus_off(1, true);
    host::CanStreamOptions o;
    o.node = 5;
    CHECK_THROWS_WITH(host::stream_can(job.plan, job.machine, host_bus, o),
                      Catch::Contains("bus-off"));
}

TEST_CASE("a silent node: the streamer gives up after the link timeout", "[can][stream][threads]") {
    const Job job = plan_example("wave.json");
    sim::CanLoopback loop;
    loop.add_endpoint();
    hal::CanBus& host_bus = loop.add_endpoint();
    host::CanStreamOptions o;
    o.node = 9;
    o.ack_timeout_ms = 20;
    o.link_timeout_seconds = 0.2;
    CHECK_THROWS_WITH(host::stream_can(job.plan, job.machine, host_bus, o),
                      Catch::Contains("no answer from node 9"));
}

TEST_CASE("can:// targets parse and refuse what is wrong", "[can]") {
    const host::CanTarget t = host::parse_can_target("can://vcan0?node=5&protocol=native");
    CHECK(t.interface_name == "vcan0");
    CHECK(t.node == 5);
    CHECK(t.protocol == "native");
    CHECK(host::parse_can_target("can://can1?protocol=cia402&node=127").protocol == "cia402");
    CHECK_THROWS_WITH(host::parse_can_target("can://vcan0"), Catch::Contains("node=N"));
    CHECK_THROWS_WITH(host::parse_can_target("can://vcan0?node=0"), Catch::Contains("1..127"));
    CHECK_THROWS_WITH(host::parse_can_target("can://vcan0?node=128"), Catch::Contains("1..127"));
    CHECK_THROWS_WITH(host::parse_can_target("can://vcan0?node=5&protocol=x"),
                      Catch::Contains("native or cia402"));
    CHECK_THROWS_WITH(host::parse_can_target("can://?node=5"), Catch::Contains("no CAN interface"));
    CHECK_THROWS_WITH(host::parse_can_target("can://vcan0?node=5&baud=1"),
                      Catch::Contains("unknown parameter"));
}
