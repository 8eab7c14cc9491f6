#include "sim_plots.hpp"

#include <cstdio>
#include <string>
#include <utility>

namespace pathstream::host {
namespace {

plot::TickSeries series_base(const sim::SimulationResult& r, std::string name) {
    plot::TickSeries s;
    s.name = std::move(name);
    s.tick_hz = r.tick_hz;
    s.axes = r.axes;
    s.pen_down = r.pen;
    return s;
}

std::string plant_description(const sim::SimulationResult& r) {
    if (r.plant == sim::PlantModel::kIdeal) return "ideal (position = setpoint)";
    char text[96];
    std::snprintf(text, sizeof text, "servo, 2nd order, f_n %.4g Hz, zeta %.3g",
                  r.servo.bandwidth_hz, r.servo.damping);
    return text;
}

}  // namespace

plot::TickSeries setpoint_series(const sim::SimulationResult& r) {
    plot::TickSeries s = series_base(r, "setpoints");
    s.quantum_mm = r.mm_per_lsb;
    s.position.reserve(r.setpoints.size());
    for (Lsb v : r.setpoints) s.position.push_back(v * r.mm_per_lsb);
    return s;
}

plot::TickSeries plant_series(const sim::SimulationResult& r) {
    plot::TickSeries s =
        series_base(r, r.plant == sim::PlantModel::kServo ? "servo plant" : "ideal plant");
    s.quantum_mm = r.plant == sim::PlantModel::kServo ? 0 : r.mm_per_lsb;
    s.position = r.positions;
    return s;
}

plot::RunSummary run_summary(const sim::SimulationResult& r) {
    plot::RunSummary s;
    s.target = "simulated device";
    s.plant = plant_description(r);
    s.ticks = r.ticks;
    s.spans = r.spans_pushed;
    s.pen_switches = r.pen_switch_ticks.size();
    s.underruns = r.underruns;
    s.late_ticks = r.late_ticks;
    s.realtime = r.paced;
    s.simulated_seconds = r.simulated_seconds;
    s.wall_seconds = r.wall_seconds;
    if (r.plant == sim::PlantModel::kServo) {
        for (const sim::FollowingError& f : r.following) {
            s.max_following_error_mm.push_back(f.max_mm);
            s.rms_following_error_mm.push_back(f.rms_mm);
        }
    }
    return s;
}

}  // namespace pathstream::host
