// Shared by the streaming tests (Modbus, CAN): an example drawing planned for the pen plotter,
// and what the core executes for it, to compare a device's record with tick for tick.
#pragma once

#include <string>
#include <vector>

#include "pathstream/host/core_playback.hpp"
#include "pathstream/host/geometry.hpp"
#include "pathstream/host/json_path.hpp"
#include "pathstream/host/planner.hpp"
#include "pathstream/linux_device/any_motion_device.hpp"
#include "pathstream/machine/machine.hpp"
#include "pathstream/span.hpp"
#include "pathstream/units.hpp"

namespace pathstream::test {

struct Job {
    host::MachineProfile machine;
    host::Plan plan;
};

/// examples/<name> (a JSON path) planned with examples/machines/pen_plotter.json.
inline Job plan_example(const std::string& name) {
    Job j;
    j.machine = host::load_machine_profile(std::string(PATHSTREAM_SOURCE_DIR) +
                                           "/examples/machines/pen_plotter.json");
    const host::Path path =
        host::load_json_path(std::string(PATHSTREAM_SOURCE_DIR) + "/examples/" + name);
    j.plan = host::plan_path(host::to_bezier_segments(path), j.machine);
    return j;
}

/// Every setpoint the core produces for `plan`, [tick * axes + axis], the end point included.
inline std::vector<Lsb> plan_setpoints(const host::Plan& plan, std::size_t axes) {
    std::vector<Lsb> out;
    host::play_through_core(plan.spans, axes, [&](const host::PlayedTick& t) {
        out.insert(out.end(), t.setpoint, t.setpoint + axes);
    });
    return out;
}

/// Where the plan's first span starts, LSB per axis: where a device must rest.
inline std::vector<Lsb> start_of(const host::Plan& plan) {
    std::vector<Lsb> s;
    for (const auto& c : plan.spans.front().control) s.push_back(c[0]);
    return s;
}

/// Where the plan's last span ends, LSB per axis: where a device rests after it.
inline std::vector<Lsb> end_of(const host::Plan& plan) {
    std::vector<Lsb> e;
    for (const auto& c : plan.spans.back().control) e.push_back(c[1]);
    return e;
}

/// examples/<name> planned with a pen-up lead-in from `from` (LSB per axis): the drawing a
/// device resting there can run next (what `pathstream stream --lead-in` plans).
inline Job plan_example_from(const std::string& name, const std::vector<Lsb>& from) {
    Job j;
    j.machine = host::load_machine_profile(std::string(PATHSTREAM_SOURCE_DIR) +
                                           "/examples/machines/pen_plotter.json");
    const host::Path path =
        host::load_json_path(std::string(PATHSTREAM_SOURCE_DIR) + "/examples/" + name);
    std::vector<host::BezierSegment> segments = host::to_bezier_segments(path);
    host::prepend_lead_in(segments,
                          {from.at(0) * j.machine.mm_per_lsb, from.at(1) * j.machine.mm_per_lsb});
    j.plan = host::plan_path(segments, j.machine);
    return j;
}

/// The device's recorded path ticks from path tick `first` on are `plan`'s setpoints, tick for
/// tick, pen included.
inline void check_recorded(const host::Plan& plan, const linux_device::AnyMotionDevice& device,
                           std::size_t first) {
    const std::size_t axes = plan.spans.front().control.size();
    const std::vector<Lsb> expected = plan_setpoints(plan, axes);
    const std::vector<Lsb>& got = device.recorded_setpoints();
    REQUIRE(got.size() >= (first + plan.total_ticks) * axes);
    for (std::size_t i = 0; i < plan.total_ticks * axes; ++i) {
        INFO("tick " << i / axes << " axis " << i % axes);
        REQUIRE(got[first * axes + i] == expected[i]);
    }
    std::size_t k = first;
    for (const auto& span : plan.spans) {
        for (std::uint32_t t = 0; t < span.ticks; ++t, ++k) {
            REQUIRE((device.recorded_ticks()[k].outputs & kOutputPenDown) ==
                    (span.pen_down ? 1 : 0));
        }
    }
}

}  // namespace pathstream::test
