// bench_can: bus load of the native CAN protocol streaming a real plan (examples/wave.json on
// the pen plotter, its two axes repeated to 1, 2, 4 and 8 axes) to the simulated device at a
// 1 kHz tick in real time over the in-process loopback, from the frames actually sent (both
// directions) with worst-case bit stuffing, as % of 1 Mbit/s; against CiA 402 cyclic
// synchronous position computed analytically (SYNC + one 6-byte RPDO and one 6-byte TPDO per
// axis per cycle) for 1 ms and 2 ms cycles.
//   bench_can [--quick] [--markdown]
#include <atomic>
#include <cstdio>
#include <cstring>
#include <thread>
#include <vector>

#include "pathstream/device/can_protocol.hpp"
#include "pathstream/host/can_stream.hpp"
#include "pathstream/host/geometry.hpp"
#include "pathstream/host/json_path.hpp"
#include "pathstream/host/machine.hpp"
#include "pathstream/host/planner.hpp"
#include "pathstream/sim/can_device.hpp"
#include "pathstream/sim/can_loopback.hpp"

using namespace pathstream;
namespace pc = device::can;

namespace {

struct Row {
    unsigned axes;
    double native_percent;
    double frames_per_second;
    double cia402_1ms, cia402_2ms;
};

// The 2-axis plan widened to `axes` axes: axis a follows axis a % 2.
host::Plan widen(const host::Plan& plan, unsigned axes) {
    host::Plan p = plan;
    for (auto& s : p.spans) {
        const auto c = s.control;
        s.control.resize(axes);
        for (unsigned a = 0; a < axes; ++a) s.control[a] = c[a % 2];
    }
    return p;
}

double cia402_percent(unsigned axes, double cycle_s) {
    const double bits = pc::frame_bits_worst_case(0) + 2.0 * axes * pc::frame_bits_worst_case(6);
    return bits / cycle_s / 1e6 * 100;
}

Row measure(const host::Plan& plan2, const host::MachineProfile& m2, unsigned axes, double time_scale) {
    const host::Plan plan = widen(plan2, axes);
    host::MachineProfile m = m2;
    m.axes.resize(axes);
    for (unsigned a = 0; a < axes; ++a) m.axes[a] = m2.axes[a % 2];
    sim::CanLoopback loop;
    hal::CanBus& device_bus = loop.add_endpoint();
    hal::CanBus& host_bus = loop.add_endpoint();
    std::vector<Lsb> start;
    for (const auto& c : plan.spans.front().control) start.push_back(c[0]);
    auto device = sim::SimulatedCanDevice::create(start, 1);
    std::atomic<bool> stop{false};
    std::thread t([&] {
        sim::DeviceLoopOptions o;
        o.time_scale = time_scale;
        sim::run_can_device_loop(*device, device_bus, o, stop);
    });
    host::CanStreamOptions o;
    o.node = 1;
    // Poll in device time: the same frames per second of motion at any time scale.
    o.poll_interval_ms = static_cast<unsigned>(10 / time_scale) + 1;
    const host::CanStreamReport r = host::stream_can(plan, m, host_bus, o);
    stop = true;
    t.join();
    const double motion = static_cast<double>(r.ticks_executed) / m.tick_hz;
    const auto c = loop.counters();
    return {axes, static_cast<double>(c.bits_worst_case) / motion / 1e6 * 100, static_cast<double>(c.frames) / motion,
            cia402_percent(axes, 0.001), cia402_percent(axes, 0.002)};
}

}  // namespace

int main(int argc, char** argv) {
    bool markdown = false, quick = false;
    for (int i = 1; i < argc; ++i) {
        if (std::strcmp(argv[i], "--markdown") == 0) markdown = true;
        else if (std::strcmp(argv[i], "--quick") == 0) quick = true;
        else {
            std::fprintf(stderr, "usage: bench_can [--quick] [--markdown]\n");
            return 2;
        }
    }
    const host::MachineProfile machine =
        host::load_machine_profile(std::string(PATHSTREAM_SOURCE_DIR) + "/examples/machines/pen_plotter.json");
    const host::Path path = host::load_json_path(std::string(PATHSTREAM_SOURCE_DIR) + "/examples/wave.json");
    const host::Plan plan = host::plan_path(host::to_bezier_segments(path), machine);
    const double time_scale = quick ? 10.0 : 1.0;
    std::vector<Row> rows;
    for (unsigned axes : {1u, 2u, 4u, 8u}) rows.push_back(measure(plan, machine, axes, time_scale));
    if (markdown) {
        std::printf("| axes | native, 1 kHz tick (%% of 1 Mbit/s) | frames/s | CiA 402 CSP 1 ms | CiA 402 CSP 2 ms |\n");
        std::printf("|---:|---:|---:|---:|---:|\n");
        for (const Row& r : rows) {
            std::printf("| %u | %.1f %% | %.0f | %.1f %% | %.1f %% |\n", r.axes, r.native_percent, r.frames_per_second,
                        r.cia402_1ms, r.cia402_2ms);
        }
    } else {
        std::printf("bus load, worst-case stuffing, %% of 1 Mbit/s (wave.json, %u-tick spans, 1 kHz tick%s)\n",
                    machine.ticks_per_span, quick ? ", device at 10x" : "");
        std::printf("%5s %12s %10s %14s %14s\n", "axes", "native", "frames/s", "CiA402 1 ms", "CiA402 2 ms");
        for (const Row& r : rows) {
            std::printf("%5u %11.1f%% %10.0f %13.1f%% %13.1f%%\n", r.axes, r.native_percent, r.frames_per_second,
                        r.cia402_1ms, r.cia402_2ms);
        }
    }
    for (const Row& r : rows) {
        if (r.axes == 4 && r.native_percent >= 20.0) {
            std::fprintf(stderr, "bench_can: 4 axes take %.1f %% of 1 Mbit/s, over the 20 %% target\n", r.native_percent);
            return 1;
        }
    }
    return 0;
}
