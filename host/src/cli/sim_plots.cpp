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
    s.motion_measured = true;
    s.residual.stops = r.residual.stops;
    s.residual.window_ticks = r.residual.window_ticks;
    s.residual.max_mm = r.residual.max_mm;
    s.residual.rms_mm = r.residual.rms_mm;
    s.residual.max_tick = r.residual.max_tick;
    s.residual.tool_mm = r.residual.max_tool_mm;
    s.residual.rest_mm = r.residual.max_rest_mm;
    s.contour.max_mm = r.contour.max_mm;
    s.contour.rms_mm = r.contour.rms_mm;
    s.contour.back_ticks = r.contour.back_ticks;
    s.contour.ahead_ticks = r.contour.ahead_ticks;
    s.contour.max_tick = r.contour.max_tick;
    s.contour.tool_mm = r.contour.max_tool_mm;
    s.contour.path_mm = r.contour.max_path_mm;
    return s;
}

std::optional<plot::CornerWindow> corner_window(const sim::SimulationResult& r,
                                                const MachineProfile& profile) {
    const sim::ContourError& c = r.contour;
    const std::size_t axes = c.window.axes;
    if (axes < 2 || !(c.max_mm > 0) || c.max_tool_mm.size() != axes) return std::nullopt;
    std::size_t ax = 0, ay = 1;
    if (const std::optional<XyzAxes> xyz = xyz_axes(profile); xyz && xyz->y < axes) {
        ax = xyz->x;
        ay = xyz->y;
    }
    const auto name = [&](std::size_t a) {
        return a < profile.axes.size() ? profile.axes[a].name : "axis" + std::to_string(a);
    };
    plot::CornerWindow w;
    w.x_name = name(ax);
    w.y_name = name(ay);
    for (std::size_t i = 0; i + axes <= c.window.path_mm.size(); i += axes)
        w.path.push_back({c.window.path_mm[i + ax], c.window.path_mm[i + ay]});
    for (std::size_t i = 0; i + axes <= c.window.tool_mm.size(); i += axes)
        w.tool.push_back({c.window.tool_mm[i + ax], c.window.tool_mm[i + ay]});
    w.worst_tool = {c.max_tool_mm[ax], c.max_tool_mm[ay]};
    w.worst_path = {c.max_path_mm[ax], c.max_path_mm[ay]};
    w.error_mm = c.max_mm;
    w.time_s = static_cast<double>(c.max_tick) / r.tick_hz;
    return w;
}

}  // namespace pathstream::host
