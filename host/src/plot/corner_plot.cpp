// corner.svg: the tool against the path, zoomed to where they were farthest apart.
#include <algorithm>
#include <cmath>

#include "pathstream/host/plot.hpp"
#include "plot_parts.hpp"
#include "svg_canvas.hpp"

namespace pathstream::host::plot {
namespace {

using detail::Canvas;
using detail::format_number;
using detail::LegendEntry;

/// The largest of 1, 2 or 5 x 10^n that is at most `most`.
double nice_length(double most) {
    const double decade = std::pow(10.0, std::floor(std::log10(most)));
    for (const double m : {5.0, 2.0, 1.0})
        if (m * decade <= most) return m * decade;
    return decade;
}

/// "20 um" below a millimetre, else "2 mm".
std::string length_text(double mm) {
    if (mm < 1) return format_number(mm * 1000, mm * 1000 < 1 ? 3 : 0) + " um";
    return format_number(mm, 0) + " mm";
}

}  // namespace

std::string corner_svg(const CornerWindow& corner, const Options& options) {
    // A square view around the worst point: ten times the error across, so that the error
    // shows as a tenth of the plot.
    const double half = std::max(5 * corner.error_mm, 0.005);
    const double cx = (corner.worst_tool.x + corner.worst_path.x) / 2;
    const double cy = (corner.worst_tool.y + corner.worst_path.y) / 2;
    const double w = detail::width_of(options);
    const double side = std::min(w - detail::kMarginLeft - detail::kMarginRight, 640.0);
    Canvas c(side + detail::kMarginLeft + detail::kMarginRight,
             side + detail::kMarginTop + detail::kMarginBottom, detail::kMarginLeft,
             detail::kMarginTop, detail::kMarginRight, detail::kMarginBottom);
    c.set_range(cx - half, cx + half, cy - half, cy + half, !options.y_up);
    c.title(detail::title_of(options, "Worst contour error, " +
                                          format_number(corner.error_mm * 1000, 1) + " um at " +
                                          format_number(corner.time_s, 3) + " s"));
    c.axes(corner.x_name + " (mm)", corner.y_name + (options.y_up ? " (mm), up" : " (mm), down"));
    c.begin_series("path");
    c.polyline(corner.path, detail::kIdealColour, 4, "", "path");
    c.end_group();
    c.begin_series("tool");
    c.polyline(corner.tool, detail::kPlantColour, 1.5, "", "tool");
    c.end_group();
    c.begin_series("worst");
    c.polyline({corner.worst_tool, corner.worst_path}, "#c92a2a", 1.5, "3 2", "worst");
    for (const Point& p : {corner.worst_tool, corner.worst_path}) {
        c.body() << "<circle cx=\"" << format_number(c.px(p.x), 1) << "\" cy=\""
                 << format_number(c.py(p.y), 1) << "\" r=\"3\" fill=\"#c92a2a\"/>\n";
    }
    c.end_group();
    // The scale bar, bottom left inside the plot: one nice length, at most a quarter across.
    const double unit = nice_length(half / 2);
    const double x0 = c.plot_left() + 16, y0 = c.plot_top() + c.plot_height() - 20;
    const double x1 = x0 + unit / (2 * half) * c.plot_width();
    c.begin_series("scale");
    c.polyline_px({{x0, y0}, {x1, y0}}, "#000", 1.2, "", "scale-bar");
    for (const double x : {x0, x1})
        c.polyline_px({{x, y0 - 5}, {x, y0 + 5}}, "#000", 1.2, "", "scale-tick");
    c.body() << "<text class=\"scale-label\" x=\"" << format_number((x0 + x1) / 2, 1) << "\" y=\""
             << format_number(y0 - 8, 1) << "\" text-anchor=\"middle\" fill=\"#000\">"
             << length_text(unit) << "</text>\n";
    c.end_group();
    c.legend({LegendEntry{"path (planned setpoints)", detail::kIdealColour, "", 4},
              LegendEntry{"tool", detail::kPlantColour, "", 1.5},
              LegendEntry{"contour error", "#c92a2a", "3 2", 1.5}});
    c.note("the tool's distance to the path is over all axes; the view shows " + corner.x_name +
           " and " + corner.y_name);
    return c.finish();
}

}  // namespace pathstream::host::plot
