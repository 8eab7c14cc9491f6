// `stream` plans on a thread of its own and streams the spans as they come: a long generated
// job reaches the simulated device (Modbus TCP) before planning has finished and executes,
// tick for tick, what plan_path plans for it; a planning error once the device runs brings
// it to a controlled stop and reaches the caller.
#include <atomic>
#include <catch2/catch.hpp>
#include <optional>
#include <thread>
#include <vector>

#include "pathstream/hal/modbus_server.hpp"
#include "pathstream/host/modbus_stream.hpp"
#include "pathstream/host/planning_thread.hpp"
#include "pathstream/linux_device/modbus_motion_device.hpp"
#include "pen_plotter_profile.hpp"
#include "random_walk_source.hpp"
#include "stream_support.hpp"

using namespace pathstream;
using host::test::pen_plotter;
using host::test::RandomWalkSource;

namespace {

// The simulated device serving Modbus TCP on a free port, ticking on its own thread.
struct TcpDevice {
    std::unique_ptr<linux_device::ModbusMotionDevice> device;
    std::optional<hal::ModbusServer> server;
    std::atomic<bool> stop{false};
    std::thread thread;

    TcpDevice(const std::vector<Lsb>& rest, double time_scale)
        : device(linux_device::ModbusMotionDevice::create(rest)) {
        device->record(true);
        server.emplace(hal::ModbusServer::tcp(device->handler(), {"127.0.0.1", 0, 4}));
        thread = std::thread([this, time_scale] {
            linux_device::DeviceLoopOptions o;
            o.time_scale = time_scale;
            linux_device::run_device_loop(
                *device, [&](std::chrono::microseconds w) { server->poll_once(w); }, o, stop);
        });
    }
    std::string target() const {
        return "modbus-tcp://127.0.0.1:" + std::to_string(server->port()) + "?unit=1";
    }
    void join() {
        stop = true;
        if (thread.joinable()) thread.join();
    }
    ~TcpDevice() { join(); }
};

std::vector<host::BezierSegment> collect(host::SegmentSource& source) {
    std::vector<host::BezierSegment> out;
    host::BezierSegment s;
    while (source.next(s)) out.push_back(s);
    source.rewind();
    return out;
}

}  // namespace

// Not [threads]: under ThreadSanitizer the reference plan alone would take minutes; the
// planning thread's sharing is what the [threads] cases here and in test_spsc_ring.cpp run.
TEST_CASE(
    "a long job streams while it is planned: first batch before planning ends, ticks as "
    "plan_path's",
    "[stream][modbus]") {
    const host::MachineProfile machine = pen_plotter();
    RandomWalkSource walk(20000, 11);
    const host::Plan reference = host::plan_path(collect(walk), machine);
    REQUIRE(reference.spans.size() > 4 * host::PlanningThread::kCapacity);

    TcpDevice device(test::start_of(reference), 400.0);
    host::PlanningThread planning(walk, machine, host::PlanOptions{}, {});
    host::StreamOptions o;
    o.target = device.target();
    std::optional<bool> finished_at_first_batch;
    std::size_t traces_before_total = 0;
    o.observer = [&](const host::StreamTrace& t) {
        if (!finished_at_first_batch && t.acknowledged >= t.job)
            finished_at_first_batch = planning.finished();
    };
    const host::StreamReport report = host::stream_modbus(
        planning, machine, o, [&](std::uint64_t, std::optional<std::uint64_t> total, double) {
            if (!total) ++traces_before_total;
        });
    device.join();
    REQUIRE(finished_at_first_batch.has_value());
    CHECK_FALSE(*finished_at_first_batch);
    CHECK(traces_before_total > 0);  // the progress said the length was not known yet
    CHECK(report.spans_sent == reference.spans.size());
    CHECK(report.ticks_executed == reference.total_ticks);
    test::check_recorded(reference, *device.device, 0);
    CHECK(device.device->recorded_setpoints().size() == reference.total_ticks * 2);
}

TEST_CASE("a planning error while the device runs: a controlled stop, then the planning error",
          "[stream][modbus][threads]") {
    const host::MachineProfile machine = pen_plotter();
    RandomWalkSource walk(3000, 5);
    const host::Plan reference = host::plan_path(collect(walk), machine);
    class FailingTap : public host::PlanSink {
    public:
        void span(const host::CoreSpan&) override {
            if (++spans == 6000) throw host::PlanError("span 6000: refused by the test");
        }
        void pen(const host::PenEvent&) override {}
        void pause(const host::PlanPause&) override {}
        std::size_t spans = 0;
    };
    REQUIRE(reference.spans.size() > 6000);
    TcpDevice device(test::start_of(reference), 20.0);
    FailingTap tap;
    host::PlanningThread planning(walk, machine, host::PlanOptions{}, {&tap, {}});
    host::StreamOptions o;
    o.target = device.target();
    bool ran = false;
    bool hold_sent = false;
    o.observer = [&](const host::StreamTrace& t) {
        ran = ran || t.status.state == device::DeviceState::kRunning;  // running
        hold_sent = hold_sent || t.hold_requested;
    };
    CHECK_THROWS_WITH(host::stream_modbus(planning, machine, o), "span 6000: refused by the test");
    CHECK(ran);
    CHECK(hold_sent);
    // Stopped and idle (modbus_rest_position throws otherwise), part of the job executed.
    CHECK_NOTHROW(host::modbus_rest_position(machine, o));
    device.join();
    const std::size_t executed = device.device->recorded_setpoints().size() / 2;
    CHECK(executed > 0);
    CHECK(executed < reference.total_ticks);
}
