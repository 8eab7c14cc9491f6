// Shared by the streaming tests (Modbus, CAN): an example drawing planned for the pen plotter,
// and what the core executes for it, to compare a device's record with tick for tick.
#pragma once

#include <string>
#include <vector>

#include "pathstream/host/core_playback.hpp"
#include "pathstream/host/geometry.hpp"
#include "pathstream/host/json_path.hpp"
#include "pathstream/host/machine.hpp"
#include "pathstream/host/planner.hpp"
#include "pathstream/units.hpp"

namespace pathstream::test {

struct Job {
    host::MachineProfile machine;
    host::Plan plan;
};

/// examples/<name> (a JSON path) planned with examples/machines/pen_plotter.json.
inline Job plan_example(const std::string& name) {
    Job j;
    j.machine = host::load_machine_profile(std::string(PATHSTREAM_SOURCE_DIR) + "/examples/machines/pen_plotter.json");
    const host::Path path = host::load_json_path(std::string(PATHSTREAM_SOURCE_DIR) + "/examples/" + name);
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

}  // namespace pathstream::test
