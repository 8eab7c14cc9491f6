// The pen-lift output on the simulated plotter: a planned drawing with two subpaths streamed
// as wire spans through MotionDevice and the GPIO glue. The pen line switches exactly at the
// plan's pen events, and no axis moves while the pen goes down or up (the plan's dwells).
#include <catch2/catch.hpp>
#include <cstdint>
#include <vector>

#include "pathstream/device/wire_span.hpp"
#include "pathstream/host/geometry.hpp"
#include "pathstream/host/json_path.hpp"
#include "pathstream/host/planner.hpp"
#include "pathstream/host/plot.hpp"
#include "pathstream/machine/machine.hpp"
#include "pathstream/sim/gpio_bench.hpp"

using namespace pathstream;
using namespace pathstream::device;

TEST_CASE("gpio pen: the pen line switches at the plan's pen events, never while moving",
          "[gpio][pen]") {
    const host::MachineProfile profile =
        host::load_machine_profile(PATHSTREAM_SOURCE_DIR "/examples/machines/pen_plotter.json");
    const host::Path path = host::parse_json_path(
        R"({"subpaths": [{"basis": "polyline", "points": [[0, 0], [10, 0], [10, 5]]},
                         {"basis": "polyline", "points": [[20, 5], [25, 0]]}]})",
        "two.json");
    const auto segments = host::to_bezier_segments(path);
    const host::Plan plan = host::plan_path(segments, profile);
    REQUIRE(plan.pen.size() >= 4);  // down, up, down, up

    MotionLimits<2> limits;
    limits.tick_hz = 1000;
    for (unsigned a = 0; a < 2; ++a) {
        limits.axis[a].max_velocity =
            static_cast<std::uint32_t>(profile.axes[a].max_velocity / profile.mm_per_lsb);
        limits.axis[a].max_acceleration =
            static_cast<std::uint32_t>(profile.axes[a].max_acceleration / profile.mm_per_lsb);
    }
    const Lsb start[2] = {plan.spans.front().control[0][0], plan.spans.front().control[1][0]};
    sim::GpioBench<2, 64> b(start, limits);

    std::size_t next = 0;
    auto feed = [&] {
        while (next < plan.spans.size() && b.device.free_slots() > 0) {
            const host::CoreSpan& c = plan.spans[next];
            WireSpan w;
            w.ticks = c.ticks;
            w.outputs = c.pen_down ? kOutputPenDown : std::uint8_t{0};
            for (unsigned a = 0; a < 2; ++a) {
                w.end[a] = c.control[a][1];
                w.start_tangent[a] = c.control[a][2];
                w.end_tangent[a] = c.control[a][3];
            }
            std::uint8_t bytes[4 + 12 * 2];
            const std::size_t n = encode_wire_span(w, 2, bytes, sizeof bytes);
            REQUIRE(b.device.accept_batch(b.device.last_accepted_sequence() + 1, 1, bytes, n) ==
                    Status::kOk);
            ++next;
        }
    };
    feed();
    REQUIRE(b.device.command(Command::kStart) == Status::kOk);
    b.step();  // the start tick: path tick 0 was output before (the rest point)
    const std::uint64_t first_path_stamp = b.clock.now();
    REQUIRE(b.run_until(
        [&] {
            feed();
            return next == plan.spans.size() && b.device.ticks_executed() >= plan.total_ticks;
        },
        static_cast<std::uint32_t>(plan.total_ticks + 100)));
    CHECK(b.device.underruns() == 0);

    // Every pen event became exactly one switch of the pen line, at the same tick distance
    // from the first path tick as in the plan.
    const auto& switches = b.pen.switch_ticks();
    REQUIRE(switches.size() == plan.pen.size());
    const std::int64_t offset =
        static_cast<std::int64_t>(switches[0]) - static_cast<std::int64_t>(plan.pen[0].tick);
    CHECK(offset >= 0);
    CHECK(static_cast<std::uint64_t>(offset) <= first_path_stamp);
    for (std::size_t i = 0; i < plan.pen.size(); ++i) {
        CHECK(static_cast<std::int64_t>(switches[i]) -
                  static_cast<std::int64_t>(plan.pen[i].tick) ==
              offset);
        CHECK(plan.pen[i].down == (i % 2 == 0));
    }
    // No drawing while the pen moves: from each switch on, the axes hold for the pen's delay.
    for (std::size_t i = 0; i < switches.size(); ++i) {
        const std::uint64_t delay = host::delay_ticks(
            plan.pen[i].down ? profile.pen_down_delay : profile.pen_up_delay, profile.tick_hz);
        const std::size_t first =
            static_cast<std::size_t>(switches[i]) - 1;  // the tick after which it switched
        INFO("pen switch " << i << " after tick " << first);
        for (std::uint64_t j = 1; j < delay && first + j < b.ticks.size(); ++j) {
            REQUIRE(b.ticks[first + j] == b.ticks[first]);
        }
    }

    // The report counts what the pen line did and the plan's pen dwells.
    host::plot::TickSeries exec;
    exec.axes = 2;
    exec.tick_hz = profile.tick_hz;
    exec.quantum_mm = profile.mm_per_lsb;
    std::size_t s = 0;
    bool down = false;
    for (std::size_t k = 0; k < b.ticks.size(); ++k) {
        while (s < switches.size() && switches[s] == k + 1) {
            down = !down;
            ++s;
        }
        exec.position.push_back(b.ticks[k][0] * profile.mm_per_lsb);
        exec.position.push_back(b.ticks[k][1] * profile.mm_per_lsb);
        exec.pen_down.push_back(down ? 1 : 0);
    }
    host::plot::RunSummary run;
    run.ticks = b.ticks.size();
    run.pen_switches = switches.size();
    const std::string report = host::plot::text_report(plan, nullptr, profile, exec, run);
    INFO(report);
    CHECK(report.find("  pen        2 down, 2 up; down ") != std::string::npos);
    CHECK(report.find("dwells 0.280 s") != std::string::npos);  // 2 x 80 ms down + 2 x 60 ms up
}
