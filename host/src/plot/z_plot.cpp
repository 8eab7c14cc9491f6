// z.svg: z against time for a machine with x, y and z axes, where a router's plunges and
// retracts, and a servo's lag behind them, show.
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "pathstream/host/plot.hpp"
#include "plot_parts.hpp"
#include "svg_canvas.hpp"

namespace pathstream::host::plot {

using detail::Canvas;
using detail::LegendEntry;

std::string z_svg(const RunRecord& r, const MachineProfile& profile, const Options& options) {
    if (!r.xyz) throw std::invalid_argument("z_svg: the machine has no x, y and z axes");
    const double w = detail::width_of(options);
    Canvas c(w, std::round(w * 0.5), detail::kMarginLeft, detail::kMarginTop, detail::kMarginRight,
             detail::kMarginBottom);
    const std::string z = detail::axis_name(profile, r.xyz->z);
    c.title(detail::title_of(options, z + " against time"));
    const double t_end = detail::end_time(r);
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (int series = 0; series < (r.has_plant ? 2 : 1); ++series) {
        if (r.bounded[series])
            lo = std::min(lo, r.lo[series][2]), hi = std::max(hi, r.hi[series][2]);
    }
    if (!(hi >= lo)) lo = 0, hi = 1;
    const double pad = std::max(1e-6, (hi - lo) * 0.05);
    c.set_range(0, t_end, lo - pad, hi + pad, false);
    c.axes("time (s)", z + " (mm)");
    detail::shade_pen_up(c, r);
    std::vector<LegendEntry> legend;
    const auto draw = [&](int series, const std::string& name, const char* id, const char* colour,
                          double width) {
        c.begin_series(id);
        c.polyline(detail::decimate_points(r.position[series], 0, t_end, detail::columns_of(c)),
                   colour, width);
        c.end_group();
        legend.push_back({name, colour, "", width});
    };
    draw(0, (r.executed_name.empty() ? "setpoints" : r.executed_name) + " (commanded)", "setpoints",
         detail::kSetpointColour, 2.5);
    if (r.has_plant)
        draw(1, (r.plant_name.empty() ? "plant" : r.plant_name) + " (executed)", "plant",
             detail::kPlantColour, 1.2);
    legend.push_back({"pen up (rapids)", detail::kPenUpShade, "", 10});
    c.legend(legend);
    c.note(
        "Commanded: the setpoints the device steps through, tick by tick; executed: where the "
        "plant's axis is. " +
        std::string(r.has_plant ? "" : "Without a plant model (ideal plant) they are one line. ") +
        "Pen-up (rapid) time shaded.");
    return c.finish();
}

}  // namespace pathstream::host::plot
